#!/usr/bin/env bash
# Installs missing dependencies, then builds the package (libraries, tools, tests) with plain
# CMake in ./build (override with OSC_BUILD_DIR). On Ubuntu 20.04 ROS Noetic is sourced from
# /opt/ros/noetic; on Debian 12 ROS lives in /usr and needs no sourcing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/install_deps.sh

if [[ -f /opt/ros/noetic/setup.bash ]]; then
  # setup.bash reads unset variables.
  set +u
  # shellcheck disable=SC1091
  source /opt/ros/noetic/setup.bash
  set -u
fi

build_dir="${OSC_BUILD_DIR:-build}"
jobs="${OSC_JOBS:-2}"

# catkin's CMake and test wrappers need a python3 with the ROS modules: the system one, not
# whatever python3 comes first on PATH (pyenv, conda, a venv).
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=/usr/bin/python3

# With catkin, gtest targets are EXCLUDE_FROM_ALL and collected in the 'tests' target;
# without catkin they are part of 'all' and there is no 'tests' target.
targets=(all)
# (Capture first: with pipefail, grep -q closing the pipe early would fail the test.)
help_text="$(cmake --build "$build_dir" --target help 2>/dev/null || true)"
if grep -Eq '^(\.\.\. )?tests(:| |$)' <<<"$help_text"; then
  targets+=(tests)
fi
for target in "${targets[@]}"; do
  cmake --build "$build_dir" --target "$target" -j "$jobs"
done
