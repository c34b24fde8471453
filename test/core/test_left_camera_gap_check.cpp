/// @file test_left_camera_gap_check.cpp
/// @brief Change detection for x_caml after a stretch without points (left_camera_gap_check.h):
/// when it is armed, when it re-opens, and what it re-opens to.
#include <gtest/gtest.h>

#include <cmath>

#include "online_stereo_calibration/core/estimator/left_camera_gap_check.h"
#include "test_intrinsics.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

MotionIncrement motion() {
  MotionIncrement m;
  m.dt = 0.1;
  return m;
}

/// A step that used @p measurements.
StepReport step(int measurements) {
  StepReport s;
  s.accepted = true;
  s.measurements_used = measurements;
  return s;
}

/// The monitor after it: its x_caml statistic beyond its bound (@p exceeded) over
/// @p window_updates updates.
ConsistencyStatus status(bool exceeded = false, int window_updates = 0) {
  ConsistencyStatus c;
  c.exceeded[static_cast<int>(ConsistencyBlock::kVehicleToLeft)] = exceeded;
  c.statistic[0] = exceeded ? 9.0 : 0.5;
  c.bound[0] = 3.8;
  c.window_updates = window_updates;
  return c;
}

struct Bench {
  CalibrationFilter filter{FilterConfig(), testIntrinsics()};
  LeftCameraGapCheck check{LeftCameraGapCheckOptions::from(FilterConfig())};
  ConsistencyMonitor monitor{FilterConfig()};

  Bench() {
    Vector12d sigma = Vector12d::Constant(1e-3);
    filter.reset(StereoExtrinsics(), sigma.array().square().matrix().asDiagonal());
  }
  /// @p seconds of steps without a measured point, then points come back.
  void blind(double seconds) {
    for (int k = 0; k < std::lround(seconds / 0.1); ++k) check.countAfterStep(motion(), step(0));
    check.beforeStep(&monitor, true);
  }
};

TEST(LeftCameraGapCheck, AfterAStretchWithoutPointsDisagreeingUpdatesReopenTheLeftCamera) {
  Bench bench;
  bench.blind(2.5);  // beyond unobserved_gap_s (2 s)
  // Two updates are too few to judge, the third re-opens.
  EXPECT_FALSE(
      bench.check.checkAfterStep(&bench.filter, motion(), step(20), status(true, 2)).reopened);
  const GapDecision decision =
      bench.check.checkAfterStep(&bench.filter, motion(), step(20), status(true, 3));
  ASSERT_TRUE(decision.reopened);
  EXPECT_NE(decision.warning.find("x_caml re-opened"), std::string::npos);
  const FilterConfig config;
  EXPECT_NEAR(decision.sigma(0), config.jump_translation_sigma, 1e-15);
  EXPECT_NEAR(decision.sigma(5), config.jump_rotation_sigma, 1e-15);
  const Matrix12d P = bench.filter.covariance();
  EXPECT_NEAR(std::sqrt(P(5, 5)), config.jump_rotation_sigma, 1e-12);  // x_caml's yaw
  EXPECT_NEAR(std::sqrt(P(11, 11)), 1e-3, 1e-12);                      // x_camr kept
  // Once answered it is disarmed.
  EXPECT_FALSE(
      bench.check.checkAfterStep(&bench.filter, motion(), step(20), status(true, 5)).reopened);
}

TEST(LeftCameraGapCheck, AShortStretchAgreeingUpdatesOrAJumpLeaveTheLeftCameraAlone) {
  Bench short_stretch;
  short_stretch.blind(1.5);  // below unobserved_gap_s
  EXPECT_FALSE(
      short_stretch.check.checkAfterStep(&short_stretch.filter, motion(), step(20), status(true, 5))
          .reopened);

  Bench agreeing;
  agreeing.blind(2.5);
  for (int k = 0; k < 10; ++k) {
    EXPECT_FALSE(
        agreeing.check.checkAfterStep(&agreeing.filter, motion(), step(20), status(false, 5))
            .reopened);
  }

  Bench answered;
  answered.blind(2.5);
  answered.check.disarm();  // a jump of x_caml was found on its own evidence
  EXPECT_FALSE(answered.check.checkAfterStep(&answered.filter, motion(), step(20), status(true, 5))
                   .reopened);
}

TEST(LeftCameraGapCheck, ArmedForTheConsistencyWindowOfUpdatesOnly) {
  Bench bench;
  bench.blind(2.5);
  // consistency_window_s = 4 s of updates (and one more) that agree, then a disagreeing one:
  // too late.
  for (int k = 0; k < 41; ++k) {
    EXPECT_FALSE(
        bench.check.checkAfterStep(&bench.filter, motion(), step(20), status(false, 5)).reopened);
  }
  EXPECT_FALSE(
      bench.check.checkAfterStep(&bench.filter, motion(), step(20), status(true, 5)).reopened);
  // Steps without a measurement do not use up the window.
  Bench waiting;
  waiting.blind(2.5);
  for (int k = 0; k < 100; ++k)
    waiting.check.checkAfterStep(&waiting.filter, motion(), step(0), status());
  EXPECT_TRUE(
      waiting.check.checkAfterStep(&waiting.filter, motion(), step(20), status(true, 3)).reopened);
}

}  // namespace
}  // namespace osc
