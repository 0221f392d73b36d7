#!/usr/bin/env bash
# Maps both shipped scenarios (rawlogs/mockup, rawlogs/walk) with two builds of the mapper and
# compares what they write: the evaluation table (every row but its timing columns) and every
# elevation raster, byte for byte. A refactor or a speed-up must print "identical" everywhere; a
# change meant to move the map says which layers moved.
#
# Usage: scripts/compare-baseline.sh BASELINE_BUILD_DIR NEW_BUILD_DIR
#   e.g. git worktree add --detach /tmp/base COMMIT && cmake -S /tmp/base -B /tmp/base/build
#        -DCMAKE_BUILD_TYPE=Release && ninja -C /tmp/base/build elevation-mapper, then
#        scripts/compare-baseline.sh /tmp/base/build build
# Run from the repository root (the scenarios' ini and rawlogs are read from here).
# Exit status: 0 if everything is identical, 1 if anything differs, 2 on bad usage.
set -uo pipefail
if [ $# -ne 2 ]; then
    echo "usage: $0 BASELINE_BUILD_DIR NEW_BUILD_DIR" >&2
    exit 2
fi
out=$(mktemp -d)
status=0
for build in "$1" "$2"; do
    exe="$build/apps/elevation-mapper/elevation-mapper"
    if [ ! -x "$exe" ]; then
        echo "$0: no mapper at $exe (build the elevation-mapper target)" >&2
        exit 2
    fi
done
table() {  # the evaluation rows without their last two (timing) columns
    grep -E '^(raw_|laser_only|multibin|mrpt_)' "$1" | awk '{$NF=""; $(NF-1)=""; print}'
}
for s in mockup walk; do
    for side in base new; do
        build=$1
        [ $side = new ] && build=$2
        "$build/apps/elevation-mapper/elevation-mapper" --config "ini/$s.ini" \
            --rawlog "rawlogs/$s.rawlog" --ground-truth "rawlogs/${s}_gt.asc" --no-plots \
            --outputs all --out "$out/$side-$s" >"$out/$side-$s.txt" 2>&1 ||
            { echo "$s: the $side mapper failed (see $out/$side-$s.txt)"; status=1; }
    done
    if diff <(table "$out/base-$s.txt") <(table "$out/new-$s.txt") >/dev/null; then
        echo "$s: evaluation table identical"
    else
        echo "$s: evaluation table DIFFERS"
        status=1
    fi
    for f in "$out/base-$s"/elevation_*.asc; do
        n=$(basename "$f")
        if [ ! -f "$out/new-$s/$n" ]; then
            echo "  $n missing in the new build's output"
            status=1
        elif cmp -s "$f" "$out/new-$s/$n"; then
            echo "  $n identical"
        else
            echo "  $n DIFFERS"
            status=1
        fi
    done
done
echo "outputs in $out"
exit $status
