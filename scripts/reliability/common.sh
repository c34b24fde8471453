# shellcheck shell=bash
# shellcheck disable=SC2034  # REL_* variables are used by the scripts that source this file
# Shared by scripts/reliability/soak.sh and kill_resume.sh (sourced, not run): paths, the
# cached drive bag, a private ROS master, the node's parameters, process bookkeeping.
#
# Environment: OSC_BUILD_DIR (default build), OSC_REL_OUT (cache and logs, default
# out/reliability), OSC_REL_FRAMES (frames of the drive, default 300 = 30 s at 10 Hz).

REL_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
REL_BUILD="${OSC_BUILD_DIR:-build}"
[[ "$REL_BUILD" = /* ]] || REL_BUILD="$REL_ROOT/$REL_BUILD"
REL_BIN="$REL_BUILD/devel/lib/online_stereo_calibration"
REL_OUT="${OSC_REL_OUT:-$REL_ROOT/out/reliability}"
REL_FRAMES="${OSC_REL_FRAMES:-300}"
REL_MONITOR="$REL_ROOT/scripts/reliability/monitor.py"
REL_TOPIC=/stereo/online_stereo_calibration/calibration  # ~calibration of calibrate.launch's node
export PATH="/usr/bin:$PATH"  # ROS's python tools need the system python3

if [[ -f "$REL_BUILD/devel/setup.bash" ]]; then
  set +u
  # shellcheck disable=SC1091
  source "$REL_BUILD/devel/setup.bash"
  set -u
fi
export ROS_PACKAGE_PATH="$REL_ROOT:${ROS_PACKAGE_PATH:-}"
for tool in simulate calibration_node; do
  [[ -x "$REL_BIN/$tool" ]] || { echo "missing $REL_BIN/$tool: build it first" >&2; exit 1; }
done

# Processes this script started (pids), stopped by rel_cleanup in reverse order.
REL_PIDS=()

rel_log() { printf '[%s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }

# rel_stop PID: SIGINT (roslaunch, roscore and rosbag shut their children down on it), then
# SIGKILL after 10 s. Only ever a pid this script started.
rel_stop() {
  local pid="$1" i
  kill -0 "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null || true; return 0; }
  kill -INT "$pid" 2>/dev/null || true
  for ((i = 0; i < 100; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null || true
}

# rel_forget PID: drop a pid that has been reaped (so that a later process reusing it is
# never signalled by rel_cleanup).
rel_forget() {
  local kept=() pid
  for pid in "${REL_PIDS[@]}"; do [[ "$pid" == "$1" ]] || kept+=("$pid"); done
  REL_PIDS=("${kept[@]}")
}

rel_cleanup() {
  local i
  for ((i = ${#REL_PIDS[@]} - 1; i >= 0; i--)); do rel_stop "${REL_PIDS[i]}"; done
  REL_PIDS=()
}

# rel_render_drive: the off-road drive at 320x240 (fx 300, as the rostests), REL_FRAMES frames,
# rendered once into $REL_OUT/drive_<frames>/ (simulate reuses a bag made from the same
# scenario file and frame count). Sets REL_BAG and REL_BAG_SECONDS.
rel_render_drive() {
  mkdir -p "$REL_OUT"
  local scenario="$REL_OUT/paper_offroad_320x240.yaml" camera
  camera='{width: 320, height: 240, fx: 300, fy: 300, cx: 159.5, cy: 119.5}'
  sed -e "s|^name:.*|name: paper_offroad_320x240|" \
      -e "s|^left_camera:.*|left_camera: $camera|" \
      -e "s|^right_camera:.*|right_camera: $camera|" \
      "$REL_ROOT/config/scenarios/paper_offroad.yaml" > "$scenario.new"
  if cmp -s "$scenario.new" "$scenario"; then rm "$scenario.new"; else mv "$scenario.new" "$scenario"; fi
  REL_BAG="$REL_OUT/drive_$REL_FRAMES/drive.bag"
  rel_log "drive: $REL_BAG ($REL_FRAMES frames, 320x240; rendered unless cached)"
  "$REL_BIN/simulate" --scenario "$scenario" --frames "$REL_FRAMES" --out "$REL_OUT/drive_$REL_FRAMES" \
    2> "$REL_OUT/simulate.log" || { cat "$REL_OUT/simulate.log" >&2; return 1; }
  REL_BAG_SECONDS="$(python3 -c 'import rosbag,sys; b=rosbag.Bag(sys.argv[1]); print("%.1f" % (b.get_end_time()-b.get_start_time()))' "$REL_BAG")"
}

# rel_free_port: a TCP port nobody listens on now.
rel_free_port() {
  python3 -c 'import socket; s=socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])'
}

rel_master_online() {
  python3 -c 'import rosgraph,sys; sys.exit(0 if rosgraph.is_master_online() else 1)' 2>/dev/null
}

# rel_start_master PORT LOGDIR: ROS_MASTER_URI=http://localhost:PORT; starts roscore there
# unless a master already answers (then it is used as it is). Sets /use_sim_time true.
rel_start_master() {
  local port="$1" logdir="$2" i
  export ROS_MASTER_URI="http://localhost:$port"
  export ROS_HOME="$logdir/ros_home"
  if rel_master_online; then
    rel_log "using the ROS master already at $ROS_MASTER_URI"
  else
    roscore -p "$port" > "$logdir/roscore.log" 2>&1 &
    REL_PIDS+=($!)
    for ((i = 0; i < 150; i++)); do
      rel_master_online && break
      sleep 0.2
    done
    rel_master_online || { echo "roscore did not come up on port $port" >&2; return 1; }
    rel_log "roscore started at $ROS_MASTER_URI (pid ${REL_PIDS[-1]})"
  fi
  rosparam set /use_sim_time true
}

# rel_guess_file PATH: the start guess of test/ros/convergence.test (the drive's truth
# x_caml = [1.5, 0.15, 1.3, 0, 0.05, 0], x_camr = [0, -0.3, 0, 0, 0, 0], off by 10 cm / 3 deg
# on the left camera and 2 cm / 0.3 deg on the right one).
rel_guess_file() {
  cat > "$1" <<'YAML'
vehicle_to_left: [1.6, 0.05, 1.4, 0.05235987755982989, -0.0023598775598298873, 0.05235987755982989]
left_to_right: [0.0, -0.28, 0.0, 0.0, 0.0, 0.005235987755982988]
YAML
}

# rel_ros_config OUT GUESS [KEY VALUE]...: config/ros.yaml with initial_guess_source file
# (GUESS) and the given keys replaced.
rel_ros_config() {
  local out="$1" guess="$2"
  shift 2
  local args=(-e 's|^initial_guess_source:.*|initial_guess_source: file|'
              -e "s|^initial_guess_file:.*|initial_guess_file: \"$guess\"|")
  while (($# >= 2)); do
    args+=(-e "s|^$1:.*|$1: $2|")
    shift 2
  done
  sed "${args[@]}" "$REL_ROOT/config/ros.yaml" > "$out"
}
