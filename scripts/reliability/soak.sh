#!/usr/bin/env bash
# Soak test of the calibration node (issue 17): a simulated drive played in a loop.
#
# Renders (or reuses) the off-road drive at 320x240 into out/reliability/drive_<frames>/
# (`simulate`), starts a roscore on a free port unless one answers there, launches the node
# with launch/calibrate.launch (sim time, start guess of test/ros/convergence.test), plays
# the bag with `rosbag play -l --clock` for N loops and watches it with
# scripts/reliability/monitor.py: the node's RSS every few seconds (/proc), ~calibration
# messages and any NaN/Inf in them, and /diagnostics "<node>: calibration" statuses, per loop
# (a loop ends when /clock jumps back). Prints a table (per loop: wall time, messages, NaN,
# statuses, RSS at the loop's end, states and status levels; RSS at start and max) and exits
# non-zero if the node died, a message held a NaN, a loop had no message or no status, or
# the run timed out. Every process it started is stopped on exit.
#
#   bash scripts/reliability/soak.sh [--loops N] [--port PORT] [--rate R] [--rss-period S]
#
#   --loops N       loops of the drive (default 3; 300 frames = 30 s each)
#   --port PORT     ROS master port (default: a free one; an existing master there is used)
#   --rate R        playback rate (default 1)
#   --rss-period S  seconds between RSS samples (default 2)
#
# Environment: OSC_BUILD_DIR (default build), OSC_REL_OUT (default out/reliability: the drive
# cache, and soak/ with the logs and soak.json), OSC_REL_FRAMES (default 300).
# Default run: about 1.5 min on a 2-core machine (rendering the drive the first time: 5 s more).
set -euo pipefail

LOOPS=3
PORT=""
RATE=1
RSS_PERIOD=2
while (($#)); do
  case "$1" in
    --loops) LOOPS="$2"; shift 2 ;;
    --port) PORT="$2"; shift 2 ;;
    --rate) RATE="$2"; shift 2 ;;
    --rss-period) RSS_PERIOD="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed -e '$d' -e 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "soak.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$LOOPS" =~ ^[1-9][0-9]*$ ]] || { echo "soak.sh: --loops must be a positive integer" >&2; exit 2; }
set --  # (catkin's setup.bash, sourced by common.sh, would read our options)
# shellcheck source=scripts/reliability/common.sh
source "$(dirname "$0")/common.sh"

trap rel_cleanup EXIT
trap 'exit 130' INT TERM
T0=$SECONDS
rel_log "load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
rel_render_drive
RUN="$REL_OUT/soak"
rm -rf "$RUN"
mkdir -p "$RUN"
[[ -n "$PORT" ]] || PORT="$(rel_free_port)"
rel_start_master "$PORT" "$RUN"

rel_guess_file "$RUN/guess.yaml"
rel_ros_config "$RUN/ros.yaml" "$RUN/guess.yaml"
roslaunch online_stereo_calibration calibrate.launch ros_config:="$RUN/ros.yaml" \
  > "$RUN/roslaunch.log" 2>&1 &
LAUNCH_PID=$!
REL_PIDS+=("$LAUNCH_PID")
NODE_PID=""
for ((i = 0; i < 300; i++)); do
  NODE_PID="$(pgrep -P "$LAUNCH_PID" -f calibration_node || true)"
  [[ -n "$NODE_PID" ]] && break
  kill -0 "$LAUNCH_PID" 2>/dev/null || break
  sleep 0.1
done
[[ -n "$NODE_PID" ]] || { cat "$RUN/roslaunch.log" >&2; echo "soak.sh: the node did not start" >&2; exit 1; }
rel_log "node pid $NODE_PID (roslaunch pid $LAUNCH_PID); logs in $RUN"

TIMEOUT="$(awk -v n="$LOOPS" -v s="$REL_BAG_SECONDS" -v r="$RATE" 'BEGIN { print int(n * s / r * 3 + 120) }')"
python3 "$REL_MONITOR" soak --pid "$NODE_PID" --loops "$LOOPS" --rss-period "$RSS_PERIOD" \
  --timeout "$TIMEOUT" --ready-file "$RUN/monitor.ready" --out "$RUN/soak.json" \
  > "$RUN/monitor.out" 2> "$RUN/monitor.log" &
MONITOR_PID=$!
REL_PIDS+=("$MONITOR_PID")
for ((i = 0; i < 300; i++)); do
  [[ -f "$RUN/monitor.ready" ]] && break
  kill -0 "$MONITOR_PID" 2>/dev/null || break
  sleep 0.1
done
[[ -f "$RUN/monitor.ready" ]] || { cat "$RUN/monitor.log" >&2; echo "soak.sh: the monitor did not start" >&2; exit 1; }

rel_log "playing $REL_BAG ($REL_BAG_SECONDS s) in a loop, $LOOPS loops at rate $RATE"
rosbag play -l --clock -q -r "$RATE" "$REL_BAG" > "$RUN/rosbag.log" 2>&1 &
REL_PIDS+=($!)
STATUS=0
wait "$MONITOR_PID" || STATUS=$?
rel_forget "$MONITOR_PID"
cat "$RUN/monitor.out"
if ! kill -0 "$NODE_PID" 2>/dev/null; then
  echo "FAIL: the node (pid $NODE_PID) is not running at the end"
  STATUS=1
fi
if grep -q "process has died" "$RUN/roslaunch.log"; then
  echo "FAIL: roslaunch reports: $(grep "process has died" "$RUN/roslaunch.log" | head -n 1)"
  STATUS=1
fi
CPU="$(ps -o times= -p "$NODE_PID" 2>/dev/null | tr -d ' ' || true)"
echo "node CPU time ${CPU:-?} s; load average at the end: $(cut -d' ' -f1-3 /proc/loadavg); total ${SECONDS}s wall (script $((SECONDS - T0)) s)"
echo "logs: $RUN (soak.json: every RSS sample)"
if ((STATUS == 0)); then echo "soak: PASS"; else echo "soak: FAIL"; fi
exit "$STATUS"
