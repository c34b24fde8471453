// The hand-eye start (issue 14): the camera's mounting rotation from the vehicle's and the
// camera's motion alone (hand_eye_rotation.h), and the camera's motion from two images
// (camera_motion.h). End to end through the estimator: test_hand_eye_start_end_to_end.cpp.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/estimator/camera_motion.h"
#include "online_stereo_calibration/core/estimator/hand_eye_rotation.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Vector3d gaussian3(std::mt19937* rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
}

/// Feeds pairs of a drive: vehicle rotation increments with per-axis rms `rotation` (rad)
/// about the axes selected by `axes` (1 = used), noise of 0.02 deg per axis on the vehicle
/// and 0.01 deg on the camera; with directions (forward driving, a little lateral) if asked.
void feed(HandEyeRotation* solver, const Eigen::Matrix3d& X, const Eigen::Vector3d& axes,
          double rotation, bool directions, int pairs, std::mt19937* rng) {
  for (int i = 0; i < pairs; ++i) {
    const Eigen::Vector3d omega = gaussian3(rng, rotation).cwiseProduct(axes);
    const Eigen::Matrix3d R_v = expSO3(omega);
    const Eigen::Matrix3d R_c = X.transpose() * R_v * X;
    solver->addRotationPair(R_v * expSO3(gaussian3(rng, 0.02 * kDeg)),
                            R_c * expSO3(gaussian3(rng, 0.01 * kDeg)));
    if (directions) {
      const Eigen::Vector3d t_v(0.35, 0.02 * gaussian3(rng, 1.0).x(), 0.0);
      const Eigen::Vector3d u_c = X.transpose() * t_v.normalized();
      solver->addDirectionPair(t_v, (u_c + gaussian3(rng, 1.0 * kDeg)).normalized());
    }
  }
}

/// The solution's error (rad) and its Mahalanobis distance.
void expectRecovered(const HandEyeRotationResult& r, const Eigen::Matrix3d& X, double tolerance) {
  ASSERT_TRUE(r.determined) << r.reason;
  const Eigen::Vector3d error = logSO3(r.R_veh_cam.transpose() * X);
  EXPECT_LT(error.norm(), tolerance) << r.reason;
  EXPECT_LT(std::sqrt(error.dot(r.covariance.inverse() * error)), 4.0) << r.reason;
  EXPECT_LT(r.max_sigma, HandEyeRotationConfig().max_sigma);
}

TEST(HandEyeRotation, RecoversBackwardAndSidewaysMountingsFromRotationAboutAllAxes) {
  std::mt19937 rng(42);
  for (const Eigen::Vector3d& rpy :
       {Eigen::Vector3d(0.0, 0.0, M_PI), Eigen::Vector3d(0.0, 0.0, M_PI / 2),
        Eigen::Vector3d(0.05, -0.1, -M_PI / 2), Eigen::Vector3d(0.0, 0.05, 0.0)}) {
    const Eigen::Matrix3d X = rotationFromRpy(rpy);
    HandEyeRotation solver;
    feed(&solver, X, Eigen::Vector3d::Ones(), 0.5 * kDeg, false, 100, &rng);
    expectRecovered(solver.solve(), X, 0.6 * kDeg);
  }
}

TEST(HandEyeRotation, YawOnlyMotionLeavesTheVerticalAxisOpen) {
  std::mt19937 rng(7);
  const Eigen::Matrix3d X = rotationFromRpy(Eigen::Vector3d(0.0, 0.05, M_PI));
  HandEyeRotation solver;
  feed(&solver, X, Eigen::Vector3d::UnitZ(), 1.0 * kDeg, false, 100, &rng);
  const HandEyeRotationResult r = solver.solve();
  EXPECT_FALSE(r.determined);
  EXPECT_GT(std::abs(r.weakest_axis_vehicle.z()), 0.99) << r.reason;
  EXPECT_NE(r.reason.find("too little rotation about the vehicle axis"), std::string::npos);
  // Roll and pitch of the camera against the vertical are determined nevertheless: the
  // camera's rotation axis is the vehicle's z.
  EXPECT_LT(std::abs((r.R_veh_cam.transpose() * Eigen::Vector3d::UnitZ() -
                      X.transpose() * Eigen::Vector3d::UnitZ())
                         .norm()),
            0.2 * kDeg);
}

TEST(HandEyeRotation, YawOnlyMotionWithTheDrivingDirectionDeterminesEverything) {
  std::mt19937 rng(8);
  for (double yaw : {M_PI, M_PI / 2, -M_PI / 2}) {
    const Eigen::Matrix3d X = rotationFromRpy(Eigen::Vector3d(0.0, 0.05, yaw));
    HandEyeRotation solver;
    feed(&solver, X, Eigen::Vector3d::UnitZ(), 1.0 * kDeg, true, 100, &rng);
    expectRecovered(solver.solve(), X, 0.5 * kDeg);
  }
}

TEST(HandEyeRotation, NoRotationAndTooFewPairsAreNotDetermined) {
  std::mt19937 rng(9);
  HandEyeRotation solver;
  EXPECT_FALSE(solver.solve().determined);
  EXPECT_NE(solver.solve().reason.find("motion pairs"), std::string::npos);
  // Standing still: the increments are noise only.
  feed(&solver, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 0.0, false, 100, &rng);
  const HandEyeRotationResult r = solver.solve();
  EXPECT_FALSE(r.determined) << r.reason;
  EXPECT_NE(r.reason.find("not determined yet"), std::string::npos);
  // Driving straight: the driving direction alone leaves the rotation about it (roll) open,
  // however many pairs.
  const Eigen::Matrix3d X = rotationFromRpy(Eigen::Vector3d(0.0, 0.0, M_PI));
  feed(&solver, X, Eigen::Vector3d::Zero(), 0.0, false, 400, &rng);
  for (int i = 0; i < 400; ++i) {  // along x exactly, the camera's direction with 1 deg noise
    solver.addDirectionPair(Eigen::Vector3d(0.35, 0.0, 0.0),
                            X.transpose() * Eigen::Vector3d::UnitX() + gaussian3(&rng, 1.0 * kDeg));
  }
  const HandEyeRotationResult straight = solver.solve();
  EXPECT_FALSE(straight.determined) << straight.reason;
  EXPECT_EQ(straight.rotation_pairs, 0);  // below min_rotation: no excitation
  EXPECT_GT(std::abs(straight.weakest_axis_vehicle.x()), 0.99) << straight.reason;
}

// Default campaign run 192 (a sideways camera, urban, 16 % moving points) was blamed on the
// hand-eye flipping x_caml by 180 deg. The hand-eye's pairs there: yaw increments of 0.8 deg
// per frame on a curve, the camera's fitted rotation 0.2-0.3 deg off per axis (moving points),
// directions along the vehicle's x; it stayed undetermined (1 sigma 2-5 deg about x) until
// frame ~120-150 and then agreed with the truth within 0.3 deg. The flip was the filter's
// first update (frame 1), the same with the hand-eye start off. This pins the hand-eye's side:
// a sideways camera on a flat road with few pairs whose yaw increments are just above
// min_rotation and a camera fit that noisy is never offered flipped (the rotation about the
// driving axis, which only the sign of the yaw increments fixes), nor confidently wrong.
TEST(HandEyeRotation, FewWeakYawPairsOfASidewaysCameraAreNotOfferedFlipped) {
  const Eigen::Matrix3d X = rotationFromRpy(Eigen::Vector3d(0.0, 0.0, -M_PI / 2));
  int determined = 0;
  for (unsigned seed = 1; seed <= 100; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> yaw(0.15 * kDeg, 0.35 * kDeg);
    HandEyeRotation solver;
    for (int i = 0; i < 10; ++i) {
      const Eigen::Matrix3d R_v = expSO3(Eigen::Vector3d(0.0, 0.0, yaw(rng)));
      solver.addRotationPair(R_v * expSO3(gaussian3(&rng, 0.02 * kDeg)),
                             X.transpose() * R_v * X * expSO3(gaussian3(&rng, 0.25 * kDeg)));
      const Eigen::Vector3d t_v(1.2, 0.01 * gaussian3(&rng, 1.0).x(), 0.0);
      solver.addDirectionPair(t_v,
                              (X.transpose() * t_v.normalized() + gaussian3(&rng, 0.3 * kDeg)));
    }
    const HandEyeRotationResult r = solver.solve();
    ASSERT_EQ(r.rotation_pairs + r.direction_pairs, 20)
        << "seed " << seed;  // all above min_rotation
    // The driving axis is the open one, and it stays open (1 sigma 2-5 deg in run 192).
    EXPECT_GT(std::abs(r.weakest_axis_vehicle.x()), 0.99) << "seed " << seed << ": " << r.reason;
    EXPECT_GT(r.max_sigma, HandEyeRotationConfig().max_sigma) << "seed " << seed;
    if (!r.determined) continue;
    ++determined;  // (none on the current code; if ever, it must be right)
    const Eigen::Vector3d error = logSO3(r.R_veh_cam.transpose() * X);
    EXPECT_LT(error.norm(), 5.0 * kDeg) << "seed " << seed << ": " << r.reason;
  }
  EXPECT_EQ(determined, 0);
}

TEST(HandEyeRotation, IsRobustToAFewOutlierPairs) {
  std::mt19937 rng(10);
  const Eigen::Matrix3d X = rotationFromRpy(Eigen::Vector3d(0.02, 0.03, M_PI));
  HandEyeRotation solver;
  feed(&solver, X, Eigen::Vector3d::Ones(), 0.5 * kDeg, true, 90, &rng);
  for (int i = 0; i < 10; ++i) {  // 10 %: the camera's fit is wrong by a few degrees
    const Eigen::Matrix3d R_v = expSO3(gaussian3(&rng, 0.5 * kDeg));
    solver.addRotationPair(R_v, expSO3(gaussian3(&rng, 3.0 * kDeg)));
    solver.addDirectionPair(Eigen::Vector3d(0.35, 0.0, 0.0), gaussian3(&rng, 1.0));
  }
  expectRecovered(solver.solve(), X, 0.6 * kDeg);
}

TEST(CameraMotion, RecoversRotationAndTranslationDirectionInTheBodyFrame) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> pixel(0.0, 0.5 / 600.0);
  // Camera body c0 -> c1: forward 0.35 m, a little left, yaw 1 deg and roll 0.5 deg.
  const Eigen::Isometry3d T_c0_c1 =
      poseFromParameters((Vector6d() << 0.35, 0.05, 0.01, 0.5 * kDeg, 0.0, 1.0 * kDeg).finished());
  const Eigen::Isometry3d T_o0_o1 = bodyFromOptical().inverse() * T_c0_c1 * bodyFromOptical();
  std::vector<Eigen::Vector2d> p0, p1;
  while (p0.size() < 100) {
    const Eigen::Vector3d x0(4.0 * u(rng), 2.0 * u(rng), 10.0 + 8.0 * u(rng));  // optical o0
    const Eigen::Vector3d x1 = T_o0_o1.inverse() * x0;
    p0.emplace_back(x0.x() / x0.z() + pixel(rng), x0.y() / x0.z() + pixel(rng));
    p1.emplace_back(x1.x() / x1.z() + pixel(rng), x1.y() / x1.z() + pixel(rng));
  }
  p1[3] += Eigen::Vector2d(0.05, 0.0);  // an outlier, 30 px
  const CameraMotion m = estimateCameraMotion(p0, p1, CameraMotionConfig());
  ASSERT_TRUE(m.valid) << m.why;
  EXPECT_LT(rotationDistance(m.R_prev_curr, T_c0_c1.linear()), 0.1 * kDeg);
  EXPECT_LT(std::acos(m.translation_direction.dot(T_c0_c1.translation().normalized())), 1.0 * kDeg);
  EXPECT_GE(m.inliers, 95);  // all but the outlier, Sampson distance within 1.5 px
  // No translation: no parallax, no fit.
  std::vector<Eigen::Vector2d> same = p0;
  EXPECT_FALSE(estimateCameraMotion(p0, same, CameraMotionConfig()).valid);
  // Too few points.
  EXPECT_FALSE(estimateCameraMotion({p0.begin(), p0.begin() + 8}, {p1.begin(), p1.begin() + 8},
                                    CameraMotionConfig())
                   .valid);
}

}  // namespace
}  // namespace osc
