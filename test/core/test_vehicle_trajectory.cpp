// Tests of the simulated vehicle's motion: VehicleTrajectory's speed, roll and pitch, steering
// phase, planar profile and stops (measurement_simulator.h), and a recorded PoseTrajectory's
// smooth interpolation (pose_interpolation.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "measurement_simulator_test_support.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {
namespace {

TEST(VehicleTrajectory, MovesAtTheProfileSpeedWithPaperLikeRollAndPitch) {
  const VehicleMotionProfile profile;
  const VehicleTrajectory trajectory(profile);
  EXPECT_TRUE(trajectory.pose(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  std::vector<double> roll, pitch;
  const double h = 1e-4;
  for (double t = 0.0; t < 150.0; t += 0.1) {
    // The ground track is the integral of speed * heading: check its derivative.
    const Eigen::Vector2d velocity =
        (trajectory.groundPosition(t + h) - trajectory.groundPosition(t - h)) / (2 * h);
    const double yaw = trajectory.yaw(t);
    ASSERT_NEAR(velocity.x(), profile.speed * std::cos(yaw), 1e-6) << "t = " << t;
    ASSERT_NEAR(velocity.y(), profile.speed * std::sin(yaw), 1e-6) << "t = " << t;
    const Vector6d p = parametersFromPose(trajectory.pose(t));
    roll.push_back(p(3));
    pitch.push_back(p(4));
  }
  // Std of 1.75 deg as in the seed's off-road drive (algorithm.md).
  EXPECT_NEAR(stddev(roll), 1.75 * kDeg, 0.1 * kDeg);
  EXPECT_NEAR(stddev(pitch), 1.75 * kDeg, 0.1 * kDeg);
}

TEST(VehicleTrajectory, PositionIsContinuousAcrossSteeringPeriods) {
  // The whole-period shortcut and the quadrature must agree at the period boundaries.
  const VehicleMotionProfile profile;
  const VehicleTrajectory trajectory(profile);
  for (int k = 1; k < 6; ++k) {
    const double t = k * profile.yaw_period;
    const Eigen::Vector2d before = trajectory.groundPosition(t - 1e-9);
    const Eigen::Vector2d after = trajectory.groundPosition(t + 1e-9);
    EXPECT_LT((after - before).norm(), 1e-7) << "period " << k;
  }
}

TEST(VehicleTrajectory, TheSteeringPhaseStartsTheDriveInItsTurnAndHalfAPeriodMirrorsIt) {
  VehicleMotionProfile left_first, right_first, straight;
  right_first.yaw_phase = M_PI;
  straight.yaw_phase = M_PI / 2.0;  // yaw rate A cos(w t + pi/2) = -A sin(w t): then right
  const VehicleTrajectory left(left_first), right(right_first), ahead(straight);
  const double amplitude = left_first.yaw_rate_amplitude, h = 1e-4;
  const auto rate = [h](const VehicleTrajectory& v, double t) {
    return (v.yaw(t + h) - v.yaw(t - h)) / (2.0 * h);
  };
  // Every phase starts at the world's origin heading along +x.
  for (const VehicleTrajectory* v : {&left, &right, &ahead}) {
    EXPECT_NEAR(v->yaw(0.0), 0.0, 1e-15);
    EXPECT_TRUE(v->pose(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  }
  EXPECT_NEAR(rate(left, 0.0), amplitude, 1e-6);
  EXPECT_NEAR(rate(right, 0.0), -amplitude, 1e-6);
  EXPECT_NEAR(rate(ahead, 0.0), 0.0, 1e-6);
  EXPECT_LT(rate(ahead, 2.0), -0.1 * amplitude);
  // Phase pi steers phase 0's drive mirrored in the x-z plane: yaw and y change sign, x stays
  // (roll, pitch and heave keep their own phases).
  for (double t = 0.0; t < 60.0; t += 0.7) {
    EXPECT_NEAR(right.yaw(t), -left.yaw(t), 1e-12) << t;
    const Eigen::Vector2d l = left.groundPosition(t), r = right.groundPosition(t);
    EXPECT_NEAR(r.x(), l.x(), 1e-9) << t;
    EXPECT_NEAR(r.y(), -l.y(), 1e-9) << t;
    EXPECT_EQ(right.roll(t), left.roll(t));
    EXPECT_EQ(right.heave(t), left.heave(t));
  }
  // The ground track still repeats every steering period (the whole-period shortcut).
  for (int k = 1; k < 4; ++k) {
    const double t = k * straight.yaw_period;
    EXPECT_LT((ahead.groundPosition(t + 1e-9) - ahead.groundPosition(t - 1e-9)).norm(), 1e-7);
  }
}

TEST(VehicleTrajectory, PhaseZeroIsTheUnshiftedSteeringBitForBit) {
  // Scenarios written before the phase existed must drive exactly as before.
  const VehicleMotionProfile profile;
  ASSERT_EQ(profile.yaw_phase, 0.0);
  const VehicleTrajectory trajectory(profile);
  const double heading_amplitude = profile.yaw_rate_amplitude * profile.yaw_period / (2 * M_PI);
  for (double t = 0.0; t < 100.0; t += 0.31) {
    EXPECT_EQ(trajectory.yaw(t), heading_amplitude * std::sin(2.0 * M_PI * t / profile.yaw_period));
  }
}

TEST(VehicleTrajectory, PlanarProfileHasNoRollPitchOrHeave) {
  VehicleMotionProfile profile;
  profile.planar = true;
  const VehicleTrajectory trajectory(profile);
  for (double t = 0.0; t < 30.0; t += 0.37) {
    const Eigen::Isometry3d pose = trajectory.pose(t);
    EXPECT_NEAR(pose.translation().z(), 0.0, 1e-15);
    EXPECT_NEAR((pose.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 0.0,
                1e-15);
  }
}

/// Ground speed (m/s) by central differences.
double groundSpeed(const VehicleTrajectory& trajectory, double t) {
  const double h = 1e-5;
  return (trajectory.groundPosition(t + h) - trajectory.groundPosition(t - h)).norm() / (2 * h);
}

TEST(VehicleTrajectory, StopsStandStillWithSmoothRampsAndThenDriveOn) {
  VehicleMotionProfile profile;
  profile.stops = {{10.0, 5.0}, {30.0, 2.0}};
  profile.stop_ramp = 2.0;
  const VehicleTrajectory stopping(profile);
  VehicleMotionProfile plain = profile;
  plain.stops.clear();
  const VehicleTrajectory driving(plain);
  // Before the first slow-down: the same drive, bit for bit.
  for (double t = 0.0; t <= 8.0; t += 0.5) {
    EXPECT_TRUE(stopping.pose(t).matrix() == driving.pose(t).matrix()) << "t = " << t;
  }
  // Inside the stop everything stands: the same pose, zero speed, exactly identity motion.
  const Eigen::Isometry3d standing = stopping.pose(10.0);
  for (double t = 10.0; t <= 15.0; t += 0.1) {
    EXPECT_TRUE(stopping.pose(t).matrix() == standing.matrix()) << "t = " << t;
    EXPECT_TRUE(stopping.motionBetween(10.0, t).matrix() == Eigen::Matrix4d::Identity());
    EXPECT_EQ(stopping.profileRate(t), 0.0);
  }
  EXPECT_NEAR(groundSpeed(stopping, 12.5), 0.0, 1e-9);
  // Smooth speed: it follows speed * rate, without jumps, full before and after the ramps.
  double previous = groundSpeed(stopping, 7.0);
  EXPECT_NEAR(previous, profile.speed, 1e-6);
  for (double t = 7.0; t <= 18.0; t += 0.01) {
    const double speed = groundSpeed(stopping, t);
    ASSERT_NEAR(speed, profile.speed * stopping.profileRate(t), 1e-5) << "t = " << t;
    // Max slope of the smoothstep ramp: 1.5 / stop_ramp per s.
    ASSERT_LE(std::abs(speed - previous), profile.speed * 1.5 / profile.stop_ramp * 0.01 + 1e-5)
        << "speed jumps at t = " << t;
    previous = speed;
  }
  EXPECT_NEAR(groundSpeed(stopping, 17.5), profile.speed, 1e-6);
  // Afterwards the profile continues where it stopped: it lags by duration + ramp per stop.
  EXPECT_DOUBLE_EQ(stopping.profileTime(25.0), 25.0 - 7.0);
  EXPECT_TRUE(stopping.pose(25.0).isApprox(driving.pose(18.0), 1e-12));
  EXPECT_TRUE(stopping.pose(40.0).isApprox(driving.pose(40.0 - 7.0 - 4.0), 1e-12));
  // The yaw, roll, pitch and heave are frozen with the vehicle's clock.
  EXPECT_EQ(stopping.roll(11.0), stopping.roll(14.0));
  EXPECT_EQ(stopping.yaw(31.0), driving.yaw(30.0 - 7.0 - 1.0));
}

TEST(VehicleTrajectory, AnAbruptStopWithoutRampAlsoStandsStill) {
  VehicleMotionProfile profile;
  profile.stops = {{0.0, 3.0}};
  profile.stop_ramp = 0.0;
  const VehicleTrajectory trajectory(profile);
  EXPECT_TRUE(trajectory.pose(0.0).matrix() == trajectory.pose(3.0).matrix());
  EXPECT_EQ(trajectory.profileTime(5.0), 2.0);
  EXPECT_NEAR(groundSpeed(trajectory, 5.0), profile.speed, 1e-6);
}

// Issue 15: a recorded drive's twists must be the derivative of its pose, also across the
// recorded samples; at()'s linear pieces jump there, smoothAt() does not.
TEST(PoseTrajectory, SmoothAtPassesThroughThePosesWithContinuousVelocityAndRate) {
  VehicleMotionProfile profile;
  profile.speed = 6.0;
  profile.yaw_rate_amplitude = 0.4;
  const VehicleTrajectory analytic(profile);
  const std::shared_ptr<const PoseTrajectory> recording = recordingOf(profile, 5.0);
  const auto twist = [](const auto& poseAt, double t0, double t1) -> Vector6d {
    return logSE3(poseAt(t0).inverse() * poseAt(t1)) / (t1 - t0);
  };
  const auto smooth = [&recording](double t) { return *recording->smoothAt(t); };
  const auto linear = [&recording](double t) { return *recording->at(t); };
  const double h = 1e-5;
  double smooth_jump = 0.0, linear_jump = 0.0, smooth_error = 0.0, linear_error = 0.0;
  for (int k = 1; k < 99; ++k) {
    const double t = 1000.0 + 0.05 * k;
    ASSERT_TRUE(smooth(t).isApprox(recording->poses()[k].pose, 1e-12)) << "sample " << k;
    // The twist just before and just after the sample.
    smooth_jump = std::max(smooth_jump, (twist(smooth, t - h, t) - twist(smooth, t, t + h)).norm());
    linear_jump = std::max(linear_jump, (twist(linear, t - h, t) - twist(linear, t, t + h)).norm());
    // Between samples, against the drive that was recorded.
    const double between = t + 0.02;
    smooth_error += boxMinus(smooth(between), analytic.pose(between - 1000.0)).norm();
    linear_error += boxMinus(linear(between), analytic.pose(between - 1000.0)).norm();
  }
  EXPECT_LT(smooth_jump, 1e-3);  // m/s + rad/s: only the finite difference's own error
  EXPECT_GT(linear_jump, 0.05);  // 6 m/s, 0.4 rad/s of steering: the twist turns by 0.1
  EXPECT_LT(smooth_error, 0.2 * linear_error);
  // The ends and outside behave as at().
  EXPECT_TRUE(recording->smoothAt(1000.0)->isApprox(*recording->at(1000.0), 1e-12));
  EXPECT_FALSE(recording->smoothAt(999.0).has_value());
}

}  // namespace
}  // namespace osc
