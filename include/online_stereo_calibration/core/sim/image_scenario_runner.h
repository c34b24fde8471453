/// @file image_scenario_runner.h
/// @brief Runs the whole image pipeline (CalibrationPipeline) over a MeasurementScenario's
/// drive: images rendered from the procedural scene along the true trajectory, noisy
/// measured motion as the measurement-level simulator makes it, and the front end's
/// matches and tracks checked against the renderer's exact ground truth.
#pragma once

#include <functional>
#include <optional>
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
  /// Exposure gain of the images of a blind frame (MeasurementScenario::blind_frames). The
  /// default renders them almost black, and the pipeline refuses them (no contrast); a gain of
  /// ~0.1 keeps a little contrast, so the pairs are processed but show (almost) no feature.
  double blind_exposure_gain = kBlindFrameExposureGain;
  /// A match or track is correct within this distance (px) of the true projection.
  double correct_tolerance = 1.5;
  /// Check the correctness of every stereo match (before bucketing), not only of the
  /// tracks and new candidates (costs a ray cast per match).
  bool check_all_matches = true;
};

/// One frame of an image-level run. A stereo pair is correct if one visible scene point has
/// its true pixels within the tolerance of both reported pixels (StereoMatchTruth::point);
/// the `_at_pixel` counts use the stricter test that the surface seen exactly at the left
/// pixel projects within tolerance of the right pixel, which also fails a correct match of an
/// object's outline whose keypoint lies a fraction of a pixel off the object, on the sky.
struct ImageFrameResult {
  ScenarioFrameResult filter;  ///< estimate vs truth, as in the measurement-level runner
  bool processed = false;      ///< the pipeline used the pair
  FrontEndStatistics front_end;
  int matches_checked = 0;  ///< stereo matches checked (all before bucketing)
  int matches_correct = 0;  ///< ... of which correct
  int matches_correct_at_pixel = 0;
  int new_checked = 0;  ///< new candidates offered
  int new_correct = 0;
  int new_correct_at_pixel = 0;
  int tracks_reported = 0;        ///< tracked points reported to the estimator
  int tracks_stereo_correct = 0;  ///< ... whose stereo pair is correct in this frame
  int tracks_stereo_correct_at_pixel = 0;
  int tracks_checked = 0;  ///< tracked points reported whose birth match was checked
  /// ... still on a scene point of their birth match (scenePointsOfStereoMatch; none if that
  /// match was wrong): within tolerance of its true projections in both images (stricter:
  /// includes drift along the track)
  int tracks_correct = 0;
  /// ... still on the surface point seen exactly at their birth's left pixel
  int tracks_correct_at_birth_pixel = 0;
  double render_ms = 0.0;  ///< time spent rendering this pair
  /// The whole-image stereo fit at a start, if tried in this pair
  /// (PipelineResult::stereo_fit), and whether x_camr's rotation was re-seeded from it.
  std::optional<RightRotationSeed> stereo_fit;
  bool right_rotation_from_stereo_fit = false;
  /// The pipeline re-opened x_camr's rotation in this pair (PipelineResult::right_camera_reopened).
  bool right_camera_reopened = false;
};

/// What the scene says about a stereo pair (left_pixel, right_pixel).
struct StereoMatchTruth {
  /// The surface point seen exactly at left_pixel projects visibly within tolerance of
  /// right_pixel.
  bool at_pixel = false;
  /// The visible surface point whose true pixels are nearest the pair (sum of squared
  /// distances), among those within tolerance in both images; none if there is no such
  /// point, i.e. the match is wrong. The exact point at left_pixel if at_pixel.
  std::optional<Eigen::Vector3d> point;
};

/// Checks a stereo pair against the scene: first the surface point at left_pixel, and if
/// that fails, the surface points seen within `tolerance` of left_pixel (sampled every
/// 0.25 px), so that a keypoint on an object's outline counts as the object's point.
StereoMatchTruth checkStereoMatch(const StereoSceneRenderer& renderer, const CameraModel& left,
                                  const CameraModel& right, const Eigen::Isometry3d& T_world_lopt,
                                  const Eigen::Isometry3d& T_world_ropt,
                                  const Eigen::Vector2d& left_pixel,
                                  const Eigen::Vector2d& right_pixel, double tolerance);

/// Every scene point a stereo pair may show: the surface points seen at left_pixel and within
/// `tolerance` of it (sampled every 0.25 px) whose true right pixel is visible and within
/// `tolerance` of right_pixel. More than one surface where the keypoint lies on an outline
/// (the object's edge and the background both within tolerance).
std::vector<Eigen::Vector3d> scenePointsOfStereoMatch(
    const StereoSceneRenderer& renderer, const CameraModel& left, const CameraModel& right,
    const Eigen::Isometry3d& T_world_lopt, const Eigen::Isometry3d& T_world_ropt,
    const Eigen::Vector2d& left_pixel, const Eigen::Vector2d& right_pixel, double tolerance);

/// Runs the scenario (scenario.frames pairs, truth incl. its step and drift) through a
/// CalibrationPipeline started from the scenario's initial guess. The measured motion, the
/// truth and the vehicle poses come from a MeasurementSimulator of the same scenario (its
/// motion noise stream and odometry errors; stops or a recorded trajectory; the scene is
/// laid along MeasurementSimulator::groundTrack()), so both runners see identical motion
/// errors. A pair the pipeline refuses (processed = false, e.g. too dark) is not checked
/// (its counts stay 0) and its motion is added to the next pair's, as the pipeline expects
/// the motion since the last processed pair. Blind frames are rendered at
/// kBlindFrameExposureGain times the exposure (the pipeline refuses them as too dark). Moving
/// points (moving_point_fraction) exist at measurement level only: the rendered scene is
/// static. on_frame is called after each frame if given.
/// @throws std::invalid_argument for an invalid scenario, config or exposure_variation.
std::vector<ImageFrameResult> runImageScenario(
    const MeasurementScenario& scenario, const FilterConfig& filter_config,
    const FrontEndConfig& front_end_config, const ImageScenarioOptions& options = {},
    const std::function<void(const ImageFrameResult&, const CalibrationPipeline&)>& on_frame = {});

}  // namespace osc
