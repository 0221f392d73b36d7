#!/usr/bin/env bash
# Makes the figures of doc/user-guide.md into doc/user-guide/: maps the shipped mock-up with
# elevation-mapper (previews, evaluation figures, 3D scenes), the shipped walk and MRPT's Malaga
# building (a horizontal laser: walls) for the 3D view at two sizes, then takes screenshots of
# MRPT's RawLogViewer (the rawlog) and SceneViewer3D (the maps, from the camera each scene
# carries) on a virtual X display (Xvfb).
# Rerun it after changing the mapper or the data; it installs what it needs (Debian packages).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/scripts/setup.sh"
# A virtual display, a screenshot (xwd -> PNG) and window sizing for programs without a window
# manager.
install_missing_packages mrpt-apps xvfb x11-apps netpbm xdotool
cd "$root"
figures=doc/user-guide
work="$build_dir/user-guide"
rm -rf "$work"
mkdir -p "$figures" "$work"

mapper="$build_dir/apps/elevation-mapper/elevation-mapper"
"$mapper" --config ini/mockup.ini --rawlog rawlogs/mockup.rawlog \
  --ground-truth rawlogs/mockup_gt.asc --out "$work/map" | tee "$work/map.txt"
for colour in sigma source; do
  "$mapper" --config ini/mockup.ini --rawlog rawlogs/mockup.rawlog --outputs scene \
    --scene-colour "$colour" --out "$work/scene-$colour" >/dev/null
done
"$mapper" --config ini/walk.ini --rawlog rawlogs/walk.rawlog --outputs scene \
  --out "$work/walk" >/dev/null
"$mapper" --config ini/lidar-2d.ini --outputs scene --out "$work/malaga" \
  --simplemap /usr/share/mrpt/datasets/malaga-cs-fac-building.simplemap.gz >/dev/null 2>&1
cp "$work/map/elevation_height.png" "$work/map/elevation_sigma.png" \
  "$work/map/elevation_source.png" "$work/map/fig_pi.png" "$work/map/fig_profile.png" \
  "$work/map/layers.png" "$figures/"
# The mapper's console output, as the guide quotes it (without the absolute output path).
sed "s|$work/|OUT/|" "$work/map.txt" > "$figures/elevation-mapper-output.txt"

# screenshot OUT.png ZOOM PROGRAM ARGS...: starts PROGRAM on the virtual display, closes its
# start-up tip, makes its main window 1280 x 800, turns the mouse wheel ZOOM notches over the
# view (0: the camera the program opened with; a saved map's scene carries one that frames it)
# and saves the screen.
cat > "$work/screenshot.sh" <<'SHOT'
set -euo pipefail
out=$1; zoom=$2; shift 2
"$@" >/dev/null 2>&1 &
pid=$!
title=""
for _ in $(seq 60); do  # wait for the main window (its title names the MRPT project)
  title=$(xdotool search --onlyvisible --name "Part of the MRPT project" 2>/dev/null | head -1 || true)
  [ -n "$title" ] && break
  sleep 0.5
done
[ -n "$title" ] || { echo "no window from $1" >&2; kill "$pid"; exit 1; }
sleep 4  # loading the file and the first draw
for tip in $(xdotool search --onlyvisible --name "Tip of the Day" 2>/dev/null || true); do
  xdotool windowunmap "$tip"
done
xdotool windowsize "$title" 1280 800 windowmove "$title" 0 0
sleep 2
xdotool mousemove 700 420
for _ in $(seq "$zoom"); do xdotool click 4; sleep 0.1; done
sleep 3
xwd -root -silent | xwdtopnm 2>/dev/null | pnmtopng > "$out"
kill "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
SHOT
# Each on its own display; a program that does not come up (a display still shutting down) is
# tried again.
shot() {
  for _ in 1 2 3; do
    xvfb-run -a -s "-screen 0 1280x800x24" bash "$work/screenshot.sh" "$@" && return 0
    sleep 2
  done
  return 1
}
shot "$figures/rawlogviewer.png" 0 RawLogViewer rawlogs/mockup.rawlog
shot "$figures/sceneviewer3d-height.png" 0 SceneViewer3D "$work/map/elevation.3Dscene"
for colour in sigma source; do
  shot "$figures/sceneviewer3d-$colour.png" 0 SceneViewer3D \
    "$work/scene-$colour/elevation.3Dscene"
done
shot "$figures/sceneviewer3d-walk.png" 0 SceneViewer3D "$work/walk/elevation.3Dscene"
shot "$figures/sceneviewer3d-malaga.png" 0 SceneViewer3D "$work/malaga/elevation.3Dscene"
echo "figures in $figures/"
