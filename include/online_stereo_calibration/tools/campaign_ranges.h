/// @file campaign_ranges.h
/// @brief The ranges a `campaign` draws its scenarios from (issue 13): one interval or one
/// weighted choice of kinds per setting, read from YAML (config/campaign.yaml lists every key
/// with its default; docs/campaign.md explains them).
///
/// A setting is written as a number (fixed), or `[min, max]` (drawn uniformly; min == max
/// fixes it). A choice of kinds is a map `{kind: weight, ...}` (drawn with probability
/// weight / sum of weights; kinds not listed get weight 0) or a single kind name. Keys not
/// given keep the defaults below, which are those of config/campaign.yaml.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace osc {

/// A closed interval to draw a setting from uniformly; min == max fixes it.
struct DrawRange {
  double min = 0.0;
  double max = 0.0;
};

/// Named kinds with relative weights (>= 0, at least one > 0), in a fixed order.
struct KindChoice {
  std::vector<std::pair<std::string, double>> weights;
  /// The weight of @p kind (0 if not listed).
  double weight(const std::string& kind) const;
};

/// Every range of a campaign. Units are in the names (m, deg, px, s, ms, percent, mps = m/s).
struct CampaignRanges {
  // --- rig -------------------------------------------------------------------------------
  DrawRange baseline_m{0.08, 0.6};      ///< rig.baseline_m: |yr| of the true x_camr
  DrawRange image_width_px{640, 1280};  ///< rig.image_width_px: height = 3/4 width
  DrawRange focal_px{400, 1400};        ///< rig.focal_px: fx = fy
  KindChoice lens{{{"pinhole", 1}, {"plumb_bob", 1}, {"equidistant", 1}}};  ///< rig.lens
  /// rig.plumb_bob_k1; limited further per run to |k1| <= 1 / (12 r_corner^2) (the
  /// polynomial must not fold back before twice the image corner's normalized radius).
  DrawRange plumb_bob_k1{-0.3, 0.0};
  DrawRange equidistant_k1{-0.05, 0.05};  ///< rig.equidistant_k1 (k2 = k3 = k4 = 0)
  KindChoice mounting{{{"forward", 1}, {"backward", 1}, {"sideways", 1}}};  ///< rig.mounting
  DrawRange forward_pitch_down_deg{0, 30};  ///< rig.forward_pitch_down_deg (forward only)

  // --- motion ----------------------------------------------------------------------------
  KindChoice motion{{{"offroad", 1}, {"urban", 1}, {"recorded", 1}}};  ///< motion.kind
  DrawRange offroad_speed_mps{2, 6};                                   ///< motion.offroad_speed_mps
  DrawRange offroad_roll_pitch_std_deg{0.5, 3};  ///< motion.offroad_roll_pitch_std_deg
  DrawRange offroad_heave_m{0, 0.1};             ///< motion.offroad_heave_m (amplitude)
  DrawRange offroad_yaw_rate_deg_s{3, 15};       ///< motion.offroad_yaw_rate_deg_s (amplitude)
  DrawRange urban_speed_mps{8, 15};              ///< motion.urban_speed_mps
  DrawRange urban_stops{1, 2};                   ///< motion.urban_stops (integer)
  DrawRange urban_stop_duration_s{2, 10};        ///< motion.urban_stop_duration_s (each stop)
  DrawRange urban_stop_ramp_s{3, 3};             ///< motion.urban_stop_ramp_s (slow-down)
  /// motion.yaw_phase_deg: the steering's phase at the first frame (offroad and urban; 0 starts
  /// at the height of a left turn), from a stream of its own (see drawCampaignRun).
  DrawRange yaw_phase_deg{0, 360};
  /// The recorded trajectories (TUM files, sorted) found in `trajectories_dir`; empty when the
  /// kind `recorded` has weight 0.
  std::vector<std::string> trajectory_files;
  /// Why the kind `recorded` was dropped (its weight set to 0, the other motions drawn):
  /// `trajectories_dir` is not a directory or holds no *.tum file (a clone without the
  /// project's ../shared/data beside it). Empty when nothing was dropped. The runs then
  /// differ from those drawn with the trajectories: every kind's share changes.
  std::string dropped_recorded;

  // --- start errors (each axis: |error| drawn, sign random) -------------------------------
  DrawRange caml_translation_error_m{0, 0.5};      ///< start_errors.caml_translation_m
  DrawRange caml_angle_error_deg{0, 10};           ///< start_errors.caml_angle_deg
  DrawRange camr_baseline_error_percent{-50, 50};  ///< start_errors.camr_baseline_percent
  DrawRange camr_translation_error_m{0, 0.02};     ///< start_errors.camr_translation_m (xr, zr)
  DrawRange camr_angle_error_deg{0, 5};            ///< start_errors.camr_angle_deg

  // --- events ----------------------------------------------------------------------------
  KindChoice event{{{"none", 1}, {"caml_yaw_step", 1}, {"camr_knock", 1}, {"camr_drift", 1}}};
  DrawRange event_at_fraction{0.4, 0.6};     ///< events.at_fraction: step frame / frames
  DrawRange caml_yaw_step_deg{2, 10};        ///< events.caml_yaw_step_deg (sign random)
  DrawRange camr_knock_deg{0.1, 1};          ///< events.camr_knock_deg (random axis)
  DrawRange camr_drift_deg_per_min{0, 0.5};  ///< events.camr_drift_deg_per_min (random axis)
  DrawRange camr_drift_mm_per_min{0, 5};     ///< events.camr_drift_mm_per_min (random direction)

  // --- odometry (beyond the white noise) ---------------------------------------------------
  DrawRange time_offset_ms{-30, 30};            ///< odometry.time_offset_ms
  DrawRange scale_error_percent{-2, 2};         ///< odometry.scale_error_percent
  DrawRange rotation_rate_bias_deg_s{0, 0.01};  ///< odometry.rotation_rate_bias_deg_s (std)
  DrawRange velocity_bias_mps{0, 0.02};         ///< odometry.velocity_bias_mps (std)
  DrawRange bias_correlation_time_s{30, 30};    ///< odometry.bias_correlation_time_s
  /// odometry.white_noise_factor: the simulated white motion noise's 1 sigma, translation and
  /// rotation, times the scenario's (which the filter assumes); drawn last, so that [1, 1]
  /// leaves every other draw as it was.
  DrawRange white_noise_factor{1, 1};

  // --- scene (both levels) -------------------------------------------------------------------
  DrawRange blind_stretches{0, 1};           ///< scene.blind_stretches (integer count)
  DrawRange blind_duration_s{2, 5};          ///< scene.blind_duration_s (each stretch)
  DrawRange moving_point_fraction{0, 0.2};   ///< scene.moving_point_fraction
  DrawRange moving_point_speed_mps{0.5, 3};  ///< scene.moving_point_speed_mps

  // --- images (--images only) ---------------------------------------------------------------
  DrawRange image_noise_grey{0, 3};    ///< images.noise_grey (std, grey levels)
  DrawRange image_blur_px{0, 1};       ///< images.blur_px (Gaussian sigma)
  DrawRange exposure_flicker{0, 0.2};  ///< images.exposure_flicker (gain 1 +- v per image)
};

/// One interval setting of the table: its YAML key (section.name), the member, the limits
/// any range must lie within, and whether it takes integers.
struct DrawRangeSpec {
  std::string key;
  DrawRange CampaignRanges::*member;
  double low, high;
  bool integer;
};

/// One choice of kinds: its YAML key and the kinds it knows, in order.
struct KindChoiceSpec {
  std::string key;
  KindChoice CampaignRanges::*member;
  std::vector<std::string> kinds;
};

/// The table of interval settings (the one list parse, checks and tests go through).
const std::vector<DrawRangeSpec>& drawRangeSpecs();
/// The table of kind choices.
const std::vector<KindChoiceSpec>& kindChoiceSpecs();

/// Reads ranges from YAML text; keys not given keep the defaults of CampaignRanges.
/// `trajectories_dir` is resolved against @p base_dir (the ranges file's directory), then
/// the current directory. When the kind `recorded` has weight > 0 but that directory is
/// missing or holds no *.tum file, `recorded` is dropped and CampaignRanges::dropped_recorded
/// says why (an error if no other motion kind has weight).
/// @throws std::runtime_error "<source_name>: invalid ranges:" listing every problem, each
/// naming its key (unknown keys, not a number or [min, max], min > max, outside the limits,
/// unknown kinds, bad weights, trajectories_dir not given or, with no other motion kind,
/// missing or empty).
CampaignRanges parseCampaignRanges(const std::string& text, const std::string& source_name,
                                   const std::string& base_dir = ".");

/// Reads a ranges file (see parseCampaignRanges; base_dir = the file's directory).
/// @throws std::runtime_error naming the file if it cannot be read.
CampaignRanges readCampaignRangesFile(const std::string& path);

/// The whole text of a file. @throws std::runtime_error naming the file.
std::string readTextFile(const std::string& path);

}  // namespace osc
