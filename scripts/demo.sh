#!/usr/bin/env bash
# The README's first command: builds the package, calibrates a simulated paper-like off-road
# drive (start errors 0.5 m / 10 deg, a 10 deg yaw step of the camera at frame 774), prints
# the Table I comparison with the paper and writes convergence plots like its Fig. 5 and 6.
# Output: out/demo/{estimates.csv,reference.csv,vehicle_to_left.png,left_to_right.png,errors.png}
# Environment: OSC_BUILD_DIR (default build), OSC_DEMO_SCENARIO (default paper_offroad),
# OSC_DEMO_BIN (path of the demo program, found under the build directory by default).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir="${OSC_BUILD_DIR:-build}"
out_dir="out/demo"
scenario="${OSC_DEMO_SCENARIO:-paper_offroad}"
step_frame=774

bash scripts/build.sh

# With catkin found, executables land in devel/lib/<package>/; without it in the build root.
# OSC_DEMO_BIN overrides the search.
find_demo_binary() {
  local candidate
  for candidate in \
    "$build_dir/devel/lib/online_stereo_calibration/calibrate_simulation" \
    "$build_dir/calibrate_simulation" \
    "$build_dir/bin/calibrate_simulation"; do
    if [[ -x "$candidate" && -f "$candidate" ]]; then
      echo "$candidate"
      return 0
    fi
  done
  find "$build_dir" -type f -name calibrate_simulation -perm -u+x -print -quit 2>/dev/null
}
binary="${OSC_DEMO_BIN:-$(find_demo_binary)}"
if [[ -z "$binary" || ! -x "$binary" ]]; then
  echo "demo: calibrate_simulation was not found under $build_dir (is it built yet?)" >&2
  exit 1
fi

mkdir -p "$out_dir"
rm -f "$out_dir"/estimates.csv "$out_dir"/reference.csv "$out_dir"/*.png
echo "demo: $binary --scenario $scenario --out $out_dir"
"$binary" --scenario "$scenario" --out "$out_dir"

for file in estimates.csv reference.csv; do
  if [[ ! -s "$out_dir/$file" ]]; then
    echo "demo: $binary did not write $out_dir/$file" >&2
    exit 1
  fi
done

# The system python3: the first python3 on PATH may lack matplotlib (pyenv, venv).
plots="$(/usr/bin/python3 scripts/plot_convergence.py --out "$out_dir" --step-frame "$step_frame")"
echo
echo "Convergence plots:"
grep -E '\.png$' <<<"$plots" | sed 's/^/  /'
echo "Per-frame estimates: $out_dir/estimates.csv (reference: $out_dir/reference.csv)"
