/// @file test_restart_from_estimate.cpp
/// @brief The linearisation guard's restart from the estimate (restart_from_estimate.h): when
/// it restarts, what it restarts with, and what it leaves alone.
#include <gtest/gtest.h>

#include <cmath>

#include "online_stereo_calibration/core/estimator/restart_from_estimate.h"
#include "test_intrinsics.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

StereoExtrinsics rig() {
  Vector12d p;
  p << 1.5, 0.1, 1.3, 0, 5 * kDeg, 0, 0, -0.3, 0, 0, 0, 0;
  return StereoExtrinsics::fromParameters(p);
}

/// The start covariance: 0.1 m and 2 deg on x_caml, 2 cm and 0.3 deg on x_camr.
Matrix12d startCovariance() {
  Vector12d sigma;
  sigma << 0.1, 0.1, 0.1, 2 * kDeg, 2 * kDeg, 2 * kDeg, 0.02, 0.02, 0.02, 0.3 * kDeg, 0.3 * kDeg,
      0.3 * kDeg;
  return sigma.array().square().matrix().asDiagonal();
}

/// A step that used @p points measurements at @p nis_per_dof of their expected size.
StepReport stepAt(double nis_per_dof, int points = 20) {
  StepReport step;
  step.accepted = true;
  step.measurements_used = points;
  step.mean_nis = 4.0 * nis_per_dof;  // 4 coordinates per stereo measurement
  return step;
}

/// A filter started at rig() whose estimate then moved xl by @p xl_sigmas start sigmas, with
/// a covariance 100 times smaller than the start's (it converged there).
struct MovedFilter {
  CalibrationFilter filter{FilterConfig(), testIntrinsics()};
  RestartFromEstimate restart{RestartFromEstimateOptions()};

  explicit MovedFilter(double xl_sigmas) {
    filter.reset(rig(), startCovariance());
    restart.anchorHere(filter, JumpBlock::kNone, Vector6d::Zero());
    Vector12d p = rig().toParameters();
    p(0) += xl_sigmas * 0.1;
    filter.reset(StereoExtrinsics::fromParameters(p), startCovariance() / 100.0);
  }
  /// Runs @p steps checks; the decision of the last.
  RestartDecision check(int steps, double nis_per_dof) {
    RestartDecision last;
    for (int k = 0; k < steps; ++k) last = restart.checkAfterStep(&filter, stepAt(nis_per_dof));
    return last;
  }
};

TEST(RestartFromEstimate, AFarMoveWithLargeInnovationsRestartsAtTheEstimateWithTheStartSigmas) {
  MovedFilter moved(1.0);  // 1 start sigma: beyond the 0.5 threshold, below the far move
  const RestartFromEstimateOptions options;
  // Checked every 15 steps only.
  EXPECT_FALSE(moved.check(options.frames - 1, 1.2).restarted);
  const Vector12d before = moved.filter.extrinsics().toParameters();
  const RestartDecision decision = moved.check(1, 1.2);
  ASSERT_TRUE(decision.restarted);
  EXPECT_NE(decision.warning.find("restarted from the current estimate"), std::string::npos);
  EXPECT_NE(decision.warning.find("x_caml moved 1"), std::string::npos) << decision.warning;
  // At the estimate; the block that moved (x_caml) with its start sigmas again, x_camr
  // keeping what it learned.
  EXPECT_TRUE(moved.filter.extrinsics().toParameters().isApprox(before, 1e-12));
  Matrix12d expected = startCovariance() / 100.0;
  expected.topLeftCorner<6, 6>() = startCovariance().topLeftCorner<6, 6>();
  EXPECT_TRUE(moved.filter.covariance().isApprox(expected, 1e-12)) << moved.filter.covariance();
}

TEST(RestartFromEstimate, InnovationsAsExpectedKeepAConvergingStart) {
  // The same move at 1.0 of the expected innovations: a start converging within its prior.
  MovedFilter moved(1.0);
  EXPECT_FALSE(moved.check(15, 1.0).restarted);
  EXPECT_TRUE(moved.filter.covariance().isApprox(startCovariance() / 100.0, 1e-12));
  // A small move with large innovations is no far-off linearisation either.
  MovedFilter small(0.3);
  EXPECT_FALSE(small.check(15, 1.5).restarted);
}

TEST(RestartFromEstimate, AMoveBeyondTheFarThresholdRestartsAtTheLowerGate) {
  // 3 start sigmas at 0.96 of the expected innovations: above the far gate 0.95, below 1.05.
  MovedFilter far(3.0);
  EXPECT_TRUE(far.check(15, 0.96).restarted);
  MovedFilter not_far(1.5);
  EXPECT_FALSE(not_far.check(15, 0.96).restarted);
  // The far gate holds only before the first restart: moved 3 start sigmas again.
  Vector12d p = far.filter.extrinsics().toParameters();
  p(0) += 0.3;
  far.filter.reset(StereoExtrinsics::fromParameters(p), startCovariance() / 100.0);
  EXPECT_FALSE(far.check(15, 0.96).restarted);
  EXPECT_TRUE(far.check(15, 1.2).restarted);
}

TEST(RestartFromEstimate, AtMostMaxRestartsAndOffWithZeroFrames) {
  MovedFilter moved(1.0);
  RestartFromEstimateOptions options;
  int restarts = 0;
  for (int check = 0; check < 10; ++check) {
    // Move the estimate on again after each restart.
    Vector12d p = moved.filter.extrinsics().toParameters();
    p(0) += 0.1;
    moved.filter.reset(StereoExtrinsics::fromParameters(p), startCovariance() / 100.0);
    restarts += moved.check(options.frames, 1.2).restarted;
  }
  EXPECT_EQ(restarts, options.max_restarts);

  options.frames = 0;
  CalibrationFilter filter(FilterConfig(), testIntrinsics());
  filter.reset(rig(), startCovariance());
  RestartFromEstimate off(options);
  off.anchorHere(filter, JumpBlock::kNone, Vector6d::Zero());
  Vector12d p = rig().toParameters();
  p(0) += 0.3;
  filter.reset(StereoExtrinsics::fromParameters(p), startCovariance() / 100.0);
  for (int k = 0; k < 100; ++k) EXPECT_FALSE(off.checkAfterStep(&filter, stepAt(2.0)).restarted);
}

TEST(RestartFromEstimate, AfterAReopeningOnlyTheReopenedComponentsAreCheckedAndRestarted) {
  // x_camr's rotation re-opened to 1 deg; its translation converged (1 mm) is not checked.
  CalibrationFilter filter(FilterConfig(), testIntrinsics());
  Matrix12d converged = startCovariance() / 10000.0;
  filter.reset(rig(), converged);
  RestartFromEstimate restart{RestartFromEstimateOptions()};
  const Vector6d reopened = uniformBlockSigmas(0.0, 1.0 * kDeg);
  filter.reopen(JumpBlock::kLeftToRight, reopened);
  restart.anchorHere(filter, JumpBlock::kLeftToRight, reopened);
  // The translation moved 5 of its converged sigmas (0.2 mm x 5): not checked.
  Vector12d p = filter.extrinsics().toParameters();
  p(7) += 0.001;
  filter.reset(StereoExtrinsics::fromParameters(p), filter.covariance());
  EXPECT_FALSE([&] {
    RestartDecision d;
    for (int k = 0; k < 15; ++k) d = restart.checkAfterStep(&filter, stepAt(1.5));
    return d.restarted;
  }());
  // The yaw moved 0.8 of its re-opened sigma: restarted, x_camr's rotation widened to the
  // re-opening again, x_caml kept.
  p = filter.extrinsics().toParameters();
  p(11) += 0.8 * kDeg;
  Matrix12d shrunk = filter.covariance();
  shrunk.bottomRightCorner<3, 3>() /= 100.0;
  filter.reset(StereoExtrinsics::fromParameters(p), shrunk);
  RestartDecision d;
  for (int k = 0; k < 15; ++k) d = restart.checkAfterStep(&filter, stepAt(1.5));
  ASSERT_TRUE(d.restarted);
  EXPECT_NE(d.warning.find("x_camr moved"), std::string::npos) << d.warning;
  const Matrix12d after = filter.covariance();
  EXPECT_NEAR(std::sqrt(after(11, 11)), 1.0 * kDeg, 1e-9);
  EXPECT_NEAR(after(0, 0), converged(0, 0), 1e-15);
}

}  // namespace
}  // namespace osc
