/// @file image_scenario_runner.h
/// @brief Runs the whole image pipeline (CalibrationPipeline) over a MeasurementScenario's
/// drive: images rendered from the procedural scene along the true trajectory, noisy
/// measured motion as the measurement-level simulator makes it, and the front end's
/// matches and tracks checked against the renderer's exact ground truth.
#pragma once

#include <functional>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/core/sim/procedural_scene.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {

/// How the images of an image-level run are made and checked.
struct ImageScenarioOptions {
  /// The scene; `path` is replaced by the trajectory's ground track.
  SceneConfig scene;
  /// Rendering of every image; noise_seed is replaced by a per-frame, per-camera seed.
  RenderOptions render;
  /// Auto-exposure flicker: each image's exposure_gain is render.exposure_gain times a factor
  /// drawn uniformly from [1 - v, 1 + v], independently per frame and camera (seeded by the
  /// frame index, so a run is reproducible). 0 = every image as render says.
  double exposure_variation = 0.0;
  /// A match or track is correct within this distance (px) of the true projection.
  double correct_tolerance = 1.5;
  /// Check the correctness of every stereo match (before bucketing), not only of the
  /// tracks and new candidates (costs a ray cast per match).
  bool check_all_matches = true;
};

/// One frame of an image-level run.
struct ImageFrameResult {
  ScenarioFrameResult filter;  ///< estimate vs truth, as in the measurement-level runner
  bool processed = false;      ///< the pipeline used the pair
  FrontEndStatistics front_end;
  int matches_checked = 0;  ///< stereo matches checked (all before bucketing)
  int matches_correct = 0;  ///< ... of which within tolerance of the truth
  int new_checked = 0;      ///< new candidates offered
  int new_correct = 0;
  int tracks_reported = 0;  ///< tracked points reported to the estimator
  /// ... whose stereo pair is correct in this frame (as for matches: the surface point at the
  /// left pixel projects within tolerance of the right pixel)
  int tracks_stereo_correct = 0;
  int tracks_checked = 0;  ///< tracked points reported whose birth point is known
  /// ... still on the point seen at their birth: within tolerance of its true projections in
  /// both images (stricter: includes drift along the track)
  int tracks_correct = 0;
  double render_ms = 0.0;  ///< time spent rendering this pair
};

/// True if (left_pixel, right_pixel) are the images of one surface point: the point seen at
/// left_pixel (renderer.surfacePoint) projects visibly within `tolerance` px of right_pixel.
bool isCorrectStereoMatch(const StereoSceneRenderer& renderer, const CameraModel& left,
                          const CameraModel& right, const Eigen::Isometry3d& T_world_lopt,
                          const Eigen::Isometry3d& T_world_ropt, const Eigen::Vector2d& left_pixel,
                          const Eigen::Vector2d& right_pixel, double tolerance);

/// Runs the scenario (scenario.frames pairs, truth incl. its step and drift) through a
/// CalibrationPipeline started from the scenario's initial guess. The measured motion, the
/// truth and the vehicle poses come from a MeasurementSimulator of the same scenario (its
/// motion noise stream), so both runners see identical motion errors. on_frame is called
/// after each frame if given.
/// @throws std::invalid_argument for an invalid scenario, config or exposure_variation.
std::vector<ImageFrameResult> runImageScenario(
    const MeasurementScenario& scenario, const FilterConfig& filter_config,
    const FrontEndConfig& front_end_config, const ImageScenarioOptions& options = {},
    const std::function<void(const ImageFrameResult&, const CalibrationPipeline&)>& on_frame = {});

}  // namespace osc
