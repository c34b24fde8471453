/// @file test_jump_test.cpp
/// @brief Change detection at the filter's gate (jump_test.h): which block is suspected,
/// when a share of gated-out points is a jump (at once, sustained), and x_caml's fitted turn.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "online_stereo_calibration/core/estimator/jump_test.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "test_intrinsics.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// A filter whose blocks are known to 1 mm and 0.06 deg: both may be re-opened.
struct Bench {
  CalibrationFilter filter{FilterConfig(), testIntrinsics()};
  JumpTestOptions options = JumpTestOptions::from(FilterConfig());

  Bench() { start(); }
  void start() {
    const Vector12d sigma = Vector12d::Constant(1e-3);
    filter.reset(StereoExtrinsics(), sigma.array().square().matrix().asDiagonal());
  }
};

/// @p tested points on a grid of the left image; the first @p gated are gated out, and of
/// those the first @p left_failing fail in the left image alone. Measured where predicted.
GateOutcome gate(int tested, int gated, int left_failing) {
  GateOutcome outcome;
  for (int i = 0; i < tested; ++i) {
    GatedPoint point;
    point.predicted_left = Eigen::Vector2d(60.0 + 50.0 * (i % 10), 60.0 + 50.0 * (i / 10));
    point.measured_left = point.predicted_left;
    point.S_left = Eigen::Matrix2d::Identity() * 0.25;
    point.gated_out = i < gated;
    point.nis_left = i < left_failing ? 100.0 : 1.0;
    outcome.points.push_back(point);
  }
  return outcome;
}

TEST(JumpTest, MostPointsGatedOutAtOnceReopenTheBlockTheLeftImageBlames) {
  Bench bench;
  bench.options.fit_rotation_sigma = 0.0;  // the whole block, no fit
  JumpTest test(bench.options);
  // 12 of 20 gated out (0.6), 6 of them in the left image alone: x_caml.
  Reopening r = test.decide(gate(20, 12, 6), bench.filter);
  EXPECT_EQ(r.block, JumpBlock::kVehicleToLeft);
  EXPECT_FALSE(r.turned);
  EXPECT_NEAR(r.sigma(0), bench.options.translation_sigma, 1e-15);
  EXPECT_NEAR(r.sigma(4), bench.options.rotation_sigma, 1e-15);
  EXPECT_EQ(r.message, "sudden calibration change detected");
  // 12 of 20 gated out, only 5 in the left image: the right camera's.
  EXPECT_EQ(test.decide(gate(20, 12, 5), bench.filter).block, JumpBlock::kLeftToRight);
  // 11 of 20 is below the fraction, and 12 of 12 too few points to judge.
  EXPECT_EQ(test.decide(gate(20, 11, 11), bench.filter).block, JumpBlock::kNone);
  EXPECT_EQ(test.decide(gate(7, 7, 7), bench.filter).block, JumpBlock::kNone);
}

TEST(JumpTest, ABlockStillAsUncertainAsAReopenedOneIsNotReopened) {
  Bench bench;
  bench.filter.reset(StereoExtrinsics());  // the config's initial sigmas: wide
  ASSERT_FALSE(bench.filter.canReopen(JumpBlock::kVehicleToLeft));
  JumpTest test(bench.options);
  EXPECT_EQ(test.decide(gate(20, 20, 20), bench.filter).block, JumpBlock::kNone);
}

TEST(JumpTest, ASmallerShareInSeveralFramesInARowIsAJumpOnceTheBlockHasSettled) {
  Bench bench;
  bench.options.settle_time = 0.0;
  JumpTest test(bench.options);
  const GateOutcome partly = gate(20, 7, 7);  // 0.35: above the sustained 0.3, below 0.6
  for (int frame = 1; frame < bench.options.sustained_frames; ++frame)
    EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kNone) << frame;
  EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kVehicleToLeft);
  // The streak started over with the jump; a clean frame breaks it too.
  for (int frame = 1; frame < bench.options.sustained_frames; ++frame)
    EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kNone);
  EXPECT_EQ(test.decide(gate(20, 0, 0), bench.filter).block, JumpBlock::kNone);
  EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kNone);
  // A start of the filter starts the streak over as well.
  EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kNone);
  bench.start();
  EXPECT_EQ(test.decide(partly, bench.filter).block, JumpBlock::kNone);
  // Before the block has settled the sustained test waits.
  Bench unsettled;
  JumpTest waiting(unsettled.options);  // settle_time 5 s, the filter just started
  for (int frame = 0; frame < 2 * unsettled.options.sustained_frames; ++frame)
    EXPECT_EQ(waiting.decide(partly, unsettled.filter).block, JumpBlock::kNone);
}

/// Every point seen turned by @p R_optical (measured bearing = R_optical x predicted).
GateOutcome turnedGate(const Eigen::Matrix3d& R_optical, double noise_px, std::mt19937* rng) {
  const Eigen::Matrix3d K = testIntrinsics().K_left;
  std::normal_distribution<double> noise(0.0, noise_px);
  GateOutcome outcome = gate(30, 30, 30);
  for (GatedPoint& point : outcome.points) {
    const Eigen::Vector3d bearing = K.inverse() * point.predicted_left.homogeneous();
    point.measured_left =
        (K * R_optical * bearing).hnormalized() + Eigen::Vector2d(noise(*rng), noise(*rng));
  }
  return outcome;
}

TEST(JumpTest, AJumpOfTheLeftCameraFoundAtOnceIsFittedAndOnlyTheTurnedAxisReopened) {
  Bench bench;
  JumpTest test(bench.options);
  std::mt19937 rng(3);
  // The camera turned 4 deg about its optical y axis (the body's -z: a yaw).
  const Eigen::Matrix3d R_optical = rotationFromRpy(Eigen::Vector3d(0, 4 * kDeg, 0));
  const Reopening r = test.decide(turnedGate(R_optical, 0.3, &rng), bench.filter);
  ASSERT_EQ(r.block, JumpBlock::kVehicleToLeft);
  ASSERT_TRUE(r.turned);
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Matrix3d expected = R_bo * R_optical.transpose() * R_bo.transpose();
  EXPECT_LT(rotationDistance(r.turn, expected), 0.02 * kDeg);
  EXPECT_NEAR(r.sigma(5), 4 * kDeg, 0.02 * kDeg);                    // yaw: by what it turned
  EXPECT_NEAR(r.sigma(3), bench.options.fit_rotation_sigma, 1e-12);  // the floor
  EXPECT_NEAR(r.sigma(4), bench.options.fit_rotation_sigma, 1e-12);
  EXPECT_NEAR(r.sigma(0), bench.options.translation_sigma, 1e-15);
  EXPECT_NE(r.message.find("rotation fitted to 30 of 30 points"), std::string::npos) << r.message;
}

TEST(JumpTest, PointsNoSingleTurnExplainsReopenTheWholeBlockInPlace) {
  Bench bench;
  JumpTest test(bench.options);
  std::mt19937 rng(5);
  // Each point off by its own 15 px: many gated out, but no turn of the camera.
  GateOutcome scattered = turnedGate(Eigen::Matrix3d::Identity(), 15.0, &rng);
  const Reopening r = test.decide(scattered, bench.filter);
  ASSERT_EQ(r.block, JumpBlock::kVehicleToLeft);
  EXPECT_FALSE(r.turned);
  for (int k : {3, 4, 5}) EXPECT_NEAR(r.sigma(k), bench.options.rotation_sigma, 1e-15);
}

}  // namespace
}  // namespace osc
