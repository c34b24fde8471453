// One full filter step (predict + update) with N tracked points: the structured filter the
// package runs against a plain dense UKF of the same model, in the same run.
//   build/.../bench_filter_step --benchmark_min_time=0.5
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "online_stereo_calibration/core/estimator/consistency_monitor.h"
#include "online_stereo_calibration/core/estimator/jump_test.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/dense_calibration_ukf.h"

namespace osc {
namespace {

/// N static points in front of a forward-looking rig, one motion step, its measurements.
struct BenchmarkProblem {
  StereoIntrinsics K;
  StereoExtrinsics truth;
  MotionIncrement motion;
  std::vector<PointMeasurement> first, second;

  /// @p forward_step: metres driven between the two image pairs, 0.1 s apart.
  explicit BenchmarkProblem(int n, double forward_step = 0.35) {
    K.K_left << 600, 0, 320, 0, 600, 240, 0, 0, 1;
    K.K_right = K.K_left;
    Vector12d p;
    p << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0, 0.0, -0.3, 0.0, 0.0, 0.0, 0.0;
    truth = StereoExtrinsics::fromParameters(p);
    Vector6d m;
    m << forward_step, 0.0, 0.01, 0.005, -0.004, 0.01;
    motion.T_prev_curr = poseFromParameters(m);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1, 1);
    std::normal_distribution<double> noise(0.0, 0.5);
    const Eigen::Isometry3d T_ropt_lopt = truth.leftToRightOptical().inverse();
    const Eigen::Isometry3d T_lopt_veh = truth.vehicleToLeftOptical().inverse();
    for (int i = 0; i < n; ++i) {
      const double depth = 4.0 + 30.0 * (0.5 + 0.5 * u(rng));
      const Eigen::Vector3d p0(depth * 0.4 * u(rng), depth * 0.3 * u(rng), depth);
      const Eigen::Vector3d p1 =
          T_lopt_veh * (motion.T_prev_curr.inverse() * (truth.vehicleToLeftOptical() * p0));
      PointMeasurement a, b;
      a.id = b.id = i + 1;
      a.variance.setConstant(0.25);
      b.variance.setConstant(0.25);
      projectStereo(p0, T_ropt_lopt, K, 0.1, &a.z);
      projectStereo(p1, T_ropt_lopt, K, 0.1, &b.z);
      for (int c = 0; c < 4; ++c) b.z(c) += noise(rng);
      first.push_back(a);
      second.push_back(b);
    }
  }
};

/// A calibration known to about 1 cm / 0.1 deg and 0.2 mm / 0.005 deg: the filter's
/// usual running state.
Matrix12d convergedCovariance() {
  Vector12d sigma;
  sigma << 0.01, 0.01, 0.01, 0.002, 0.002, 0.002, 2e-4, 2e-4, 2e-4, 1e-4, 1e-4, 1e-4;
  return sigma.array().square().matrix().asDiagonal();
}

/// One structured step with @p config (the shipped defaults, or the consistency monitor off),
/// @p forward_step metres in 0.1 s, as the estimator makes it: the jump test shown the gate,
/// the consistency monitor fed the update's scores.
void structuredFilterStep(benchmark::State& state, const FilterConfig& config,
                          double forward_step = 0.35) {
  const BenchmarkProblem problem(static_cast<int>(state.range(0)), forward_step);
  CalibrationFilter prepared(config, problem.K);
  prepared.reset(problem.truth, convergedCovariance());
  for (const auto& m : problem.first) prepared.addPoint(m);
  const ConsistencyMonitor prepared_monitor(config);
  for (auto _ : state) {
    state.PauseTiming();
    CalibrationFilter filter = prepared;
    ConsistencyMonitor monitor = prepared_monitor;
    JumpTest jump_test(JumpTestOptions::from(config));
    state.ResumeTiming();
    benchmark::DoNotOptimize(
        filter.step(problem.motion, problem.second,
                    [&](const GateOutcome& gate) { return jump_test.decide(gate, filter); }));
    monitor.addUpdate(problem.motion.dt, filter.lastUpdateScores());
  }
  state.counters["points"] = static_cast<double>(prepared.pointCount());
}

void BM_StructuredFilterStep(benchmark::State& state) {
  structuredFilterStep(state, FilterConfig());
}

/// The same without the consistency monitor (consistency_window_s 0): what the monitor's
/// per-update sums cost.
void BM_StructuredFilterStepWithoutMonitor(benchmark::State& state) {
  FilterConfig config;
  config.consistency_window = 0.0;
  structuredFilterStep(state, config);
}

/// The same with the points stored as positions (inverse_depth_points 0, the seed's): what
/// the inverse-depth parametrisation costs.
void BM_StructuredFilterStepWithPositions(benchmark::State& state) {
  FilterConfig config;
  config.inverse_depth_points = 0;
  structuredFilterStep(state, config);
}

/// The same without tempering (max_sigma_shrink_per_update 0): what the check whether an
/// update would shrink a sigma too far costs (it runs the update's covariance part once more).
void BM_StructuredFilterStepUntempered(benchmark::State& state) {
  FilterConfig config;
  config.max_sigma_shrink_per_update = 0.0;
  structuredFilterStep(state, config);
}

/// The same at 1 m/s: slower than 2 m/s the step is repeated at the corrected motion
/// (motion_relinearizations 1, CalibrationFilter::wantsMotionRelinearized); what that costs.
void BM_StructuredFilterStepSlow(benchmark::State& state) {
  structuredFilterStep(state, FilterConfig(), 0.1);
}

/// The same slow step linearised once (motion_relinearizations 0): the baseline of the above.
void BM_StructuredFilterStepSlowOnce(benchmark::State& state) {
  FilterConfig config;
  config.motion_relinearizations = 0;
  structuredFilterStep(state, config, 0.1);
}

void BM_DenseUkfStep(benchmark::State& state) {
  const BenchmarkProblem problem(static_cast<int>(state.range(0)));
  DenseCalibrationUkf prepared(FilterConfig(), problem.K);
  prepared.reset(problem.truth, convergedCovariance());
  std::vector<PointMeasurement> measured;
  for (const auto& m : problem.first) {
    if (prepared.addPoint(m)) measured.push_back(problem.second[m.id - 1]);
  }
  for (auto _ : state) {
    state.PauseTiming();
    DenseCalibrationUkf filter = prepared;
    state.ResumeTiming();
    benchmark::DoNotOptimize(filter.step(problem.motion, measured));
  }
  state.counters["points"] = static_cast<double>(prepared.pointIds().size());
}

BENCHMARK(BM_StructuredFilterStep)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Arg(200)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StructuredFilterStepWithoutMonitor)
    ->Arg(25)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StructuredFilterStepUntempered)
    ->Arg(25)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StructuredFilterStepWithPositions)
    ->Arg(25)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StructuredFilterStepSlow)->Arg(25)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StructuredFilterStepSlowOnce)
    ->Arg(25)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DenseUkfStep)->Arg(25)->Arg(50)->Arg(100)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace osc

BENCHMARK_MAIN();
