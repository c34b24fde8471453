#include "online_stereo_calibration/core/sim/image_scenario_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {

namespace {

/// Squared distance of p's true pixels to the pair (seen_at: where p is seen in the left
/// image) if p's right pixel is visible and within tolerance, else -1.
double pairError(const StereoSceneRenderer& renderer, const CameraModel& right,
                 const Eigen::Isometry3d& T_world_ropt, const Eigen::Vector3d& p,
                 const Eigen::Vector2d& seen_at, const Eigen::Vector2d& left_pixel,
                 const Eigen::Vector2d& right_pixel, double tolerance) {
  Eigen::Vector2d projected;
  if (!renderer.projectVisible(right, T_world_ropt, p, &projected)) return -1.0;
  const double right_error = (projected - right_pixel).norm();
  if (right_error > tolerance) return -1.0;
  return right_error * right_error + (seen_at - left_pixel).squaredNorm();
}

/// Calls visit(point, error) for every surface point seen within `tolerance` of left_pixel
/// (sampled every 0.25 px) that explains the pair (pairError >= 0).
template <typename Visit>
void forEachPointNearPair(const StereoSceneRenderer& renderer, const CameraModel& left,
                          const CameraModel& right, const Eigen::Isometry3d& T_world_lopt,
                          const Eigen::Isometry3d& T_world_ropt, const Eigen::Vector2d& left_pixel,
                          const Eigen::Vector2d& right_pixel, double tolerance, Visit visit) {
  constexpr double kStep = 0.25;  // px between the sampled rays around the left pixel
  const int steps = static_cast<int>(std::floor(tolerance / kStep));
  for (int dy = -steps; dy <= steps; ++dy) {
    for (int dx = -steps; dx <= steps; ++dx) {
      const Eigen::Vector2d seen_at = left_pixel + kStep * Eigen::Vector2d(dx, dy);
      if ((seen_at - left_pixel).norm() > tolerance) continue;
      const std::optional<Eigen::Vector3d> p = renderer.surfacePoint(left, T_world_lopt, seen_at);
      if (!p) continue;
      const double error =
          pairError(renderer, right, T_world_ropt, *p, seen_at, left_pixel, right_pixel, tolerance);
      if (error >= 0.0) visit(*p, error);
    }
  }
}

}  // namespace

StereoMatchTruth checkStereoMatch(const StereoSceneRenderer& renderer, const CameraModel& left,
                                  const CameraModel& right, const Eigen::Isometry3d& T_world_lopt,
                                  const Eigen::Isometry3d& T_world_ropt,
                                  const Eigen::Vector2d& left_pixel,
                                  const Eigen::Vector2d& right_pixel, double tolerance) {
  StereoMatchTruth truth;
  const std::optional<Eigen::Vector3d> exact =
      renderer.surfacePoint(left, T_world_lopt, left_pixel);
  if (exact && pairError(renderer, right, T_world_ropt, *exact, left_pixel, left_pixel, right_pixel,
                         tolerance) >= 0.0) {
    truth.at_pixel = true;
    truth.point = exact;
    return truth;
  }
  double best = -1.0;
  forEachPointNearPair(renderer, left, right, T_world_lopt, T_world_ropt, left_pixel, right_pixel,
                       tolerance, [&](const Eigen::Vector3d& p, double error) {
                         if (best < 0.0 || error < best) {
                           best = error;
                           truth.point = p;
                         }
                       });
  return truth;
}

std::vector<Eigen::Vector3d> scenePointsOfStereoMatch(
    const StereoSceneRenderer& renderer, const CameraModel& left, const CameraModel& right,
    const Eigen::Isometry3d& T_world_lopt, const Eigen::Isometry3d& T_world_ropt,
    const Eigen::Vector2d& left_pixel, const Eigen::Vector2d& right_pixel, double tolerance) {
  std::vector<Eigen::Vector3d> points;
  forEachPointNearPair(renderer, left, right, T_world_lopt, T_world_ropt, left_pixel, right_pixel,
                       tolerance, [&](const Eigen::Vector3d& p, double) { points.push_back(p); });
  return points;
}

std::vector<ImageFrameResult> runImageScenario(
    const MeasurementScenario& scenario, const FilterConfig& filter_config,
    const FrontEndConfig& front_end_config, const ImageScenarioOptions& options,
    const std::function<void(const ImageFrameResult&, const CalibrationPipeline&)>& on_frame) {
  if (!(options.exposure_variation >= 0.0 && options.exposure_variation < 1.0)) {
    throw std::invalid_argument(
        "ImageScenarioOptions.exposure_variation = " + std::to_string(options.exposure_variation) +
        " must be in [0, 1) (a gain factor 1 +- v must stay positive)");
  }
  MeasurementSimulator simulator(scenario);  // motion noise, truth and poses
  SceneConfig scene = options.scene;
  scene.path = simulator.groundTrack();  // analytic (with stops) or recorded
  const StereoSceneRenderer renderer(scene);
  const CameraModel& left_camera = simulator.leftCamera();
  const CameraModel& right_camera = simulator.rightCamera();

  CalibrationPipeline pipeline(filter_config, front_end_config, scenario.left, scenario.right,
                               simulator.initialGuess());
  // The scene points a tracked point's birth match may show, and the one at its left pixel.
  struct Birth {
    std::vector<Eigen::Vector3d> points;
    std::optional<Eigen::Vector3d> at_pixel;
  };
  std::unordered_map<PointId, Birth> births;
  std::vector<ImageFrameResult> results;
  results.reserve(static_cast<size_t>(scenario.frames));
  // The pipeline wants the motion since the last pair it processed: a refused pair (e.g. the
  // dark images of a blind frame) adds its motion to the next pair's.
  std::optional<MotionIncrement> since_processed;
  SimulatedFrame frame;
  while (true) {
    // The odometry read where the estimator believes the images were (its time offset).
    simulator.setOdometryTimeShift(pipeline.estimator().odometryTimeShift());
    if (!simulator.nextFrame(&frame)) break;
    ImageFrameResult r;
    const Eigen::Isometry3d T_world_lopt = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
    const Eigen::Isometry3d T_world_ropt = T_world_lopt * frame.truth.leftToRightOptical();
    const auto render_start = std::chrono::steady_clock::now();
    RenderOptions render = options.render;
    render.noise_seed = 2u * static_cast<unsigned>(frame.index) + 1u;
    std::mt19937 exposure_rng(render.noise_seed);
    std::uniform_real_distribution<double> flicker(1.0 - options.exposure_variation,
                                                   1.0 + options.exposure_variation);
    // A blind frame is rendered almost black (only the noise remains to see) or dim.
    const double gain =
        options.render.exposure_gain * (frame.blind ? options.blind_exposure_gain : 1.0);
    render.exposure_gain = gain * flicker(exposure_rng);
    const cv::Mat left = renderer.render(left_camera, T_world_lopt, render);
    render.noise_seed += 1u;
    render.exposure_gain = gain * flicker(exposure_rng);
    const cv::Mat right = renderer.render(right_camera, T_world_ropt, render);
    r.render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - render_start)
            .count();

    MotionIncrement motion = frame.measured_motion;
    if (since_processed) {
      motion.T_prev_curr = since_processed->T_prev_curr * motion.T_prev_curr;
      motion.dt += since_processed->dt;
    }
    const PipelineResult result = pipeline.process(left, right, motion);
    r.processed = result.processed;
    r.front_end = result.front_end;
    if (result.stereo_fit_tried) r.stereo_fit = result.stereo_fit;
    r.right_rotation_from_stereo_fit =
        result.estimator.has(FrameEvent::kRightRotationFromStereoFit);
    r.right_camera_reopened = result.right_camera_reopened;
    since_processed.reset();
    if (!result.processed) {
      // Nothing to check: the front end's lists are still the last processed pair's.
      if (frame.index > 0) since_processed = motion;
      r.filter =
          makeFrameResult(frame, result.estimate, result.estimator, 1e3 * result.processing_time);
      if (on_frame) on_frame(r, pipeline);
      results.push_back(r);
      continue;
    }

    // Correctness against the renderer's ground truth.
    const StereoFrontEnd& front_end = pipeline.frontEnd();
    const double tol = options.correct_tolerance;
    const auto check = [&](const StereoObservation& o) {
      return checkStereoMatch(renderer, left_camera, right_camera, T_world_lopt, T_world_ropt,
                              o.left_pixel, o.right_pixel, tol);
    };
    if (options.check_all_matches) {
      for (const StereoObservation& o : front_end.lastStereoMatches()) {
        const StereoMatchTruth truth = check(o);
        ++r.matches_checked;
        r.matches_correct += truth.point.has_value();
        r.matches_correct_at_pixel += truth.at_pixel;
      }
    }
    for (const StereoObservation& o : front_end.lastNewCandidates()) {
      const StereoMatchTruth truth = check(o);
      ++r.new_checked;
      r.new_correct += truth.point.has_value();
      r.new_correct_at_pixel += truth.at_pixel;
      // A wrong birth match has no scene point; its track is counted as wrong throughout.
      if (pipeline.estimator().filter().hasPoint(o.id)) {
        Birth& birth = births[o.id];
        birth.points = scenePointsOfStereoMatch(renderer, left_camera, right_camera, T_world_lopt,
                                                T_world_ropt, o.left_pixel, o.right_pixel, tol);
        birth.at_pixel = renderer.surfacePoint(left_camera, T_world_lopt, o.left_pixel);
      }
    }
    for (const StereoObservation& o : front_end.lastTracked()) {
      const StereoMatchTruth truth = check(o);
      ++r.tracks_reported;
      r.tracks_stereo_correct += truth.point.has_value();
      r.tracks_stereo_correct_at_pixel += truth.at_pixel;
      const auto it = births.find(o.id);
      if (it == births.end()) continue;
      ++r.tracks_checked;
      const auto stillOn = [&](const Eigen::Vector3d& p) {
        Eigen::Vector2d pl, pr;
        return renderer.projectVisible(left_camera, T_world_lopt, p, &pl) &&
               renderer.projectVisible(right_camera, T_world_ropt, p, &pr) &&
               (pl - o.left_pixel).norm() <= tol && (pr - o.right_pixel).norm() <= tol;
      };
      const Birth& birth = it->second;
      r.tracks_correct += std::any_of(birth.points.begin(), birth.points.end(), stillOn);
      r.tracks_correct_at_birth_pixel += birth.at_pixel && stillOn(*birth.at_pixel);
    }
    for (PointId id : result.estimator.dropped) births.erase(id);

    r.filter =
        makeFrameResult(frame, result.estimate, result.estimator, 1e3 * result.processing_time);
    if (on_frame) on_frame(r, pipeline);
    results.push_back(r);
  }
  return results;
}

}  // namespace osc
