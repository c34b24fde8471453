#include "online_stereo_calibration/core/sim/image_scenario_runner.h"

#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/vehicle_trajectory.h"

namespace osc {

bool isCorrectStereoMatch(const StereoSceneRenderer& renderer, const CameraModel& left,
                          const CameraModel& right, const Eigen::Isometry3d& T_world_lopt,
                          const Eigen::Isometry3d& T_world_ropt, const Eigen::Vector2d& left_pixel,
                          const Eigen::Vector2d& right_pixel, double tolerance) {
  const std::optional<Eigen::Vector3d> p = renderer.surfacePoint(left, T_world_lopt, left_pixel);
  if (!p) return false;
  Eigen::Vector2d projected;
  if (!renderer.projectVisible(right, T_world_ropt, *p, &projected)) return false;
  return (projected - right_pixel).norm() <= tolerance;
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
  const VehicleTrajectory& trajectory = simulator.trajectory();
  SceneConfig scene = options.scene;
  scene.path.clear();
  const double duration = scenario.frames / scenario.rate_hz;
  const double speed = std::max(scenario.motion.speed, 0.1);
  const int samples = std::max(2, static_cast<int>(std::ceil(duration * speed)) + 1);
  for (int i = 0; i <= samples; ++i) {
    scene.path.push_back(trajectory.groundPosition(duration * i / samples));
  }
  const StereoSceneRenderer renderer(scene);
  const CameraModel& left_camera = simulator.leftCamera();
  const CameraModel& right_camera = simulator.rightCamera();

  CalibrationPipeline pipeline(filter_config, front_end_config, scenario.left, scenario.right,
                               simulator.initialGuess());
  std::unordered_map<PointId, Eigen::Vector3d> birth_points;
  std::vector<ImageFrameResult> results;
  results.reserve(static_cast<size_t>(scenario.frames));
  SimulatedFrame frame;
  while (simulator.nextFrame(&frame)) {
    ImageFrameResult r;
    const Eigen::Isometry3d T_world_lopt = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
    const Eigen::Isometry3d T_world_ropt = T_world_lopt * frame.truth.leftToRightOptical();
    const auto render_start = std::chrono::steady_clock::now();
    RenderOptions render = options.render;
    render.noise_seed = 2u * static_cast<unsigned>(frame.index) + 1u;
    std::mt19937 exposure_rng(render.noise_seed);
    std::uniform_real_distribution<double> flicker(1.0 - options.exposure_variation,
                                                   1.0 + options.exposure_variation);
    render.exposure_gain = options.render.exposure_gain * flicker(exposure_rng);
    const cv::Mat left = renderer.render(left_camera, T_world_lopt, render);
    render.noise_seed += 1u;
    render.exposure_gain = options.render.exposure_gain * flicker(exposure_rng);
    const cv::Mat right = renderer.render(right_camera, T_world_ropt, render);
    r.render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - render_start)
            .count();

    const PipelineResult result = pipeline.process(left, right, frame.measured_motion);
    r.processed = result.processed;
    r.front_end = result.front_end;

    // Correctness against the renderer's ground truth.
    const StereoFrontEnd& front_end = pipeline.frontEnd();
    const double tol = options.correct_tolerance;
    if (options.check_all_matches) {
      for (const StereoObservation& o : front_end.lastStereoMatches()) {
        ++r.matches_checked;
        r.matches_correct += isCorrectStereoMatch(renderer, left_camera, right_camera, T_world_lopt,
                                                  T_world_ropt, o.left_pixel, o.right_pixel, tol);
      }
    }
    for (const StereoObservation& o : front_end.lastNewCandidates()) {
      ++r.new_checked;
      r.new_correct += isCorrectStereoMatch(renderer, left_camera, right_camera, T_world_lopt,
                                            T_world_ropt, o.left_pixel, o.right_pixel, tol);
      if (pipeline.estimator().filter().hasPoint(o.id)) {
        const auto p = renderer.surfacePoint(left_camera, T_world_lopt, o.left_pixel);
        if (p) birth_points[o.id] = *p;
      }
    }
    for (const StereoObservation& o : front_end.lastTracked()) {
      ++r.tracks_reported;
      r.tracks_stereo_correct +=
          isCorrectStereoMatch(renderer, left_camera, right_camera, T_world_lopt, T_world_ropt,
                               o.left_pixel, o.right_pixel, tol);
      const auto it = birth_points.find(o.id);
      if (it == birth_points.end()) continue;
      ++r.tracks_checked;
      Eigen::Vector2d pl, pr;
      const bool ok = renderer.projectVisible(left_camera, T_world_lopt, it->second, &pl) &&
                      renderer.projectVisible(right_camera, T_world_ropt, it->second, &pr) &&
                      (pl - o.left_pixel).norm() <= tol && (pr - o.right_pixel).norm() <= tol;
      r.tracks_correct += ok;
    }
    for (PointId id : result.estimator.dropped) birth_points.erase(id);

    r.filter =
        makeFrameResult(frame, result.estimate, result.estimator, 1e3 * result.processing_time);
    if (on_frame) on_frame(r, pipeline);
    results.push_back(r);
  }
  return results;
}

}  // namespace osc
