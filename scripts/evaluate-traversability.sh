#!/usr/bin/env bash
# Traversability against the truth (doc/traversability.md): the scoring scenarios of
# scripts/evaluate-independent.sh (boards AC, CC, CD, seed 7) with the matched and the independent
# noise, and the tuning mock-up the hexapod preset's calibration was fitted on, each simulated with
# a 3 mm ground truth (features of the surface far finer than the map's 20 mm cells), mapped with
# the scenario's ini at 20 mm plus ini/traversability-hexapod.ini, scored on the boards alone.
#
# Usage: bash scripts/evaluate-traversability.sh [OUTDIR]   (default build/traversability)
#        bash scripts/evaluate-traversability.sh --tune [OUTDIR]
# --tune maps only the tuning mock-up (matched and independent noise) with the hexapod preset's
# limits and no calibration, and fits the calibration on its cells (scripts/fit-traversability.py).
# Then MRPT's PlannerSimple2D on each scenario's exported grid against the truth's grid
# (build/tests/traversability/traversability_planning: PLAN_PAIRS start/goal pairs, default 100,
# seed 1, at each P(untraversable) limit of PLAN_P_MAX; the row "lattice": the truth's heights
# at the cells' centres thresholded, the best a map on this lattice can do).
# Needs a configured build; builds terrain-sim, elevation-mapper and traversability_planning.
# About 2 minutes on 2 cores.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_BUILD_DIR:-$root/build}
tune=0
if [ "${1:-}" = --tune ]; then tune=1; shift; fi
out=${1:-$build_dir/traversability}
cmake --build "$build_dir" --target terrain-sim elevation-mapper traversability_planning >/dev/null
sim="$build_dir/apps/terrain-sim/terrain-sim"
mapper="$build_dir/apps/elevation-mapper/elevation-mapper"
planning="$build_dir/tests/traversability/traversability_planning"
read -r -a plan_p_max <<<"${PLAN_P_MAX:-0.6 0.5 0.4 0.3 0.2 0.1}"
boards="$root/rawlogs/terrain/littledog"
mkdir -p "$out"

declare -A scenario area
scenario[score-mockup]="--scenario mockup --terrain $boards/AC.asc,$boards/CC.asc,$boards/CD.asc --tiles 4x3 --seed 7"
area[score-mockup]="0,2.428,-0.9105,0.9105"
scenario[score-walk]="--scenario walk --terrain $boards/AC.asc,$boards/CC.asc,$boards/CD.asc --tiles 4x2 --speed 0.15 --seed 7"
area[score-walk]="0,2.428,-0.607,0.607"
scenario[tune-mockup]="--scenario mockup --terrain $boards/B.asc,$boards/X1.asc,$boards/W.asc,$boards/AC.asc --tiles 3x3 --seed 1"
area[tune-mockup]="0,1.821,-0.9105,0.9105"

run() {  # scenario noise
  local s=$1 n=$2 prefix="$out/$1-$2"
  # shellcheck disable=SC2086
  "$sim" ${scenario[$s]} --noise "$n" --gt-cell 0.003 --out "$prefix" | head -1
  # --tune: the preset without its calibration keys (identity).
  sed 's/^resolution_m = .*/resolution_m = 0.02/' "$prefix.ini" |
    cat - <(if [ $tune = 1 ]; then grep -Ev '_(bias|gain|model_sigma)' "$root/ini/traversability-hexapod.ini"
            else cat "$root/ini/traversability-hexapod.ini"; fi) >"$prefix-hexapod.ini"
  "$mapper" --config "$prefix-hexapod.ini" --rawlog "$prefix.rawlog" \
    --ground-truth "${prefix}_gt.asc" --eval-area "${area[$s]}" --no-plots --outputs map,gridmap \
    --out "$prefix-boards" >"$prefix-boards.log"
  rm -f "$prefix.simplemap"
}
if [ $tune = 1 ]; then
  run tune-mockup matched
  run tune-mockup independent
  python3 "$root/scripts/fit-traversability.py" "$out"/tune-mockup-*-boards/traversability_cells.csv
  exit 0
fi
for s in score-mockup score-walk; do
  for n in matched independent; do run "$s" "$n"; done
done
run tune-mockup matched

python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
print("| scenario | noise | method | precision | recall | F1 | ECE | coverage |")
print("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |")
for s, n in (("score-mockup", "matched"), ("score-mockup", "independent"),
             ("score-walk", "matched"), ("score-walk", "independent"), ("tune-mockup", "matched")):
    t = json.load(open(f"{out}/{s}-{n}-boards/traversability.json"))["methods"]
    h = json.load(open(f"{out}/{s}-{n}-boards/report.json"))["methods"]
    for m, r in t.items():
        print(f"| {s} | {n} | {m} | {r['precision']:.3f} | {r['recall']:.3f} | {r['f1']:.3f} | "
              f"{r['ece']:.3f} | {r['coverage']:.3f} |")
    print(f"| {s} | {n} | (height layer multibin_filled coverage) | | | | | "
          f"{h['multibin_filled']['coverage']:.3f} |")
print()
r = json.load(open(f"{out}/score-mockup-independent-boards/traversability.json"))["methods"]["multibin"]
print("Reliability, score-mockup independent, multibin: | P decile | cells | mean P | observed |")
for b, d in enumerate(r["reliability"]):
    print(f"| {b / 10:.1f}-{(b + 1) / 10:.1f} | {d['cells']} | {d['mean_p']:.3f} | {d['observed']:.3f} |")
print()
# The truth's untraversable cells the layer misses, by the truth's step (above 0.15 m: the seams
# between boards, slots down to the ground) and by whether the map measured the cell (else filled).
def asc(path):
    with open(path) as f:
        h = {k.lower(): float(v) for k, v in (f.readline().split() for _ in range(6))}
        z = [[float(v) for v in line.split()] for line in f if line.strip()]
    def at(x, y):
        c = round((x - h["xllcenter"]) / h["cellsize"])
        r = len(z) - 1 - round((y - h["yllcenter"]) / h["cellsize"])
        return 0 <= r < len(z) and 0 <= c < len(z[0]) and z[r][c] != h["nodata_value"]
    return at
print("| scenario | noise | truth step | truth untraversable | P > 0.5 | P < 0.3 | of them measured |")
print("| --- | --- | --- | ---: | ---: | ---: | ---: |")
import csv
for s, n in (("score-mockup", "matched"), ("score-mockup", "independent"),
             ("score-walk", "matched"), ("score-walk", "independent"), ("tune-mockup", "matched")):
    d = f"{out}/{s}-{n}-boards"
    lim = json.load(open(f"{d}/traversability.json"))["limits"]
    measured = asc(f"{d}/eval_multibin.asc")
    rows = list(csv.DictReader(open(f"{d}/traversability_cells.csv")))
    bad = [r for r in rows if float(r["truth_step_m"]) > lim["max_step_m"]
           or float(r["truth_slope_deg"]) > lim["max_slope_deg"]
           or float(r["truth_roughness_m"]) > lim["max_roughness_m"]]
    for label, seam in (("> 0.15 m", True), ("<= 0.15 m", False)):
        b = [r for r in bad if (float(r["truth_step_m"]) > 0.15) == seam]
        missed = [r for r in b if float(r["untraversable"]) < 0.3]
        print(f"| {s} | {n} | {label} | {len(b)} | {sum(float(r['untraversable']) > 0.5 for r in b)} | "
              f"{len(missed)} | {sum(measured(float(r['x_m']), float(r['y_m'])) for r in missed)} |")
PY

echo
echo "PlannerSimple2D on the exported grid against the truth's grid (${PLAN_PAIRS:-100} pairs, seed 1):"
echo "| scenario | noise | P max | pairs | truth found | map found there | map found, truth none | unsafe paths | unsafe cells / path cells | length <= 1.15 x | max ratio |"
echo "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for sn in score-mockup-matched score-mockup-independent score-walk-matched score-walk-independent \
  tune-mockup-matched; do
  "$planning" "$out/$sn-boards" "$out/${sn}_gt.asc" "${PLAN_PAIRS:-100}" 1 "${plan_p_max[@]}" |
    sed "s/^|/| ${sn%-*} | ${sn##*-} |/"
done
