#!/usr/bin/env bash
# Maps and evaluates both shipped scenarios and copies the reports and figures into doc/eval/
# (the numbers in doc/evaluation.md come from here), then the mock-up once more over its 3 x 3
# boards only (--eval-area, without the floor around them). Add --with-mrf to also solve MRPT's
# GMRF height map on a 35 x 35 cell crop (slow: minutes).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/scripts/setup.sh"
cd "$root"
for scenario in mockup walk; do
  out="$build_dir/eval/$scenario"
  rm -rf "$out"
  "$build_dir/apps/elevation-mapper/elevation-mapper" --config "ini/$scenario.ini" \
    --rawlog "rawlogs/$scenario.rawlog" --ground-truth "rawlogs/${scenario}_gt.asc" \
    --out "$out" "$@"
  mkdir -p "doc/eval/$scenario"
  cp "$out/report.json" "$out/fig_pi.png" "$out/fig_profile.png" "$out/layers.png" \
    "doc/eval/$scenario/"
done
# The boards span x in [0, 1.83], y in [-0.915, 0.915] m (3 x 3 tiles of 0.61 m).
out="$build_dir/eval/mockup-boards"
rm -rf "$out"
"$build_dir/apps/elevation-mapper/elevation-mapper" --config ini/mockup.ini \
  --rawlog rawlogs/mockup.rawlog --ground-truth rawlogs/mockup_gt.asc \
  --eval-area 0,1.83,-0.915,0.915 --no-plots --out "$out"
mkdir -p doc/eval/mockup-boards
cp "$out/report.json" doc/eval/mockup-boards/
