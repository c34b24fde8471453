#!/usr/bin/env bash
# Every mechanism around the filter switched off on its own, on the measurement-level
# campaigns and paper_offroad, beside the shipped estimator and beside the shipped estimator on
# another seed range (the benches' own noise). Issue "One estimator a newcomer can read",
# step 3: a mechanism whose removal changes nothing beyond that noise is deleted.
#
#   bash scripts/ablation.sh [--out DIR] [--jobs J] [--runs N] [--no-build] [MECHANISM ...]
#
# Per mechanism (and for `shipped` and `noise`): the drawn default campaign (N runs, 200 by
# default), the phase-0 campaign (N runs) and paper_offroad seeds 1-27 (`noise`: campaign runs
# from seed 1001 and paper_offroad seeds 28-54); OUT/ablation.md gets
# one row per mechanism (honest runs / frames beyond 5 sigma per campaign, pooled RMSE of
# paper_offroad relative to shipped, pitch_l's on its own). About 20 min per mechanism on the
# 2-core machine. The image campaign and the KITTI test are not in it: run them for the
# mechanisms this table cannot judge (stereo_fit acts only on images) with scripts/results.sh
# and --config OUT/MECHANISM.yaml.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# mechanism -> the config keys that switch it off (config/default.yaml; docs/design.md).
declare -A off=(
  [hand_eye]="hand_eye_start: 0"
  [stereo_fit]="stereo_fit_start: 0"
  [baseline_from_motion]="baseline_from_motion: 0"
  [restart_from_estimate]="relinearization_frames: 0"
  [far_move_gate]="relinearization_far_threshold: 0"
  [tempering]="max_sigma_shrink_per_update: 0"
  [repeated_step_while_slow]="motion_relinearizations: 0"
  [point_count_hold]="min_points_to_update: 0"
  [sustained_jump_test]="jump_sustained_frames: 0"
  [fitted_turn]="jump_fit_rotation_sigma_deg: 0"
  [gap_check]="unobserved_gap_s: 0"
  [epipolar_knock_test]="epipolar_knock_false_alarm: 0"
  [score_widening]="jump_score_false_alarm: 0"
  [consistency_monitor]="consistency_window_s: 0"
  [time_offset_state]="initial_time_offset_sigma_ms: 0"
  [read_odometry_at_offset]="read_odometry_at_offset: 0"
  [velocity_error_states]="odometry_velocity_bias_sigma_mps: 0
odometry_forward_velocity_bias_sigma_mps: 0"
  [scale_in_sigmas]="odometry_scale_sigma_percent: 0"
  [camr_drift_rate]="camr_rotation_drift_rate_sigma_deg_per_min: 0"
  [excitation]="motion_excitation_window_s: 0"
)
order=(hand_eye stereo_fit baseline_from_motion restart_from_estimate far_move_gate tempering
  repeated_step_while_slow point_count_hold sustained_jump_test fitted_turn gap_check
  epipolar_knock_test score_widening consistency_monitor time_offset_state
  read_odometry_at_offset velocity_error_states scale_in_sigmas camr_drift_rate excitation)

out=out/ablation
jobs=2
runs=200
build=1
chosen=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    -h|--help) sed -n '2,16p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "ablation.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *)
      if [[ -z "${off[$1]+x}" ]]; then
        echo "ablation.sh: unknown mechanism '$1'; one of: ${order[*]}" >&2
        exit 2
      fi
      chosen+=("$1"); shift ;;
  esac
done
[[ ${#chosen[@]} -gt 0 ]] || chosen=("${order[@]}")

if [[ $build -eq 1 ]]; then bash scripts/build.sh; fi
bin="${OSC_BUILD_DIR:-build}/devel/lib/online_stereo_calibration"
[[ -x "$bin/campaign" ]] || { echo "ablation.sh: $bin/campaign not found; build first" >&2; exit 1; }
mkdir -p "$out"
out="$(cd "$out" && pwd)"
# The same absolute path that scripts/results.sh writes, so that its campaigns (the same
# inputs) can stand in for `shipped` and resume here.
sed "s|^trajectories_dir: .*|trajectories_dir: $(pwd)/config/../../shared/data/trajectories|" \
  config/campaign.yaml > "$out/drawn.yaml"
sed 's|^  yaw_phase_deg: \[0, 360\]|  yaw_phase_deg: 0       |' "$out/drawn.yaml" > "$out/phase0.yaml"
grep -q '^  yaw_phase_deg: 0 ' "$out/phase0.yaml" ||
  { echo "ablation.sh: could not fix yaw_phase_deg in the ranges copy" >&2; exit 1; }

# bench NAME CONFIG SEED: the three benches of one variant into OUT/NAME/.
bench() {
  local name="$1" config="$2" seed="$3" dir="$out/$1"
  echo "ablation.sh: $name ($(date +%H:%M:%S))"
  mkdir -p "$dir"
  local with_config=()
  [[ -n "$config" ]] && with_config=(--config "$config")
  # A campaign that finished (its summary written) is kept: an interrupted ablation resumes.
  local campaign
  for campaign in drawn phase0; do
    [[ -f "$dir/$campaign/summary.txt" ]] ||
      "$bin/campaign" --runs "$runs" --jobs "$jobs" --seed "$seed" --ranges "$out/$campaign.yaml" \
        "${with_config[@]}" --out "$dir/$campaign" > "$dir/$campaign.log" 2>&1
  done
  # paper_offroad seeds 1-27; the noise bench draws 28-54.
  local first=1
  [[ "$seed" == 1 ]] || first=28
  for s in $(seq "$first" $((first + 26))); do
    [[ -f "$dir/po/seed_$s/estimates.csv" ]] ||
      "$bin/calibrate_simulation" --scenario paper_offroad --seed "$s" "${with_config[@]}" \
        --out "$dir/po/seed_$s" > /dev/null 2>&1
  done
}

bench shipped "" 1
bench noise "" 1001   # the same benches, runs drawn from another seed range
for mechanism in "${chosen[@]}"; do
  printf '%s\n' "${off[$mechanism]}" > "$out/$mechanism.yaml"
  bench "$mechanism" "$out/$mechanism.yaml" 1
done
/usr/bin/python3 scripts/results_tables.py ablation "$out" shipped noise "${chosen[@]}" \
  > "$out/ablation.md"
cat "$out/ablation.md"
