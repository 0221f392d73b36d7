#!/usr/bin/env python3
"""Fits the traversability calibration (doc/traversability.md) on the cells of tuning runs.

Per feature, truth = bias + gain x map by least squares over the cells of every CSV given
(traversability_cells.csv of runs mapped without calibration), and model_sigma the RMS of the
residuals; prints the ini keys.
Usage: python3 scripts/fit-traversability.py RUN/traversability_cells.csv [...]
"""
import csv
import math
import sys

rows = [r for path in sys.argv[1:] for r in csv.DictReader(open(path))]
if not rows:
    sys.exit("fit-traversability.py: no cells in " + " ".join(sys.argv[1:]))
print(f"; fitted on {len(rows)} cells of " + ", ".join(sys.argv[1:]))
for name, unit in (("step", "m"), ("slope", "deg"), ("roughness", "m")):
    x = [float(r[f"{name}_{unit}"]) for r in rows]
    y = [float(r[f"truth_{name}_{unit}"]) for r in rows]
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    gain = sxy / sxx
    bias = my - gain * mx
    sigma = math.sqrt(sum((b - bias - gain * a) ** 2 for a, b in zip(x, y)) / (n - 2))
    print(f"{name}_bias_{unit} = {bias:.4g}\n{name}_gain = {gain:.4g}\n"
          f"{name}_model_sigma_{unit} = {sigma:.4g}")
