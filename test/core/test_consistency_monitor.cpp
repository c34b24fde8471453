// The consistency monitor (consistency_monitor.h): its per-block score statistic against a
// dense computation and its distribution under a consistent linear-Gaussian model, the
// window test's false alarms, detection and attribution of a shifted block, the inflation
// factor rising and relaxing; and at measurement level, a right camera drifting faster than
// the configured random walk followed honestly, the paper's drive not disturbed.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "online_stereo_calibration/core/estimator/consistency_monitor.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"

namespace osc {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kDeg = M_PI / 180.0;
constexpr int kCaml = static_cast<int>(ConsistencyBlock::kVehicleToLeft);
constexpr int kCamr = static_cast<int>(ConsistencyBlock::kLeftToRight);
constexpr int kPoints = static_cast<int>(ConsistencyBlock::kPoints);

TEST(ChiSquare, UpperQuantileMatchesTables) {
  EXPECT_NEAR(chiSquareUpperQuantile(6, 1e-3), 22.458, 0.25);
  EXPECT_NEAR(chiSquareUpperQuantile(10, 0.05), 18.307, 0.05);
  EXPECT_NEAR(chiSquareUpperQuantile(100, 0.01), 135.807, 0.1);
  EXPECT_NEAR(chiSquareUpperQuantile(240, 1e-3), 313.437, 0.1);  // scipy chi2.isf
}

/// A linear-Gaussian update like the filter's: global error dg (G = 18: x_caml, x_camr, a
/// motion error) with prior N(0, P), N points r_i = J_i dg + n_i, n_i ~ N(0, S0_i).
struct SyntheticUpdate {
  int G = 18, N = 25;
  MatrixXd P;
  std::vector<MatrixXd> J, S0;

  explicit SyntheticUpdate(std::mt19937* rng) {
    std::normal_distribution<double> normal;
    MatrixXd L(G, G);
    for (int a = 0; a < G; ++a)
      for (int b = 0; b < G; ++b) L(a, b) = normal(*rng);
    P = 0.05 * L * L.transpose() + 0.1 * MatrixXd::Identity(G, G);
    for (int i = 0; i < N; ++i) {
      MatrixXd Ji(4, G), Si(4, 4);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < G; ++b) Ji(a, b) = normal(*rng);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) Si(a, b) = 0.3 * normal(*rng);
      J.push_back(Ji);
      S0.push_back(Si * Si.transpose() + MatrixXd::Identity(4, 4));
    }
  }

  /// Draws r with dg ~ N(shift, P) and returns the update's scores; optionally the dense
  /// statistics (score test on the full innovation covariance) for comparison.
  UpdateScores draw(std::mt19937* rng, const VectorXd& shift, VectorXd* r_out = nullptr) const {
    std::normal_distribution<double> normal;
    VectorXd z(G);
    for (int a = 0; a < G; ++a) z(a) = normal(*rng);
    const VectorXd dg = shift + P.llt().matrixL() * z;
    MatrixXd A = MatrixXd::Zero(G, G);
    VectorXd b = VectorXd::Zero(G), r(4 * N);
    double c = 0.0;
    for (int i = 0; i < N; ++i) {
      Eigen::Vector4d w;
      for (int a = 0; a < 4; ++a) w(a) = normal(*rng);
      const Eigen::Vector4d ri = J[i] * dg + S0[i].llt().matrixL() * w;
      r.segment<4>(4 * i) = ri;
      const MatrixXd Si = S0[i].inverse();
      A += J[i].transpose() * Si * J[i];
      b += J[i].transpose() * Si * ri;
      c += ri.dot(Si * ri);
    }
    if (r_out) *r_out = r;
    const MatrixXd P_post = (P.inverse() + A).inverse();
    return computeUpdateScores(globalScore(A, b, P_post), b, c, 4 * N);
  }
};

// The statistics equal the score test computed densely: g = J^T S^-1 r, F = J^T S^-1 J with
// the full innovation covariance S = J P J^T + S0 (partial for each calibration block).
TEST(ConsistencyScores, EqualTheDenseScoreTest) {
  std::mt19937 rng(5);
  const SyntheticUpdate u(&rng);
  VectorXd r;
  const UpdateScores s = u.draw(&rng, VectorXd::Zero(u.G), &r);
  MatrixXd Jall(4 * u.N, u.G), S0all = MatrixXd::Zero(4 * u.N, 4 * u.N);
  for (int i = 0; i < u.N; ++i) {
    Jall.middleRows(4 * i, 4) = u.J[i];
    S0all.block(4 * i, 4 * i, 4, 4) = u.S0[i];
  }
  const MatrixXd S = Jall * u.P * Jall.transpose() + S0all;
  const VectorXd g = Jall.transpose() * S.ldlt().solve(r);
  const MatrixXd F = Jall.transpose() * S.ldlt().solve(Jall);
  const auto quadratic = [&](int first, int count) {
    return g.segment(first, count)
        .dot(F.block(first, first, count, count).ldlt().solve(g.segment(first, count)));
  };
  EXPECT_LT((s.score - g.head<12>()).norm(), 1e-8 * g.norm());
  EXPECT_LT((s.information - F.topLeftCorner<12, 12>()).norm(), 1e-8 * F.norm());
  std::array<double, 2> statistic;
  std::array<int, 2> dof;
  calibrationStatistics(s.score, s.information, &statistic, &dof);
  const double both = quadratic(0, 12);
  EXPECT_NEAR(statistic[kCamr], both - quadratic(0, 6), 1e-6 * both);
  EXPECT_NEAR(statistic[kCaml], both - quadratic(6, 6), 1e-6 * both);
  const double total = r.dot(S.ldlt().solve(r));
  EXPECT_NEAR(s.rest, total - quadratic(0, u.G), 1e-6 * total);
  EXPECT_EQ(dof[kCamr], 6);
  EXPECT_EQ(dof[kCaml], 6);
  EXPECT_EQ(s.rest_dof, 4 * u.N - u.G);
}

// The shift that best explains one update's score, x_caml free: unbiased for a shifted
// x_camr (5 prior sigmas per axis) and zero for the unshifted x_caml, within 4 standard
// errors of the draws' scatter.
TEST(ConsistencyScores, PartialShiftEstimateRecoversTheShiftedBlock) {
  std::mt19937 rng(17);
  const SyntheticUpdate u(&rng);
  VectorXd shift = VectorXd::Zero(u.G);
  shift.segment<6>(6) = 5.0 * u.P.diagonal().segment<6>(6).cwiseSqrt();
  const int draws = 400;
  std::vector<Eigen::Matrix<double, 6, 1>> right, left;
  for (int k = 0; k < draws; ++k) {
    const UpdateScores s = u.draw(&rng, shift);
    right.push_back(partialShiftEstimate(s.score, s.information, ConsistencyBlock::kLeftToRight));
    left.push_back(partialShiftEstimate(s.score, s.information, ConsistencyBlock::kVehicleToLeft));
  }
  const auto check = [&](const std::vector<Eigen::Matrix<double, 6, 1>>& estimates,
                         const Eigen::Matrix<double, 6, 1>& truth, const char* block) {
    Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& e : estimates) mean += e / draws;
    Eigen::Matrix<double, 6, 1> variance = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& e : estimates) variance += (e - mean).cwiseAbs2() / (draws - 1);
    const Eigen::Matrix<double, 6, 1> standard_error = (variance / draws).cwiseSqrt();
    for (int a = 0; a < 6; ++a) {
      EXPECT_NEAR(mean(a), truth(a), 4.0 * standard_error(a)) << block << " " << a;
    }
    return standard_error;
  };
  const Eigen::Matrix<double, 6, 1> error = check(right, shift.segment<6>(6), "x_camr");
  check(left, Eigen::Matrix<double, 6, 1>::Zero(), "x_caml");
  // The shift stands far out of the estimates' scatter: an estimator of zero would fail.
  for (int a = 0; a < 6; ++a) EXPECT_GT(shift(6 + a), 10.0 * error(a)) << a;
}

FilterConfig monitorConfig() {
  FilterConfig config;
  config.consistency_window = 4.0;
  config.consistency_false_alarm = 0.01;
  config.max_drift_inflation = 100.0;
  config.drift_inflation_decade = 2.0;
  config.drift_inflation_relax = 10.0;
  return config;
}

// Under the model each statistic is chi-square with its degrees of freedom, and the window
// test exceeds its bound about as often as its false-alarm probability says.
TEST(ConsistencyMonitor, ConsistentUpdatesStayWithinTheBand) {
  std::mt19937 rng(11);
  const SyntheticUpdate u(&rng);
  ConsistencyMonitor monitor(monitorConfig());
  const int updates = 4000;
  std::array<double, 3> sum = {0, 0, 0}, dof = {0, 0, 0};
  int exceeded = 0;
  for (int k = 0; k < updates; ++k) {
    const UpdateScores s = u.draw(&rng, VectorXd::Zero(u.G));
    std::array<double, 2> statistic;
    std::array<int, 2> statistic_dof;
    calibrationStatistics(s.score, s.information, &statistic, &statistic_dof);
    for (int b = 0; b < 2; ++b) {
      sum[b] += statistic[b];
      dof[b] += statistic_dof[b];
    }
    sum[kPoints] += s.rest;
    dof[kPoints] += s.rest_dof;
    monitor.addUpdate(0.1, &s);
    const ConsistencyStatus& status = monitor.status();
    exceeded += status.exceeded[kCaml] || status.exceeded[kCamr] || status.exceeded[kPoints];
  }
  // Means per degree of freedom: 1 within 4 standard errors (sqrt(2 / dof)).
  for (int b = 0; b < 3; ++b) EXPECT_NEAR(sum[b] / dof[b], 1.0, 4.0 * std::sqrt(2.0 / dof[b]));
  // Three tests at 1 % each; windows overlap, so the share scatters more than binomially.
  EXPECT_LT(exceeded, 0.06 * updates);
  EXPECT_LT(monitor.inflation().camr, 100.0);
}

// x_camr shifted beyond its prior: its statistic exceeds within a few updates, x_caml's
// (the partial score) does not, the factor grows to its bound and relaxes once consistent.
TEST(ConsistencyMonitor, ShiftedBlockTriggersIsAttributedAndRelaxes) {
  std::mt19937 rng(13);
  const SyntheticUpdate u(&rng);
  const FilterConfig config = monitorConfig();
  ConsistencyMonitor monitor(config);
  for (int k = 0; k < 40; ++k) {  // a consistent window first
    const UpdateScores s = u.draw(&rng, VectorXd::Zero(u.G));
    monitor.addUpdate(0.1, &s);
  }
  VectorXd shift = VectorXd::Zero(u.G);
  shift.segment<6>(6) = 1.0 * u.P.diagonal().segment<6>(6).cwiseSqrt();  // 1 sigma per axis
  int first_exceeded = -1, caml_exceeded = 0;
  for (int k = 0; k < 100; ++k) {
    const UpdateScores s = u.draw(&rng, shift);
    monitor.addUpdate(0.1, &s);
    if (first_exceeded < 0 && monitor.status().acting(ConsistencyBlock::kLeftToRight))
      first_exceeded = k;
    caml_exceeded += monitor.status().acting(ConsistencyBlock::kVehicleToLeft);
  }
  ASSERT_GE(first_exceeded, 0);
  EXPECT_LT(first_exceeded, 10);
  EXPECT_LT(caml_exceeded, 5);
  EXPECT_NEAR(monitor.inflation().camr, 100.0, 1e-6);
  EXPECT_LT(monitor.inflation().caml, 2.0);
  EXPECT_EQ(monitor.status().message(),
            "measurements disagree with the model: process noise raised on x_camr");
  // Consistent again: the window empties of the shift, then the factor relaxes (tau 10 s).
  for (int k = 0; k < 400; ++k) {
    const UpdateScores s = u.draw(&rng, VectorXd::Zero(u.G));
    monitor.addUpdate(0.1, &s);
  }
  EXPECT_LT(monitor.inflation().camr, 1.3);
  EXPECT_GT(monitor.inflation().camr, 1.0);
  EXPECT_FALSE(monitor.status().acting());
  EXPECT_EQ(monitor.status().message(), "");
}

// The points' excess (every measurement noisier than modelled) is not the calibration's.
TEST(ConsistencyMonitor, CommonNoiseExcessDoesNotRaiseTheCalibration) {
  std::mt19937 rng(17);
  const SyntheticUpdate u(&rng);
  ConsistencyMonitor monitor(monitorConfig());
  int acting = 0, points = 0;
  for (int k = 0; k < 300; ++k) {
    UpdateScores s = u.draw(&rng, VectorXd::Zero(u.G));
    s.score *= std::sqrt(1.5);  // noise sigma 1.22 x the model's
    s.rest *= 1.5;
    monitor.addUpdate(0.1, &s);
    acting += monitor.status().acting();
    points += monitor.status().exceeded[kPoints];
  }
  EXPECT_GT(points, 250);
  EXPECT_LT(acting, 15);
}

// After a reset both calibration blocks are acted on at once: a mounting that turns from the
// start is followed from the start.
TEST(ConsistencyMonitor, ActsOnBothBlocksFromTheStart) {
  std::mt19937 rng(19);
  const SyntheticUpdate u(&rng);
  ConsistencyMonitor monitor(monitorConfig());
  VectorXd shift = VectorXd::Zero(u.G);
  shift.head<12>() = 2.0 * u.P.diagonal().head<12>().cwiseSqrt();  // both blocks 2 sigma off
  int camr_first = -1, caml_first = -1;
  for (int k = 0; k < 30; ++k) {
    const UpdateScores s = u.draw(&rng, shift);
    monitor.addUpdate(0.1, &s);
    if (camr_first < 0 && monitor.inflation().camr > 1.0) camr_first = k;
    if (caml_first < 0 && monitor.inflation().caml > 1.0) caml_first = k;
  }
  EXPECT_GE(camr_first, 0);
  EXPECT_LT(camr_first, 10);
  EXPECT_GE(caml_first, 0);
  EXPECT_LT(caml_first, 10);
  EXPECT_EQ(monitor.status().message(),
            "measurements disagree with the model: process noise raised on x_caml and x_camr");
}

// forgetEvidence empties the window, so a shift seen after it is judged on its own updates;
// the factors it drove are kept.
TEST(ConsistencyMonitor, ForgettingTheEvidenceKeepsTheFactors) {
  std::mt19937 rng(23);
  const SyntheticUpdate u(&rng);
  ConsistencyMonitor monitor(monitorConfig());
  VectorXd shift = VectorXd::Zero(u.G);
  shift.segment<6>(6) = 2.0 * u.P.diagonal().segment<6>(6).cwiseSqrt();  // x_camr 2 sigma off
  for (int k = 0; k < 60; ++k) {  // 6 s: x_camr's factor raised
    const UpdateScores s = u.draw(&rng, shift);
    monitor.addUpdate(0.1, &s);
  }
  ASSERT_TRUE(monitor.status().exceeded[kCamr]);
  const double factor = monitor.inflation().camr;
  ASSERT_GT(factor, 10.0);
  monitor.forgetEvidence();
  EXPECT_EQ(monitor.status().window_updates, 0);
  EXPECT_FALSE(monitor.status().exceeded[kCamr]);
  EXPECT_DOUBLE_EQ(monitor.inflation().camr, factor);
}

TEST(ConsistencyMonitor, OffDoesNothing) {
  FilterConfig config = monitorConfig();
  config.consistency_window = 0.0;
  ConsistencyMonitor monitor(config);
  UpdateScores s;
  s.score.setConstant(1e3);
  s.information.setIdentity();
  s.rest = 1e6;
  s.rest_dof = 100;
  for (int k = 0; k < 100; ++k) monitor.addUpdate(0.1, &s);
  EXPECT_FALSE(monitor.status().enabled);
  EXPECT_FALSE(monitor.status().acting());
  EXPECT_EQ(monitor.inflation().camr, 1.0);
}

// ---------------------------------------------------------------------------------------
// Measurement level.

/// Per-frame figures of one run.
struct RunFigures {
  int frames = 0;                         ///< frames in the window
  Vector12d within2 = Vector12d::Zero();  ///< share within 2 sigma per parameter, window
  Vector12d rmse = Vector12d::Zero();     ///< window
  double all_within3 = 0.0;               ///< share of frames >= 30 with all 12 within 3 sigma
  double max_ratio = 0.0;                 ///< max |error| / sigma over frames >= 30
  double beyond5 = 0.0;                   ///< share of frames >= 30 with any beyond 5 sigma
  double acting = 0.0;                    ///< share of frames the monitor acts
  double ms_per_frame = 0.0;
};

RunFigures run(const MeasurementScenario& scenario, const FilterConfig& config, int first,
               int last) {
  RunFigures f;
  MeasurementSimulator simulator(scenario);
  StereoCalibrationEstimator estimator(config, scenario.left, scenario.right,
                                       simulator.initialGuess());
  SimulatedFrame frame;
  int late = 0;
  double ms = 0.0;
  while (simulator.nextFrame(&frame)) {
    const auto start = std::chrono::steady_clock::now();
    const FrameReport report = estimator.processFrame(frame.measured_motion, frame.observations);
    const CalibrationEstimate estimate = estimator.estimate();
    ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    simulator.dropTracks(report.dropped);
    const ScenarioFrameResult r = makeFrameResult(frame, estimate, report, 0.0);
    f.acting += estimate.consistency.acting();
    // Errors on the manifold against their sigmas (as the RPY ones, any mounting).
    const Vector12d ratio = r.tangent_error.cwiseAbs().cwiseQuotient(r.tangent_sigmas);
    Vector12d e = r.parameters - r.truth;
    for (int k : {3, 4, 5, 9, 10, 11}) e(k) = std::remainder(e(k), 2.0 * M_PI);
    if (r.frame >= first && r.frame <= last) {
      ++f.frames;
      f.rmse += e.cwiseAbs2();
      for (int k = 0; k < 12; ++k) f.within2(k) += std::abs(e(k)) <= 2.0 * r.sigmas(k);
    }
    if (r.frame >= 30) {
      ++late;
      f.all_within3 += ratio.maxCoeff() <= 3.0;
      f.beyond5 += ratio.maxCoeff() > 5.0;
      f.max_ratio = std::max(f.max_ratio, ratio.maxCoeff());
    }
  }
  f.within2 /= std::max(f.frames, 1);
  f.rmse = (f.rmse / std::max(f.frames, 1)).cwiseSqrt();
  f.all_within3 /= std::max(late, 1);
  f.beyond5 /= std::max(late, 1);
  f.acting /= scenario.frames;
  f.ms_per_frame = ms / scenario.frames;
  return f;
}

/// The paper's drive without its step, x_camr drifting linearly (per second).
MeasurementScenario drifting(double yaw_r_deg, double pitch_r_deg, double yr_m, double seconds) {
  MeasurementScenario s = paperOffroadScenario();
  s.name = "fast_camr_drift";
  s.step_frame = -1;
  s.drift_per_second.setZero();
  s.drift_per_second(11) = yaw_r_deg * kDeg / seconds;
  s.drift_per_second(10) = pitch_r_deg * kDeg / seconds;
  s.drift_per_second(7) = yr_m / seconds;
  return s;
}

/// The case: 0.3 deg yaw_r, -0.2 deg pitch_r and 5 mm yr over 90 s.
MeasurementScenario thermalDrift() { return drifting(0.3, -0.2, 0.005, 90.0); }

// The failure: a thermal drift of the right camera faster than the shipped random
// walk, followed late and overconfidently. With the monitor it is followed honestly (seed 1
// measured with inverse-depth points: all 12 within 3 sigma in 99 % of frames 30-1199
// against 57 % without, none beyond 5 sigma in either; yaw_r within 2 sigma in frames
// 1000-1150 44 % against 30 %. With points as positions: 80 % against 36 %, 31 % against 1 %).
// Measured without x_camr's drift rate state, which follows this drift alone (below).
TEST(ConsistencyScenario, FastRightCameraDriftIsFollowedHonestly) {
  MeasurementScenario scenario = thermalDrift();
  scenario.frames = 1200;
  FilterConfig walk_only;
  walk_only.camr_rotation_drift_rate_sigma = 0.0;
  FilterConfig off = walk_only;
  off.consistency_window = 0.0;
  const RunFigures before = run(scenario, off, 1000, 1150);
  const RunFigures after = run(scenario, walk_only, 1000, 1150);
  std::cout << "all 12 within 3 sigma from frame 30: " << before.all_within3 << " -> "
            << after.all_within3 << ", beyond 5: " << before.beyond5 << " -> " << after.beyond5
            << "; yaw_r within 2 sigma in frames 1000-1150: " << before.within2(11) << " -> "
            << after.within2(11) << "\n";
  EXPECT_GE(after.all_within3, 0.7);
  EXPECT_GE(after.all_within3, before.all_within3 + 0.3);
  EXPECT_LE(after.beyond5, 0.005);
  EXPECT_LT(after.max_ratio, 5.0);
  EXPECT_GE(after.within2(11), before.within2(11) + 0.1);  // yaw_r
  EXPECT_GT(after.acting, 0.0);
  EXPECT_EQ(before.acting, 0.0);
}

// The mounting itself turning from the start, at the rate of issue 57's car drive (pitch_l
// 4.5 deg/min, yaw_l -6 deg/min): the monitor raises x_caml's noise from its first updates
// (it used to hold x_caml for 20 s after a start, and the rendered drive reached yaw_l
// 8.2 sigma, docs/RESULTS.md). Measured, seed 1, frames 30-399: without the monitor all 12
// within 3 sigma in 2 % of the frames, 74 % beyond 5 sigma, largest error 17 sigma; with it
// 69 %, none beyond 5, largest 4.3 sigma.
TEST(ConsistencyScenario, LeftCameraTurningFromTheStartIsFollowed) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.name = "caml_ramp";
  scenario.step_frame = -1;
  scenario.frames = 400;
  scenario.drift_per_second.setZero();
  scenario.drift_per_second(4) = 4.5 * kDeg / 60.0;   // pitch_l
  scenario.drift_per_second(5) = -6.0 * kDeg / 60.0;  // yaw_l
  FilterConfig off;
  off.consistency_window = 0.0;
  const RunFigures before = run(scenario, off, 250, 399);
  const RunFigures after = run(scenario, FilterConfig(), 250, 399);
  std::cout << "all 12 within 3 sigma from frame 30: " << before.all_within3 << " -> "
            << after.all_within3 << ", beyond 5: " << before.beyond5 << " -> " << after.beyond5
            << ", largest |error| / sigma " << before.max_ratio << " -> " << after.max_ratio
            << "\n";
  EXPECT_GT(before.beyond5, 0.5);  // the ramp is far faster than the configured walk
  EXPECT_EQ(after.beyond5, 0.0);
  EXPECT_LT(after.max_ratio, 5.0);
  EXPECT_GE(after.all_within3, 0.6);
  EXPECT_GT(after.acting, 0.0);
}

// The same drift with x_camr's drift rate as a state and no monitor: followed without a lag
// (measured: all 12 within 3 sigma in 100 % of frames 30-1199, yaw_r within 2 sigma in 100 %
// of frames 1000-1150).
TEST(ConsistencyScenario, FastRightCameraDriftIsFollowedByTheDriftRateAlone) {
  MeasurementScenario scenario = thermalDrift();
  scenario.frames = 1200;
  FilterConfig rate_only;
  ASSERT_GT(rate_only.camr_rotation_drift_rate_sigma, 0.0);
  rate_only.consistency_window = 0.0;
  const RunFigures f = run(scenario, rate_only, 1000, 1150);
  EXPECT_GE(f.all_within3, 0.95);
  EXPECT_EQ(f.beyond5, 0.0);
  EXPECT_GE(f.within2(11), 0.9);  // yaw_r
}

// The paper's drive (with its step) is not disturbed: the monitor acts rarely.
TEST(ConsistencyScenario, PaperDriveRarelyTriggers) {
  const RunFigures f = run(paperOffroadScenario(), FilterConfig(), 1000, 1150);
  EXPECT_LT(f.acting, 0.05);
  for (int k = 0; k < 12; ++k) EXPECT_GE(f.within2(k), 0.85) << "parameter " << k;
}

// The before/after table of docs/RESULTS.md ("Consistency monitor"):
//   test_consistency_monitor --gtest_also_run_disabled_tests --gtest_filter='*Report*'
TEST(ConsistencyScenario, DISABLED_Report) {
  struct Case {
    const char* name;
    MeasurementScenario scenario;
  };
  std::vector<Case> cases = {{"thermal 0.3/-0.2 deg 5 mm / 90 s", thermalDrift()},
                             {"yaw_r 0.5 deg + yr 5 mm / min", drifting(0.5, 0.0, 0.005, 60.0)},
                             {"pitch_r -0.5 deg + yr 5 mm / min", drifting(0.0, -0.5, 0.005, 60.0)},
                             {"paper_offroad", paperOffroadScenario()},
                             {"urban_planar", urbanPlanarScenario()},
                             {"drift (stock)", driftScenario()}};
  for (const Case& c : cases) {
    for (unsigned seed : {1u, 2u, 3u}) {
      MeasurementScenario scenario = c.scenario;
      scenario.seed = seed;
      for (bool on : {false, true}) {
        FilterConfig config;
        if (!on) config.consistency_window = 0.0;
        const RunFigures f = run(scenario, config, 1000, 1150);
        std::printf(
            "%-34s seed %u %-3s | all12<=3s %5.1f %% | >5s %5.1f %% | max %5.2f | acting %5.1f %% "
            "| 2s yr %3.0f pr %3.0f yawr %3.0f min %3.0f %% | rmse yr %.2f mm pr %.4f yawr %.4f "
            "deg yawl %.3f deg xl %.1f mm | %.2f ms\n",
            c.name, seed, on ? "on" : "off", 100 * f.all_within3, 100 * f.beyond5, f.max_ratio,
            100 * f.acting, 100 * f.within2(7), 100 * f.within2(10), 100 * f.within2(11),
            100 * f.within2.minCoeff(), 1e3 * f.rmse(7), f.rmse(10) / kDeg, f.rmse(11) / kDeg,
            f.rmse(5) / kDeg, 1e3 * f.rmse(0), f.ms_per_frame);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace
}  // namespace osc
