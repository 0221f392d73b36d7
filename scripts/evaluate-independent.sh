#!/usr/bin/env bash
# Independent evaluation (doc/independent-evaluation.md): generates the scoring scenarios on the
# boards the project's constants were not chosen on (AC, CC, CD in arrangements and seeds no
# tuning used) and the shipped mock-up's set-up, each with the noise the library's models assume
# (matched) and with errors they do not describe (independent, and each error alone), maps and
# scores every run with elevation-mapper, and prints the tables of the doc.
#
# Usage: bash scripts/evaluate-independent.sh [OUTDIR]   (default build/independent)
# Needs a configured build (scripts/setup.sh); builds only terrain-sim and elevation-mapper.
# About 10 minutes on 2 cores; not part of CI.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_BUILD_DIR:-$root/build}
out=${1:-$build_dir/independent}
if [[ ! -f "$build_dir/build.ninja" && ! -f "$build_dir/Makefile" ]]; then
  echo "evaluate-independent.sh: no configured build in $build_dir (run scripts/setup.sh first)" >&2
  exit 1
fi
cmake --build "$build_dir" --target terrain-sim elevation-mapper >/dev/null
sim="$build_dir/apps/terrain-sim/terrain-sim"
mapper="$build_dir/apps/elevation-mapper/elevation-mapper"
boards="$root/rawlogs/terrain/littledog"
cd "$root"
mkdir -p "$out"

# Scenarios: name, terrain-sim arguments, --eval-area of the boards alone (tiles of 0.607 m).
declare -A scenario area
scenario[score-mockup]="--scenario mockup --terrain $boards/AC.asc,$boards/CC.asc,$boards/CD.asc --tiles 4x3 --seed 7"
area[score-mockup]="0,2.428,-0.9105,0.9105"
scenario[score-walk]="--scenario walk --terrain $boards/AC.asc,$boards/CC.asc,$boards/CD.asc --tiles 4x2 --speed 0.15 --seed 7"
area[score-walk]="0,2.428,-0.607,0.607"
# The same with another seed (noise, pose errors and texture), for the run-to-run spread.
scenario[score-mockup-seed8]="${scenario[score-mockup]/--seed 7/--seed 8}"
area[score-mockup-seed8]=${area[score-mockup]}
scenario[score-walk-seed8]="${scenario[score-walk]/--seed 7/--seed 8}"
area[score-walk-seed8]=${area[score-walk]}
# The shipped mock-up (tuning boards B, X1, W, AC): its matched run is rawlogs/mockup.* exactly.
scenario[tune-mockup]="--scenario mockup --terrain $boards/B.asc,$boards/X1.asc,$boards/W.asc,$boards/AC.asc --tiles 3x3 --seed 1"
area[tune-mockup]="0,1.821,-0.9105,0.9105"

# Noise variants: name, terrain-sim arguments.
declare -A noise
noise[matched]="--noise matched"
noise[independent]="--noise independent"
noise[tails]="--tail-dof 4"
noise[bias]="--laser-range-bias -0.002,0.01"
noise[outliers]="--outliers 0.01"
noise[mixed]="--laser-mixed 1,0.015 --stereo-mixed 0.5"
noise[calibration]="--laser-pitch-error 0.3 --stereo-baseline-error 0.0003 --stereo-principal-point-error 0.5,0.5"

run() {  # scenario noise
  local s=$1 n=$2 prefix="$out/$1-$2"
  # shellcheck disable=SC2086
  "$sim" ${scenario[$s]} ${noise[$n]} --out "$prefix" | head -1
  "$mapper" --config "$prefix.ini" --rawlog "$prefix.rawlog" --ground-truth "${prefix}_gt.asc" \
    --no-plots --out "$prefix-map" >"$prefix-map.log"
  "$mapper" --config "$prefix.ini" --rawlog "$prefix.rawlog" --ground-truth "${prefix}_gt.asc" \
    --eval-area "${area[$s]}" --no-plots --out "$prefix-boards" >"$prefix-boards.log"
  rm -f "$prefix.simplemap"  # not used here; saves 4 MB per run
}

for s in score-mockup score-walk; do
  for n in matched independent tails bias outliers mixed calibration; do run "$s" "$n"; done
done
for s in score-mockup-seed8 score-walk-seed8 tune-mockup; do
  for n in matched independent; do run "$s" "$n"; done
done
# Per tile (0.607 m squares, row-major from the smallest y, boards cycling AC, CC, CD).
for s in score-mockup score-walk; do
  rows=3
  [[ $s == score-walk ]] && rows=2
  for n in matched independent; do
    prefix="$out/$s-$n"
    for ((r = 0; r < rows; r++)); do
      for ((c = 0; c < 4; c++)); do
        a=$(awk -v r=$r -v c=$c -v R=$rows 'BEGIN { L = 0.607;
          printf "%.4f,%.4f,%.4f,%.4f", c * L, (c + 1) * L, -R * L / 2 + r * L, -R * L / 2 + (r + 1) * L }')
        "$mapper" --config "$prefix.ini" --rawlog "$prefix.rawlog" --ground-truth "${prefix}_gt.asc" \
          --eval-area "$a" --no-plots --out "$prefix-tile$r$c" >/dev/null
      done
    done
  done
done
if cmp -s "$out/tune-mockup-matched.rawlog" rawlogs/mockup.rawlog; then
  echo "tune-mockup-matched.rawlog is rawlogs/mockup.rawlog byte for byte"
fi

python3 - "$out" <<'EOF'
import json, sys
out = sys.argv[1]
def rep(run, where):
    return json.load(open(f"{out}/{run}-{where}/report.json"))["methods"]
def row(s, n, where, m):
    r = rep(f"{s}-{n}", where)[m]
    w = r["within_3sigma"]
    return (f"| {s} | {n} | {where} | {m} | {1000 * r['rmse_m']:.2f} | {r['pi']:.3f} | "
            f"{r['coverage']:.3f} | {'-' if w is None else f'{w:.3f}'} |")
print("| scenario | noise | area | method | RMSE [mm] | PI | coverage | within 3 sigma |")
print("| --- | --- | --- | --- | ---: | ---: | ---: | ---: |")
for s in ("score-mockup", "score-walk", "score-mockup-seed8", "score-walk-seed8", "tune-mockup"):
    for where in ("map", "boards"):
        for m in ("laser_only", "multibin", "multibin_filled", "mrpt_height_grid"):
            for n in ("matched", "independent"):
                print(row(s, n, where, m))
print()
print("Per tile, seed 7, multibin: RMSE [mm] / within 3 sigma, matched (independent):")
print("| tile (row, column): board | score-mockup | score-walk |")
print("| --- | --- | --- |")
import os
for r in range(3):
    for c in range(4):
        cells = []
        for s in ("score-mockup", "score-walk"):
            if not os.path.exists(f"{out}/{s}-matched-tile{r}{c}"):
                cells.append("-")
                continue
            a, b = (rep(f"{s}-{n}", f"tile{r}{c}")["multibin"] for n in ("matched", "independent"))
            cells.append(f"{1000 * a['rmse_m']:.1f} / {a['within_3sigma']:.3f} "
                         f"({1000 * b['rmse_m']:.1f} / {b['within_3sigma']:.3f})")
        print(f"| ({r}, {c}): {('AC', 'CC', 'CD')[(r * 4 + c) % 3]} | {cells[0]} | {cells[1]} |")
print()
print("Each error alone (multibin, measured cells, whole truth / boards alone):")
print("| scenario | noise | RMSE [mm] | within 3 sigma | RMSE boards [mm] | within 3 sigma boards | coverage |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: |")
for s in ("score-mockup", "score-walk"):
    for n in ("matched", "tails", "bias", "outliers", "mixed", "calibration", "independent"):
        a, b = rep(f"{s}-{n}", "map")["multibin"], rep(f"{s}-{n}", "boards")["multibin"]
        print(f"| {s} | {n} | {1000 * a['rmse_m']:.2f} | {a['within_3sigma']:.3f} | "
              f"{1000 * b['rmse_m']:.2f} | {b['within_3sigma']:.3f} | {a['coverage']:.3f} |")
EOF
