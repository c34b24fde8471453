#!/usr/bin/env bash
# Builds everything (scripts/build.sh) and runs all tests with CTest.
# Exit code: CTest's. The output ends with CTest's summary line ("X% tests passed, Y tests
# failed out of Z") followed by a last line "N passed, N failed" (N counts CTest tests: one
# per gtest executable).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir="${OSC_BUILD_DIR:-build}"

if ! bash scripts/build.sh; then
  echo "run_tests: the build failed; no test ran (counted as 1 failure)" >&2
  echo "0 passed, 1 failed"
  exit 1
fi

if [[ -f /opt/ros/noetic/setup.bash ]]; then
  set +u
  # shellcheck disable=SC1091
  source /opt/ros/noetic/setup.bash
  set -u
fi

# ROS's test tools (rostest, roslaunch-check) run 'python3' from PATH: make it the system
# interpreter that has the ROS modules, not a pyenv/conda/venv one first on PATH.
if [[ -x /usr/bin/python3 ]]; then
  export PATH="/usr/bin:$PATH"
fi

log="$(mktemp)"
trap 'rm -f "$log"' EXIT
# CMake 3.16 (Ubuntu 20.04) has no 'ctest --test-dir': run from inside the build directory.
set +e
(cd "$build_dir" && ctest --output-on-failure) 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
set -e

# "100% tests passed, 0 tests failed out of 3"
summary="$(grep -E '[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "$log" | tail -n 1 || true)"
if [[ -n "$summary" ]]; then
  failed="$(sed -E 's/.*passed, ([0-9]+) tests? failed out of ([0-9]+).*/\1/' <<<"$summary")"
  total="$(sed -E 's/.*passed, ([0-9]+) tests? failed out of ([0-9]+).*/\2/' <<<"$summary")"
  echo "$summary"
  echo "$((total - failed)) passed, ${failed} failed"
elif [[ $status -eq 0 ]]; then
  echo "0 passed, 0 failed"
else
  echo "0 passed, 1 failed"
fi
exit "$status"
