#!/bin/bash
# Single-scan benchmarks of two Release builds, alternating, 3 rounds, median of 3 repetitions
# (CPU time): compare-bench-builds.sh BASE_BUILD NEW_BUILD   (doc/route-scale.md)
set -euo pipefail
base=$1/tests/bench
new=$2/tests/bench
cd "$(dirname "$0")/.."
for round in 1 2 3; do
  for side in base new; do
    dir=$base
    [ $side = new ] && dir=$new
    "$dir/bench_pipeline" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
      --benchmark_filter='BM_LaserScanEndToEnd/1$|BM_LaserScansMockup/1$|BM_StereoFrameEndToEnd/1/1$' \
      2>/dev/null | grep median | sed "s/^/$side $round /"
    "$dir/bench_lidar" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
      --benchmark_filter='BM_MapInsertVlp16Revolution/1$' 2>/dev/null | grep median |
      sed "s/^/$side $round /"
  done
done
