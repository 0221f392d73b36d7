#!/usr/bin/env python3
"""Times multibin.ElevationMap.height() over 1 M points against a Python loop of single queries
and against C++: the same batch query (multibin_query_table --time: HeightQuery.h, the map's
heights()) and a C++ loop of single height() calls (--one-by-one).

The map: the shipped mock-up mapped and saved, then loaded and filled by both sides (the same
bins in the same memory layout). The points: uniform over the map's window (about a fifth of
them known). Each method is timed per block of 100 000 points, the fastest of N runs of each
block in CPU time of the calling thread (the query runs there, GIL released or not), summed over
the blocks: a shared machine's other work is not counted, and all four see the same blocks. The figures of doc/python.md:

    PYTHONPATH=build/python/module /usr/bin/python3 python/bench/bench_height.py [--build build]
"""
import argparse
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import multibin

ROOT = pathlib.Path(__file__).resolve().parents[2]
BLOCK = 100_000  # as kTimedBlock of python/tests/query_table.cpp


def best_of(runs, f):
    """The fastest of `runs` calls of f [s, CPU time of this thread]."""
    best = float("inf")
    for _ in range(runs):
        t0 = time.thread_time()
        f()
        best = min(best, time.thread_time() - t0)
    return best


def blockwise(runs, x, y, time_block):
    """Sum over the blocks of the fastest of `runs` runs of time_block(xb, yb) [s]."""
    return sum(best_of(runs, lambda: time_block(x[b:b + BLOCK], y[b:b + BLOCK]))
               for b in range(0, len(x), BLOCK))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"), help="the build folder")
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=15, help="runs of each block (vectorised, C++)")
    ap.add_argument("--loop-runs", type=int, default=5, help="runs of each block (Python loop)")
    args = ap.parse_args()
    helper = pathlib.Path(args.build) / "python" / "multibin_query_table"

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        mapped = multibin.ElevationMap(str(ROOT / "ini" / "mockup.ini"))
        mapped.map_rawlog(str(ROOT / "rawlogs" / "mockup.rawlog"))
        mapped.save(str(tmp / "map.bin"))
        m = multibin.ElevationMap.load(str(tmp / "map.bin"))
        m.fill()
        xmin, xmax, ymin, ymax = m.extent_m
        rng = np.random.default_rng(1)
        x = rng.uniform(xmin, xmax, args.points)
        y = rng.uniform(ymin, ymax, args.points)
        np.column_stack([x, y]).tofile(tmp / "xy.bin")
        known = np.count_nonzero(np.isfinite(m.height(x, y)[0]))

        vectorised_s = blockwise(args.runs, x, y, m.height)

        def python_loop(xb, yb):
            for xi, yi in zip(xb.tolist(), yb.tolist()):
                m.height(xi, yi)

        loop_s = blockwise(args.loop_runs, x, y, python_loop)
        # The same by what the map answers: the query's own cost differs by source.
        _, _, src = m.height(x, y)
        by_source = {}
        for name, sel in [("unknown", src == multibin.SOURCE_UNKNOWN),
                          ("measured", src == multibin.SOURCE_MEASURED),
                          ("filled", src >= multibin.SOURCE_FILLED_MEDIAN)]:
            xs, ys = x[sel][:BLOCK], y[sel][:BLOCK]
            by_source[name] = (len(xs), blockwise(args.runs, xs, ys, m.height),
                               blockwise(args.loop_runs, xs, ys, python_loop))
        def cpp(*mode):
            return float(subprocess.run(
                [str(helper), "--fill", "--time", str(args.runs), *mode, str(tmp / "map.bin"),
                 str(tmp / "xy.bin")], check=True, capture_output=True, text=True).stdout)

        cpp_s, cpp_loop_s = cpp(), cpp("--one-by-one")

    print(f"{args.points} points ({known} known) on the mock-up map; CPU time, per block of "
          f"{BLOCK} the fastest of {args.runs} runs ({args.loop_runs} for the Python loop), "
          f"summed:")
    for name, t in [("height(x, y) vectorised", vectorised_s),
                    ("Python loop of height(xi, yi)", loop_s), ("C++ heights() batch", cpp_s),
                    ("C++ loop of height()", cpp_loop_s)]:
        print(f"  {name:30s} {t * 1e3:8.1f} ms  ({t / args.points * 1e9:5.0f} ns/point)")
    print(f"  Python loop / vectorised: {loop_s / vectorised_s:.1f} x (target >= 5)")
    print(f"  vectorised / C++ batch:   {vectorised_s / cpp_s:.2f} x (target <= 1.5)")
    print(f"  vectorised / C++ loop:    {vectorised_s / cpp_loop_s:.2f} x")
    print("By source (up to one block of the points the map answers so):")
    for name, (n, vec_s, py_s) in by_source.items():
        print(f"  {name:9s} {n:6d} points: vectorised {vec_s / n * 1e9:5.0f} ns/point, Python "
              f"loop {py_s / n * 1e9:5.0f} ns/point, {py_s / vec_s:.1f} x")


if __name__ == "__main__":
    main()
