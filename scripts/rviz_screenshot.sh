#!/usr/bin/env bash
# Reproduces docs/rviz_screenshot.png: renders a short simulated drive into a bag (`simulate`,
# cached), plays it with launch/play_bag.launch (sim time, the nodelet, rviz with
# rviz/calibration.rviz) on a virtual X display (Xvfb) and grabs the screen.
# Not part of the test run. Needs: a build with catkin (targets calibration_node, simulate),
# Xvfb and ImageMagick (apt-get install -y xvfb imagemagick).
#
#   bash scripts/rviz_screenshot.sh [OUT.png]     (default docs/rviz_screenshot.png)
#
# OSC_SHOT_RECTIFY=1 adds stereo_image_proc on the live calibration (rectify:=true) and so the
# stereo point cloud (docs/rviz_point_cloud.png:
#   OSC_SHOT_RECTIFY=1 bash scripts/rviz_screenshot.sh docs/rviz_point_cloud.png).
# Environment: OSC_BUILD_DIR (default build), OSC_SHOT_FRAMES (frames rendered, default 150,
# played at half speed: 30 s), OSC_SHOT_AFTER (s after the start before the grab, default 30;
# keep it below 3 + 2 * FRAMES / 10: the launch ends with the bag), DISPLAY_NUMBER (default 99).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="${1:-$ROOT/docs/rviz_screenshot.png}"
BUILD="${OSC_BUILD_DIR:-build}"
[[ "$BUILD" = /* ]] || BUILD="$ROOT/$BUILD"
FRAMES="${OSC_SHOT_FRAMES:-150}"
AFTER="${OSC_SHOT_AFTER:-30}"
DISPLAY_NUMBER="${DISPLAY_NUMBER:-99}"
RECTIFY=false
[[ "${OSC_SHOT_RECTIFY:-0}" == "1" ]] && RECTIFY=true
WORK="${TMPDIR:-/tmp}/osc_rviz_screenshot"
export PATH="/usr/bin:$PATH"  # ROS's python tools need the system python3

# The package from the build tree: devel space if there is one.
if [[ -f "$BUILD/devel/setup.bash" ]]; then
  set +u; source "$BUILD/devel/setup.bash"; set -u
fi
export ROS_PACKAGE_PATH="$ROOT:${ROS_PACKAGE_PATH:-}"
BIN="$BUILD/devel/lib/online_stereo_calibration"
for tool in simulate calibration_node; do
  [[ -x "$BIN/$tool" ]] || { echo "missing $BIN/$tool: build the targets simulate and calibration_node" >&2; exit 1; }
done

mkdir -p "$WORK"
"$BIN/simulate" --scenario "$ROOT/config/scenarios/paper_offroad.yaml" --frames "$FRAMES" \
  --out "$WORK/drive"
# Adapter parameters: ros.yaml with the start guess of test/ros/convergence.test (the drive's
# truth, x_caml = [1.5, 0.15, 1.3, 0, 0.05, 0], x_camr = [0, -0.3, 0, 0, 0, 0], off by
# 10 cm / 3 deg on the left camera and 2 cm / 0.3 deg on the right one).
cat > "$WORK/guess.yaml" <<'YAML'
vehicle_to_left: [1.6, 0.05, 1.4, 0.05235987755982989, -0.0023598775598298873, 0.05235987755982989]
left_to_right: [0.0, -0.28, 0.0, 0.0, 0.0, 0.005235987755982988]
YAML
sed -e 's|^initial_guess_source:.*|initial_guess_source: file|' \
    -e "s|^initial_guess_file:.*|initial_guess_file: \"$WORK/guess.yaml\"|" \
    "$ROOT/config/ros.yaml" > "$WORK/ros.yaml"

PIDS=()
cleanup() { for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT

Xvfb ":$DISPLAY_NUMBER" -screen 0 1400x900x24 -nolisten tcp >"$WORK/xvfb.log" 2>&1 &
PIDS+=($!)
export DISPLAY=":$DISPLAY_NUMBER"
sleep 2
export ROS_MASTER_URI="http://localhost:11399"
export ROS_HOME="$WORK/ros_home"
roslaunch -p 11399 online_stereo_calibration play_bag.launch bag:="$WORK/drive/drive.bag" \
  rate:=0.5 ros_config:="$WORK/ros.yaml" rviz:=true rectify:="$RECTIFY" >"$WORK/roslaunch.log" 2>&1 &
PIDS+=($!)
sleep "$AFTER"
import -window root "$WORK/screen.png"
# Keep it small for the repository: 8-bit palette.
convert "$WORK/screen.png" -colors 256 -strip "PNG8:$OUT"
echo "wrote $OUT ($(stat -c %s "$OUT") bytes); logs in $WORK"
