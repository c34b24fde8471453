#!/usr/bin/env bash
# Regenerates the benches of docs/RESULTS.md: runs them and writes one Markdown table per
# bench into OUT/NAME.md (and the runs' files into OUT/NAME/).
#
#   bash scripts/results.sh [--out DIR] [--jobs J] [--config PARAMS.yaml] [--no-build]
#                           [--update-docs] [BENCH ...]
#
# --config runs every bench with those estimator keys over the defaults (a variant, e.g. a
# mechanism switched off for the ablation); the kitti bench, a test's diagnostic, is then
# skipped.
#
# Benches (all by default), with their time on the 2-core development machine:
#   paper_offroad    calibrate_simulation, seeds 1-27, pooled RMSE over frames 1000-1150   ~3 min
#   campaign_drawn   campaign, 200 runs of the shipped ranges (config/campaign.yaml)       ~7 min
#   campaign_phase0  the same with the steering's phase at frame 0 fixed (yaw_phase_deg 0) ~6 min
#   campaign_images  campaign --images, 20 runs of 200 frames (renderer + front end)   ~15-25 min
#   kitti            test_kitti's diagnostic on ../shared/data/kitti_odometry_51           ~1 min
#   kitti_raw        evaluate --kitti-raw on ../shared/data/kitti_raw_2011_09_26_200,
#                    from the paper's start errors                                        ~15 s
# The campaigns and the KITTI bench need ../shared/data (the recorded trajectories, the
# KITTI stretches); without it the campaigns draw no recorded drive and say so, and the
# KITTI bench is skipped.
#
# Runs already in OUT are not run again (delete OUT/NAME to rerun a bench); the campaigns
# resume where they stopped. --update-docs puts the tables into docs/RESULTS.md between its
# <!-- results:NAME --> markers, under a line naming the commit they were measured on.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

out=out/results
jobs=2
build=1
update_docs=0
config=""
benches=()
all=(paper_offroad campaign_drawn campaign_phase0 campaign_images kitti kitti_raw)
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --config) config="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --no-build) build=0; shift ;;
    --update-docs) update_docs=1; shift ;;
    -h|--help) sed -n '2,26p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "results.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *)
      if [[ " ${all[*]} " != *" $1 "* ]]; then
        echo "results.sh: unknown bench '$1'; one of: ${all[*]}" >&2
        exit 2
      fi
      benches+=("$1"); shift ;;
  esac
done
[[ ${#benches[@]} -gt 0 ]] || benches=("${all[@]}")
with_config=()
if [[ -n "$config" ]]; then
  [[ -f "$config" ]] || { echo "results.sh: --config $config not found" >&2; exit 2; }
  [[ $update_docs -eq 0 ]] ||
    { echo "results.sh: --update-docs takes the shipped configuration, not --config" >&2; exit 2; }
  with_config=(--config "$config")
fi

if [[ $build -eq 1 ]]; then bash scripts/build.sh; fi
bin="${OSC_BUILD_DIR:-build}/devel/lib/online_stereo_calibration"
if [[ ! -x "$bin/campaign" ]]; then
  echo "results.sh: $bin/campaign not found; build first (bash scripts/build.sh)" >&2
  exit 1
fi
python=/usr/bin/python3
tables="$(pwd)/scripts/results_tables.py"
shared="$(cd .. && pwd)/shared/data"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

started() { echo "results.sh: $1 ($(date +%H:%M:%S))"; }

# The shipped ranges with the recorded trajectories' directory made absolute (the copy lives
# in OUT), and optionally more lines appended.
ranges_copy() {
  local target="$1"; shift
  sed "s|^trajectories_dir: .*|trajectories_dir: $(pwd)/config/../../shared/data/trajectories|" \
    config/campaign.yaml > "$target"
  local line
  for line in "$@"; do
    sed -i "$line" "$target"
  done
}

run_campaign() {
  local name="$1"; shift
  started "$name"
  "$bin/campaign" --out "$out/$name" --jobs "$jobs" "${with_config[@]}" "$@" \
    > "$out/$name.log" 2>&1
  "$python" "$tables" campaign "$out/$name" > "$out/$name.md"
  cat "$out/$name.md"
}

for bench in "${benches[@]}"; do
  case "$bench" in
    paper_offroad)
      started paper_offroad
      dirs=()
      for seed in $(seq 1 27); do
        dir="$out/paper_offroad/seed_$seed"
        mkdir -p "$out/paper_offroad"
        [[ -f "$dir/estimates.csv" ]] ||
          "$bin/calibrate_simulation" --scenario paper_offroad --seed "$seed" --out "$dir" \
            "${with_config[@]}" > "$dir.log" 2>&1
        dirs+=("$dir")
      done
      "$python" "$tables" rmse "${dirs[@]}" --window 1000 1150 > "$out/paper_offroad.md"
      cat "$out/paper_offroad.md"
      ;;
    campaign_drawn)
      ranges_copy "$out/drawn.yaml"
      run_campaign campaign_drawn --runs 200 --ranges "$out/drawn.yaml"
      ;;
    campaign_phase0)
      ranges_copy "$out/phase0.yaml" 's|^  yaw_phase_deg: \[0, 360\]|  yaw_phase_deg: 0       |'
      grep -q '^  yaw_phase_deg: 0 ' "$out/phase0.yaml" ||
        { echo "results.sh: could not fix yaw_phase_deg in the ranges copy" >&2; exit 1; }
      run_campaign campaign_phase0 --runs 200 --ranges "$out/phase0.yaml"
      ;;
    campaign_images)
      ranges_copy "$out/drawn.yaml"
      run_campaign campaign_images --runs 20 --frames 200 --images --ranges "$out/drawn.yaml"
      ;;
    kitti)
      if [[ -n "$config" ]]; then
        echo "results.sh: kitti skipped: its diagnostic takes no --config"
        continue
      fi
      if [[ ! -d "$shared/kitti_odometry_51" ]]; then
        echo "results.sh: kitti skipped: $shared/kitti_odometry_51 not found"
        continue
      fi
      started kitti
      "$bin/test_kitti" --gtest_also_run_disabled_tests --gtest_filter='Kitti.DISABLED_Diagnostic' \
        > "$out/kitti.log" 2>&1
      "$python" "$tables" kitti "$out/kitti.log" > "$out/kitti.md"
      cat "$out/kitti.md"
      ;;
    kitti_raw)
      drive="$shared/kitti_raw_2011_09_26_200"
      if [[ ! -d "$drive" ]]; then
        echo "results.sh: kitti_raw skipped: $drive not found"
        continue
      fi
      started kitti_raw
      # The drive's truth (its README: KITTI's calibration chain) plus the paper's start
      # errors, +0.5 m and +10 deg on each of x_caml's values and +0.1 m on yr.
      cat > "$out/kitti_raw_guess.yaml" <<'END'
vehicle_to_left: [1.5833019442051151, 0.19011110597932479, 1.2299198216595262, 0.16034062760679291, 0.16187376430050837, 0.18303138768827343]
left_to_right: [-0.0039992335629800901, -0.43712680515653102, -0.0052845250069352354, 0.0186104888807654, 0.0089985889355015131, -0.030677614122532119]
END
      "$bin/evaluate" --kitti-raw "$drive" --initial-guess "$out/kitti_raw_guess.yaml" \
        --out "$out/kitti_raw" "${with_config[@]}" > "$out/kitti_raw.log" 2>&1
      "$python" "$tables" kitti_raw "$out/kitti_raw" > "$out/kitti_raw.md"
      cat "$out/kitti_raw.md"
      ;;
  esac
done
if [[ $update_docs -eq 1 ]]; then
  commit="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
  dirty="$(git status --porcelain --untracked-files=no 2>/dev/null | grep -q . && echo ' + local changes' || true)"
  "$python" "$tables" splice docs/RESULTS.md "$out" \
    --stamp "Measured on main \`$commit\`$dirty, $(date +%Y-%m-%d), by \`bash scripts/results.sh\`."
fi
echo "results.sh: done; tables in $out/*.md"
