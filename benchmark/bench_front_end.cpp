/// @file bench_front_end.cpp
/// @brief Time of the image front end per stereo pair (detection + epipolar-guided matching
/// + tracking of ~100 points) at 640x480 and 1280x960, and of a whole frame (front end +
/// filter), on rendered pairs of the paper's drive.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {
namespace {

/// A few rendered pairs of the drive and an estimator + front end that tracks ~100 points.
struct Setup {
  explicit Setup(double scale) {
    scenario = paperOffroadScenario();
    scenario.frames = 8;
    scenario.initial_error.setZero();
    for (CameraIntrinsics* k : {&scenario.left, &scenario.right}) {
      k->width = static_cast<int>(k->width * scale);
      k->height = static_cast<int>(k->height * scale);
      k->fx *= scale;
      k->fy *= scale;
      k->cx = (k->cx + 0.5) * scale - 0.5;
      k->cy = (k->cy + 0.5) * scale - 0.5;
    }
    MeasurementSimulator simulator(scenario);
    SceneConfig scene;
    for (int i = 0; i <= 10; ++i)
      scene.path.push_back(simulator.trajectory().groundPosition(0.1 * i));
    StereoSceneRenderer renderer(scene);
    FilterConfig filter_config;
    filter_config.initial_camr_rotation_sigma = 0.001;
    filter_config.initial_camr_translation_sigma = 0.002;
    filter_config.max_points = 100;
    estimator = std::make_unique<StereoCalibrationEstimator>(
        filter_config, scenario.left, scenario.right, simulator.initialGuess());
    front_end = std::make_unique<StereoFrontEnd>(FrontEndConfig(), filter_config,
                                                 estimator->leftCamera(), estimator->rightCamera());
    SimulatedFrame frame;
    while (simulator.nextFrame(&frame)) {
      const Eigen::Isometry3d T_world_lopt = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
      left.push_back(renderer.render(simulator.leftCamera(), T_world_lopt));
      right.push_back(renderer.render(simulator.rightCamera(),
                                      T_world_lopt * frame.truth.leftToRightOptical()));
      motion.push_back(frame.measured_motion);
    }
    for (size_t i = 0; i + 1 < left.size(); ++i) {
      const auto obs =
          front_end->observe(left[i], right[i], motion[i], estimator->filter(), nullptr);
      front_end->commit(estimator->processFrame(motion[i], obs), estimator->filter());
    }
  }
  MeasurementScenario scenario;
  std::unique_ptr<StereoCalibrationEstimator> estimator;
  std::unique_ptr<StereoFrontEnd> front_end;
  std::vector<cv::Mat> left, right;
  std::vector<MotionIncrement> motion;
};

Setup& setup(double scale) {
  static Setup small(1.0);
  if (scale == 1.0) return small;
  static Setup large(2.0);
  return large;
}

void BM_FrontEnd(benchmark::State& state) {
  Setup& s = setup(state.range(0) == 640 ? 1.0 : 2.0);
  FrontEndStatistics stats;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.front_end->observe(s.left.back(), s.right.back(), s.motion.back(),
                                                  s.estimator->filter(), &stats));
  }
  state.counters["tracked"] = stats.tracked;
  state.counters["features"] = stats.features_left;
  state.counters["matches"] = stats.stereo_matches;
}
BENCHMARK(BM_FrontEnd)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond);

void BM_WholeFrame(benchmark::State& state) {
  Setup& s = setup(state.range(0) == 640 ? 1.0 : 2.0);
  for (auto _ : state) {
    state.PauseTiming();
    StereoCalibrationEstimator estimator = *s.estimator;
    state.ResumeTiming();
    const auto obs = s.front_end->observe(s.left.back(), s.right.back(), s.motion.back(),
                                          estimator.filter(), nullptr);
    benchmark::DoNotOptimize(estimator.processFrame(s.motion.back(), obs));
  }
}
BENCHMARK(BM_WholeFrame)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace osc

BENCHMARK_MAIN();
