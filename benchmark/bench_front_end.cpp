/// @file bench_front_end.cpp
/// @brief Time of the image front end per stereo pair (detection + epipolar-guided matching
/// + tracking) at 640x480 and 1280x960, and of a whole frame (front end + filter), on a
/// rendered stretch of the paper's drive: every timed iteration processes the next pair of
/// the drive with the state the previous pairs left (so the tracks are real tracks).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/pipeline/right_rotation_seed.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {
namespace {

constexpr int kFrames = 30;        ///< rendered pairs of the drive
constexpr int kWarmUpFrames = 10;  ///< processed before timing (the state fills up)

/// The rendered pairs of a stretch of the drive at a scale of the paper's 640x480 camera.
struct Drive {
  explicit Drive(double scale) {
    scenario = paperOffroadScenario();
    scenario.frames = kFrames;
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
    scene.path = simulator.groundTrack();
    const StereoSceneRenderer renderer(scene);
    guess = simulator.initialGuess();
    SimulatedFrame frame;
    while (simulator.nextFrame(&frame)) {
      const Eigen::Isometry3d T_world_lopt = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
      left.push_back(renderer.render(simulator.leftCamera(), T_world_lopt));
      right.push_back(renderer.render(simulator.rightCamera(),
                                      T_world_lopt * frame.truth.leftToRightOptical()));
      motion.push_back(frame.measured_motion);
    }
  }
  MeasurementScenario scenario;
  StereoExtrinsics guess;
  std::vector<cv::Mat> left, right;
  std::vector<MotionIncrement> motion;
};

const Drive& drive(int width) {
  static const Drive small(1.0);
  if (width == 640) return small;
  static const Drive large(2.0);
  return large;
}

/// An estimator and front end run along the drive; starts over (warmed up again) at its end.
class Replay {
 public:
  Replay(const Drive& drive, const FrontEndConfig& config) : drive_(drive), config_(config) {
    restart();
  }

  /// The pair to process next.
  size_t next() const { return next_; }
  StereoCalibrationEstimator& estimator() { return *estimator_; }
  StereoFrontEnd& frontEnd() { return *front_end_; }

  /// Hands the filter's report on the pair to the front end and moves on.
  void finish(const FrameReport& report) {
    front_end_->commit(report, estimator_->filter());
    if (++next_ == drive_.left.size()) restart();
  }

 private:
  void restart() {
    FilterConfig filter_config;
    filter_config.initial_camr_rotation_sigma = 0.001;
    filter_config.initial_camr_translation_sigma = 0.002;
    filter_config.max_points = 100;
    estimator_ = std::make_unique<StereoCalibrationEstimator>(filter_config, drive_.scenario.left,
                                                              drive_.scenario.right, drive_.guess);
    front_end_ = std::make_unique<StereoFrontEnd>(config_, filter_config, estimator_->leftCamera(),
                                                  estimator_->rightCamera());
    for (next_ = 0; next_ < static_cast<size_t>(kWarmUpFrames); ++next_) process();
  }
  void process() {
    const auto observations =
        front_end_->observe(drive_.left[next_], drive_.right[next_], drive_.motion[next_],
                            estimator_->filter(), nullptr);
    front_end_->commit(estimator_->processFrame(drive_.motion[next_], observations),
                       estimator_->filter());
  }

  const Drive& drive_;
  const FrontEndConfig config_;
  std::unique_ptr<StereoCalibrationEstimator> estimator_;
  std::unique_ptr<StereoFrontEnd> front_end_;
  size_t next_ = 0;
};

/// Arguments: image width (640 or 1280) and whether search_lost_tracks is on (twice the
/// tracks: ~70 per pair instead of ~30).
void imageSizesWithAndWithoutSearch(benchmark::internal::Benchmark* benchmark) {
  benchmark->Args({640, 0})->Args({1280, 0})->Args({640, 1})->Args({1280, 1});
  benchmark->ArgNames({"width", "search_lost"});
}

FrontEndConfig configOf(const benchmark::State& state) {
  FrontEndConfig config;
  config.search_lost_tracks = state.range(1) != 0;
  return config;
}

void BM_FrontEnd(benchmark::State& state) {
  const Drive& d = drive(static_cast<int>(state.range(0)));
  Replay replay(d, configOf(state));
  double tracked = 0.0, features = 0.0, matches = 0.0;
  for (auto _ : state) {
    const size_t i = replay.next();
    FrontEndStatistics stats;
    const auto observations = replay.frontEnd().observe(d.left[i], d.right[i], d.motion[i],
                                                        replay.estimator().filter(), &stats);
    state.PauseTiming();
    tracked += stats.tracked;
    features += stats.features_left;
    matches += stats.stereo_matches;
    replay.finish(replay.estimator().processFrame(d.motion[i], observations));
    state.ResumeTiming();
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["tracked"] = tracked / n;  // mean per pair
  state.counters["features"] = features / n;
  state.counters["matches"] = matches / n;
}
BENCHMARK(BM_FrontEnd)->Apply(imageSizesWithAndWithoutSearch)->Unit(benchmark::kMillisecond);

void BM_WholeFrame(benchmark::State& state) {
  const Drive& d = drive(static_cast<int>(state.range(0)));
  Replay replay(d, configOf(state));
  double points = 0.0;
  for (auto _ : state) {
    const size_t i = replay.next();
    const auto observations = replay.frontEnd().observe(d.left[i], d.right[i], d.motion[i],
                                                        replay.estimator().filter(), nullptr);
    const FrameReport report = replay.estimator().processFrame(d.motion[i], observations);
    state.PauseTiming();
    points += static_cast<double>(replay.estimator().filter().pointCount());
    replay.finish(report);
    state.ResumeTiming();
  }
  state.counters["points"] = points / static_cast<double>(state.iterations());
}
BENCHMARK(BM_WholeFrame)->Apply(imageSizesWithAndWithoutSearch)->Unit(benchmark::kMillisecond);

/// The whole-image stereo fit (issue 14) on the keypoints the front end detected in a pair:
/// it runs only after two pairs without any stereo pair, so this is its cost when it runs.
void BM_WholeImageStereoFit(benchmark::State& state) {
  const Drive& d = drive(static_cast<int>(state.range(0)));
  Replay replay(d, FrontEndConfig());
  double inliers = 0.0, features = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    const size_t i = replay.next();
    const auto observations = replay.frontEnd().observe(d.left[i], d.right[i], d.motion[i],
                                                        replay.estimator().filter(), nullptr);
    state.ResumeTiming();
    const GlobalStereoFit fit =
        fitStereoGeometry(replay.frontEnd().lastLeftFeatures(),
                          replay.frontEnd().lastRightFeatures(), replay.estimator().leftCamera(),
                          replay.estimator().rightCamera(), Eigen::Vector3d::UnitX());
    state.PauseTiming();
    inliers += fit.inliers;
    features += static_cast<double>(replay.frontEnd().lastLeftFeatures().size());
    replay.finish(replay.estimator().processFrame(d.motion[i], observations));
    state.ResumeTiming();
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["inliers"] = inliers / n;
  state.counters["features"] = features / n;
}
BENCHMARK(BM_WholeImageStereoFit)
    ->Arg(640)
    ->Arg(1280)
    ->ArgName("width")
    ->Unit(benchmark::kMillisecond);

/// The stereo fit at start (FilterConfig::stereo_fit_start): the same fit with the rotation
/// and the baseline direction refined together under the start's direction prior
/// (baselineDirectionCovariance of the default 10 cm translation sigma), as
/// CalibrationPipeline runs it once per start.
void BM_StartStereoFit(benchmark::State& state) {
  const Drive& d = drive(static_cast<int>(state.range(0)));
  Replay replay(d, FrontEndConfig());
  double inliers = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    const size_t i = replay.next();
    const auto observations = replay.frontEnd().observe(d.left[i], d.right[i], d.motion[i],
                                                        replay.estimator().filter(), nullptr);
    const StereoExtrinsics estimate = replay.estimator().filter().extrinsics();
    GlobalStereoFitConfig config;
    config.baseline_direction_covariance =
        baselineDirectionCovariance(estimate, replay.estimator().filter().covariance());
    state.ResumeTiming();
    const GlobalStereoFit fit = fitStereoGeometry(
        replay.frontEnd().lastLeftFeatures(), replay.frontEnd().lastRightFeatures(),
        replay.estimator().leftCamera(), replay.estimator().rightCamera(),
        estimate.leftToRightOptical().translation().normalized(), config);
    state.PauseTiming();
    inliers += fit.inliers;
    replay.finish(replay.estimator().processFrame(d.motion[i], observations));
    state.ResumeTiming();
  }
  state.counters["inliers"] = inliers / static_cast<double>(state.iterations());
}
BENCHMARK(BM_StartStereoFit)->Arg(640)->ArgName("width")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace osc

BENCHMARK_MAIN();
