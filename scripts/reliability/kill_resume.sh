#!/usr/bin/env bash
# kill -9 test of the calibration node's saving and resuming (issue 17).
#
# Renders (or reuses) the off-road drive at 320x240 (as soak.sh), starts a roscore on a free
# port unless one answers there, loads config/default.yaml and config/ros.yaml into the node's
# namespace with `calibration_file` a file in the run directory, `save_interval` 0.5 s and
# `resume: true`, plays the bag in a loop (`rosbag play -l --clock`) and runs
# calibration_node (as launch/calibrate.launch does: /stereo/online_stereo_calibration,
# odom:=/odom) K+1 times. Each start is watched by `monitor.py first`: its first ~calibration
# must equal the calibration file as it was before the start (parameters to 1e-9 absolute,
# covariance to 1e-9 relative; the first start has no file and uses the start guess of
# test/ros/convergence.test). After the first message and a random delay (seeded: the same
# delays every run) the node gets SIGKILL and the file is checked (`monitor.py validate`:
# the reader's rules, every key the node writes, ends with a newline). The last start is
# stopped with SIGINT (its shutdown save is checked too). Prints a table per kill and a
# summary (kills, files valid, resumes exact, temporary files left by a kill during a write)
# and exits non-zero on any failure. Every process it started is stopped on exit.
#
#   bash scripts/reliability/kill_resume.sh [--kills K] [--seed S] [--port PORT]
#        [--save-interval S] [--min-delay S] [--max-delay S]
#
#   --kills K          kill -9 count (default 18)
#   --seed S           seed of the delays (bash RANDOM; default 17)
#   --port PORT        ROS master port (default: a free one; an existing master there is used)
#   --save-interval S  the node's save_interval (default 0.5 s of sim time)
#   --min-delay S, --max-delay S
#                      delay between the first message of a start and its kill, uniform
#                      (default 1.0 and 4.0 s wall)
#
# Environment: OSC_BUILD_DIR (default build), OSC_REL_OUT (default out/reliability: the drive
# cache, and kill_resume/ with the logs, the file before each start and each start's first
# message), OSC_REL_FRAMES (default 300).
# Default run: about 2 min on a 2-core machine.
set -euo pipefail

KILLS=18
SEED=17
PORT=""
SAVE_INTERVAL=0.5
MIN_DELAY=1.0
MAX_DELAY=4.0
while (($#)); do
  case "$1" in
    --kills) KILLS="$2"; shift 2 ;;
    --seed) SEED="$2"; shift 2 ;;
    --port) PORT="$2"; shift 2 ;;
    --save-interval) SAVE_INTERVAL="$2"; shift 2 ;;
    --min-delay) MIN_DELAY="$2"; shift 2 ;;
    --max-delay) MAX_DELAY="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed -e '$d' -e 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "kill_resume.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$KILLS" =~ ^[0-9]+$ ]] || { echo "kill_resume.sh: --kills must be an integer" >&2; exit 2; }
[[ "$SEED" =~ ^[0-9]+$ ]] || { echo "kill_resume.sh: --seed must be an integer" >&2; exit 2; }
set --  # (catkin's setup.bash, sourced by common.sh, would read our options)
# shellcheck source=scripts/reliability/common.sh
source "$(dirname "$0")/common.sh"

trap rel_cleanup EXIT
trap 'exit 130' INT TERM
T0=$SECONDS
rel_log "load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
rel_render_drive
RUN="$REL_OUT/kill_resume"
rm -rf "$RUN"
mkdir -p "$RUN"
FILE="$RUN/calibration.yaml"
[[ -n "$PORT" ]] || PORT="$(rel_free_port)"
rel_start_master "$PORT" "$RUN"

NS="/stereo/online_stereo_calibration"
rel_guess_file "$RUN/guess.yaml"
rel_ros_config "$RUN/ros.yaml" "$RUN/guess.yaml" calibration_file "\"$FILE\"" resume true \
  save_interval "$SAVE_INTERVAL"
rosparam load "$REL_ROOT/config/default.yaml" "$NS"
rosparam load "$RUN/ros.yaml" "$NS"

rosbag play -l --clock -q "$REL_BAG" > "$RUN/rosbag.log" 2>&1 &
REL_PIDS+=($!)
rel_log "playing $REL_BAG ($REL_BAG_SECONDS s) in a loop; $KILLS kills, seed $SEED, save_interval $SAVE_INTERVAL s; logs in $RUN"

# json_field FILE KEY: one field of a one-line JSON object ("" when absent).
json_field() {
  python3 -c 'import json,sys; v=json.load(open(sys.argv[1])).get(sys.argv[2]); print("" if v is None else v)' "$1" "$2" 2>/dev/null || true
}

RANDOM=$SEED
FAILURES=()
VALID=0
CHECKED=0
EXACT=0
MAX_DP=0
MAX_DC=0
echo "(start k: resumed = its first ~calibration vs the file before it; delay_s: then SIGKILL;" \
  "dparam: largest |parameter diff|, dcov: largest covariance diff / largest entry; seq: of that message)"
printf '%-5s %8s %-28s %-7s %9s %9s %5s\n' start delay_s "file after the kill" resumed dparam dcov seq
for ((k = 0; k <= KILLS; k++)); do
  # The file as this start will find it.
  EXPECT=()
  if [[ -f "$FILE" ]]; then
    cp "$FILE" "$RUN/before_$k.yaml"
    EXPECT=(--file "$RUN/before_$k.yaml")
  fi
  rm -f "$RUN/first.ready"
  python3 "$REL_MONITOR" first "${EXPECT[@]}" --ready-file "$RUN/first.ready" --timeout 60 \
    > "$RUN/first_$k.json" 2> "$RUN/first_$k.log" &
  MONITOR_PID=$!
  REL_PIDS+=("$MONITOR_PID")
  for ((i = 0; i < 300; i++)); do
    [[ -f "$RUN/first.ready" ]] && break
    kill -0 "$MONITOR_PID" 2>/dev/null || break
    sleep 0.1
  done
  sleep 0.3  # the monitor's subscription registered before the node advertises

  "$REL_BIN/calibration_node" __name:=online_stereo_calibration __ns:=/stereo odom:=/odom \
    > "$RUN/node_$k.log" 2>&1 &
  NODE_PID=$!
  REL_PIDS+=("$NODE_PID")
  MONITOR_STATUS=0
  wait "$MONITOR_PID" || MONITOR_STATUS=$?
  rel_forget "$MONITOR_PID"
  RESUMED="-"; DP="-"; DC="-"
  SEQ="$(json_field "$RUN/first_$k.json" seq)"
  if ((${#EXPECT[@]})); then
    CHECKED=$((CHECKED + 1))
    DP="$(json_field "$RUN/first_$k.json" max_abs_parameter_diff)"
    DC="$(json_field "$RUN/first_$k.json" max_rel_covariance_diff)"
    [[ -z "$DP" ]] || DP="$(printf '%.1e' "$DP")"
    [[ -z "$DC" ]] || DC="$(printf '%.1e' "$DC")"
    if [[ "$SEQ" != 0 ]]; then
      RESUMED=MISSED
      FAILURES+=("start $k: the monitor missed the first message (got seq ${SEQ:-none}): not checked")
    elif ((MONITOR_STATUS == 0)); then
      EXACT=$((EXACT + 1)); RESUMED=exact
    else
      RESUMED=DIFFERS
      FAILURES+=("start $k: first message is not the file it resumed from: $(cat "$RUN/first_$k.json")")
    fi
    [[ -n "$DP" ]] && MAX_DP="$(awk -v a="$MAX_DP" -v b="$DP" 'BEGIN { print (b > a) ? b : a }')"
    [[ -n "$DC" ]] && MAX_DC="$(awk -v a="$MAX_DC" -v b="$DC" 'BEGIN { print (b > a) ? b : a }')"
  elif ((MONITOR_STATUS != 0)); then
    FAILURES+=("start $k: no valid first message: $(cat "$RUN/first_$k.json")")
  fi

  if ((k == KILLS)); then
    # The last start: a normal shutdown, whose save must be valid too.
    sleep 1
    rel_stop "$NODE_PID"
    rel_forget "$NODE_PID"
    if python3 "$REL_MONITOR" validate "$FILE" > "$RUN/after_$k.json"; then
      STATE="shutdown save valid"
    else
      STATE="shutdown save INVALID"
      FAILURES+=("after the final SIGINT: $(cat "$RUN/after_$k.json")")
    fi
    printf '%-5s %8s %-28s %-7s %9s %9s %5s\n' "$k" "-" "$STATE" "$RESUMED" "$DP" "$DC" "$SEQ"
    break
  fi

  DELAY="$(awk -v r="$RANDOM" -v a="$MIN_DELAY" -v b="$MAX_DELAY" 'BEGIN { printf "%.3f", a + (b - a) * r / 32767 }')"
  sleep "$DELAY"
  if ! kill -0 "$NODE_PID" 2>/dev/null; then
    FAILURES+=("start $k: the node died by itself before its kill (log: $RUN/node_$k.log)")
  fi
  kill -KILL "$NODE_PID" 2>/dev/null || true
  wait "$NODE_PID" 2>/dev/null || true
  rel_forget "$NODE_PID"
  if python3 "$REL_MONITOR" validate "$FILE" > "$RUN/after_$k.json"; then
    VALID=$((VALID + 1))
    if [[ -f "$RUN/before_$k.yaml" ]] && cmp -s "$FILE" "$RUN/before_$k.yaml"; then
      STATE="valid (unchanged)"
    else
      STATE="valid (stamp $(printf '%.1f' "$(sed -n 's/^stamp: //p' "$FILE")"))"
    fi
  else
    STATE="INVALID"
    FAILURES+=("kill $((k + 1)): $(cat "$RUN/after_$k.json")")
  fi
  printf '%-5s %8s %-28s %-7s %9s %9s %5s\n' "$k" "$DELAY" "$STATE" "$RESUMED" "$DP" "$DC" "$SEQ"
done

shopt -s nullglob
TEMPS=("$FILE".tmp.*)
shopt -u nullglob
echo "kills: $KILLS; files valid after a kill: $VALID/$KILLS; resumes exact: $EXACT/$CHECKED" \
  "(largest |parameter diff| $MAX_DP, largest covariance diff $MAX_DC of its largest entry);" \
  "temporary files left by a kill during a write: ${#TEMPS[@]}"
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg); $((SECONDS - T0)) s wall; logs: $RUN"
for f in "${FAILURES[@]}"; do echo "FAIL: $f"; done
if ((${#FAILURES[@]} == 0)); then echo "kill_resume: PASS"; exit 0; fi
echo "kill_resume: FAIL"
exit 1
