#!/usr/bin/env bash
# Maps random scenes nobody tuned on (doc/random-scenes.md) and prints, per quantity of issue 38,
# the distribution over the scenes (median, 90th percentile, worst) and the failing scenes.
# Usage: evaluate-random-scenes.sh [FIRST-LAST] [BOARDS] [SENSOR]  (default: the 50 scoring seeds
# 1000-1049 on the scoring boards AC, CC, CD, the laser), once with matched and once with
# independent noise. SENSOR stereo maps stereo alone against the naive pipeline.
# Writes build/random-scenes/BOARDS-NOISE.txt (stereo: BOARDS-stereo-NOISE.txt; one line per
# scene, then the table). About 3 minutes per noise on one core for the laser, 6 for stereo;
# not part of CI.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_BUILD_DIR:-$root/build}
seeds=${1:-1000-1049}
boards=${2:-scoring}
sensor=${3:-laser}
case $sensor in laser) tag=$boards ;; stereo) tag=$boards-stereo ;;
  *) echo "evaluate-random-scenes.sh: SENSOR must be laser or stereo (got '$sensor')" >&2; exit 1 ;;
esac
[ -f "$build_dir/build.ninja" ] || cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" --target random-scenes
mkdir -p "$build_dir/random-scenes"
cd "$root"
for noise in matched independent; do
  out="$build_dir/random-scenes/$tag-$noise.txt"
  "$build_dir/apps/terrain-sim/random-scenes" --boards "$boards" --seeds "$seeds" --noise "$noise" \
    --sensor "$sensor" --board-dir rawlogs/terrain/littledog > "$out"
  echo "== $sensor, $boards boards, seeds $seeds, $noise noise ($out)"
  sed -n '/^| quantity/,$p' "$out"
done
