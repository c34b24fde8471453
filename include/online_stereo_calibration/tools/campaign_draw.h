/// @file campaign_draw.h
/// @brief Drawing one run of a campaign from its ranges and seed: the scenario, the image
/// options and the drawn settings (the CSV's setting columns).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"

namespace osc {

/// The drawn settings of a run as (column name, value) pairs, in campaignSettingNames() order.
using CampaignSettings = std::vector<std::pair<std::string, std::string>>;

/// One run of a campaign, ready to simulate.
struct CampaignRunSpec {
  int run = 0;        ///< index k of the run, from 0
  unsigned seed = 0;  ///< seed S + k: drives every draw and the scenario's random streams
  MeasurementScenario scenario;
  ImageScenarioOptions image_options;  ///< used with --images
  CampaignSettings settings;
  /// Why the run cannot be made (e.g. a recorded trajectory unreadable or shorter than the
  /// drive), "" if it can; the settings are complete either way.
  std::string error;
};

/// The names of the drawn-setting columns, in order (docs/campaign.md explains each):
/// baseline_m, image_width, image_height, focal_px, lens, k1, mounting, pitch_down_deg,
/// motion, trajectory, trajectory_start_s, speed_mps, roll_pitch_std_deg, heave_m,
/// yaw_rate_deg_s, yaw_phase_deg, stops, stop_s, start_caml_m, start_caml_deg,
/// start_baseline_percent, start_camr_m, start_camr_deg, event, event_frame, event_deg,
/// event_mm_per_min, odo_time_offset_ms, odo_scale_percent, odo_rotation_bias_deg_s,
/// odo_velocity_bias_mps, blind_s, moving_fraction, moving_speed_mps, and with @p images also
/// image_noise, image_blur_px, image_flicker.
std::vector<std::string> campaignSettingNames(bool images);

/// Draws run @p run with seed @p seed: every value from its range (uniform; kinds by weight),
/// the same values for the same arguments on every machine (its own 64-bit generator and
/// conversions). frames at 10 Hz.
/// A recorded trajectory that cannot be read or is shorter than the drive sets `error`.
/// @throws std::invalid_argument for ranges with `recorded` but no trajectory files.
CampaignRunSpec drawCampaignRun(const CampaignRanges& ranges, int run, unsigned seed, int frames,
                                bool images);

}  // namespace osc
