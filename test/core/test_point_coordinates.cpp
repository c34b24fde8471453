// Inverse-depth points (FilterConfig::inverse_depth_points): the conversions, the models on
// homogeneous points, inverse-depth triangulation, and a new far point's uncertainty under a
// wide x_camr prior against Monte Carlo.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/measurement_model.h"
#include "online_stereo_calibration/core/filter/point_coordinates.h"
#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

StereoIntrinsics intrinsics600() {
  StereoIntrinsics K;
  K.K_left << 600, 0, 320, 0, 600, 240, 0, 0, 1;
  K.K_right = K.K_left;
  return K;
}

/// A 0.3 m rig looking forward from 1.3 m, the right camera turned a little.
StereoExtrinsics smallRig() {
  Vector12d p;
  p << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0, 0.0, -0.3, 0.0, 0.2 * kDeg, -0.1 * kDeg, 0.3 * kDeg;
  return StereoExtrinsics::fromParameters(p);
}

TEST(PointCoordinates, InverseDepthRoundTripsAndItsJacobianIsTheDerivative) {
  const PointCoordinates inverse(true), position(false);
  const Eigen::Vector3d p(2.0, -1.0, 8.0);
  const Eigen::Vector3d c = inverse.fromPosition(p);
  EXPECT_TRUE(c.isApprox(Eigen::Vector3d(0.25, -0.125, 0.125)));
  EXPECT_TRUE(inverse.position(c, 1e-6).isApprox(p));
  EXPECT_DOUBLE_EQ(inverse.depth(c), 8.0);
  Eigen::Vector3d back;
  ASSERT_TRUE(inverse.fromHomogeneous(3.0 * inverse.homogeneous(c), &back));  // scale-free
  EXPECT_TRUE(back.isApprox(c));
  ASSERT_TRUE(position.fromHomogeneous(position.homogeneous(p), &back));
  EXPECT_TRUE(back.isApprox(p));
  // d c / d position, numerically.
  const Eigen::Matrix3d J = inverse.jacobianFromPosition(c);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d h = 1e-6 * Eigen::Vector3d::Unit(k);
    const Eigen::Vector3d numeric =
        (inverse.fromPosition(p + h) - inverse.fromPosition(p - h)) / 2e-6;
    EXPECT_LT((J.col(k) - numeric).norm(), 1e-8) << k;
  }
  EXPECT_TRUE(position.jacobianFromPosition(p).isIdentity());
  // At and beyond infinity: no depth, a far position, and no coordinates behind the camera.
  EXPECT_TRUE(std::isinf(inverse.depth(Eigen::Vector3d(0.1, 0.0, -0.01))));
  EXPECT_NEAR(inverse.position(Eigen::Vector3d(0.0, 0.0, -0.01), 0.01).z(), 100.0, 1e-9);
  EXPECT_FALSE(inverse.fromHomogeneous(Eigen::Vector4d(0.0, 0.0, -1.0, 0.1), &back));
}

TEST(PointCoordinates, HomogeneousModelsAgreeWithThePositionModels) {
  const StereoIntrinsics K = intrinsics600();
  const StereoExtrinsics rig = smallRig();
  Vector6d w;
  w << 0.4, 0.05, 0.01, 0.01, -0.02, 0.03;
  const Eigen::Isometry3d motion = poseFromParameters(w);
  const Eigen::Isometry3d T_veh_lopt = rig.vehicleToLeftOptical();
  const Eigen::Vector3d p(1.0, 0.5, 12.0), error(0.02, -0.01, 0.03);
  const Eigen::Matrix3d R_excited = rotationFromRpy(Eigen::Vector3d(0.005, -0.01, 0.02));
  // The motion: scaling the homogeneous point does not change the point it stands for.
  const Eigen::Vector4d moved =
      predictHomogeneousPoint(Eigen::Vector4d(2.0 * p.x(), 2.0 * p.y(), 2.0 * p.z(), 2.0),
                              T_veh_lopt, motion, error, R_excited);
  EXPECT_LT(
      (moved.head<3>() / moved.w() - predictPoint(p, T_veh_lopt, motion, error, R_excited)).norm(),
      1e-12);
  // A point at infinity only turns with the camera.
  const Eigen::Vector4d far = predictHomogeneousPoint(Eigen::Vector4d(0.1, 0.0, 1.0, 0.0),
                                                      T_veh_lopt, motion, error, R_excited);
  EXPECT_DOUBLE_EQ(far.w(), 0.0);
  EXPECT_NEAR(far.head<3>().norm(), Eigen::Vector3d(0.1, 0.0, 1.0).norm(), 1e-12);
  // The projection: the same pixels for w = 1, the limit for w -> 0.
  const Eigen::Isometry3d T_ropt_lopt = rig.leftToRightOptical().inverse();
  Eigen::Vector4d z3, z4, z_far, z_almost;
  ASSERT_TRUE(projectStereo(p, T_ropt_lopt, K, 0.1, &z3));
  ASSERT_TRUE(projectHomogeneousStereo(Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0), T_ropt_lopt, K,
                                       0.1, &z4));
  EXPECT_LT((z3 - z4).norm(), 1e-12);
  ASSERT_TRUE(
      projectHomogeneousStereo(Eigen::Vector4d(0.1, 0.0, 1.0, 0.0), T_ropt_lopt, K, 0.1, &z_far));
  ASSERT_TRUE(projectStereo(Eigen::Vector3d(1e5, 0.0, 1e6), T_ropt_lopt, K, 0.1, &z_almost));
  EXPECT_LT((z_far - z_almost).norm(), 1e-3);
}

TEST(PointCoordinates, InverseDepthTriangulationIsExactAndDefinedBeyondInfinity) {
  const StereoIntrinsics K = intrinsics600();
  const StereoExtrinsics rig = smallRig();
  const Eigen::Isometry3d T_lopt_ropt = rig.leftToRightOptical();
  const Eigen::Vector3d p(-2.0, 0.7, 25.0);
  Eigen::Vector4d z;
  ASSERT_TRUE(projectStereo(p, T_lopt_ropt.inverse(), K, 0.1, &z));
  const auto c = triangulateInverseDepth(z, T_lopt_ropt, K);
  ASSERT_TRUE(c.has_value());
  EXPECT_LT((*c - PointCoordinates(true).fromPosition(p)).norm(), 1e-9);
  // A far point whose right pixel noise reverses the disparity: no ray intersection, but a
  // (negative) inverse depth near zero.
  ASSERT_TRUE(projectStereo(Eigen::Vector3d(0.0, 0.0, 500.0), T_lopt_ropt.inverse(), K, 0.1, &z));
  z(2) += 1.0;  // 0.36 px of disparity the other way
  EXPECT_FALSE(triangulateStereo(z, T_lopt_ropt, K).has_value());
  const auto beyond = triangulateInverseDepth(z, T_lopt_ropt, K);
  ASSERT_TRUE(beyond.has_value());
  EXPECT_LT(beyond->z(), 0.0);
  EXPECT_GT(beyond->z(), -0.01);
}

TEST(PointCoordinates, NewFarPointUnderAWideRightCameraPriorMatchesMonteCarlo) {
  // 30 m ahead on a 0.3 m rig is 6 px of disparity; x_camr's rotation is 1 deg uncertain
  // (10 px): the depth is undetermined, its inverse is Gaussian. The filter's new point (a
  // UT through triangulation, Sec. II-A) must agree with sampling the same inputs, in the
  // mean, the covariance and the cross-covariance with x_camr.
  const StereoIntrinsics K = intrinsics600();
  const StereoExtrinsics rig = smallRig();
  FilterConfig config;
  config.initial_time_offset_sigma = 0.0;
  config.odometry_velocity_bias_sigma = 0.0;
  config.inverse_depth_points = 1;
  CalibrationFilter filter(config, K);
  Vector12d sigma;
  sigma << 0.1, 0.1, 0.1, 2 * kDeg, 2 * kDeg, 2 * kDeg, 0.02, 0.02, 0.02, 1 * kDeg, 1 * kDeg,
      1 * kDeg;
  const Matrix12d prior = sigma.array().square().matrix().asDiagonal();
  filter.reset(rig, prior);
  PointMeasurement m;
  m.id = 1;
  ASSERT_TRUE(projectStereo(Eigen::Vector3d(1.0, 0.5, 30.0), rig.leftToRightOptical().inverse(), K,
                            0.1, &m.z));
  m.variance.setConstant(0.25);
  ASSERT_TRUE(filter.addPoint(m));
  const Eigen::MatrixXd joint = filter.denseCovariance();  // [12, (a, b, rho)]
  const Eigen::Vector3d ut_mean =
      PointCoordinates(true).fromPosition(filter.points()[0].position_lopt);

  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  const Eigen::Matrix<double, 6, 6> L = prior.block<6, 6>(6, 6).llt().matrixL();
  const int samples = 100000;
  std::vector<std::pair<Vector6d, Eigen::Vector3d>> draws;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int s = 0; s < samples; ++s) {
    Vector6d w;
    for (int k = 0; k < 6; ++k) w(k) = n01(rng);
    const Vector6d dr = L * w;
    Eigen::Vector4d z = m.z;
    for (int k = 0; k < 4; ++k) z(k) += 0.5 * n01(rng);
    StereoExtrinsics e = rig;
    e.T_caml_camr = boxPlus(e.T_caml_camr, dr);
    const auto c = triangulateInverseDepth(z, e.leftToRightOptical(), K);
    ASSERT_TRUE(c.has_value());
    draws.emplace_back(dr, *c);
    mean += *c;
  }
  mean /= samples;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 6> cross = Eigen::Matrix<double, 3, 6>::Zero();
  for (const auto& d : draws) {
    cov += (d.second - mean) * (d.second - mean).transpose();
    cross += (d.second - mean) * d.first.transpose();
  }
  cov /= samples - 1;
  cross /= samples - 1;
  // The inverse depth really is undetermined: its sigma is above its mean.
  ASSERT_GT(std::sqrt(cov(2, 2)), mean.z());
  EXPECT_LT(std::abs(ut_mean.z() - mean.z()), 0.1 * std::sqrt(cov(2, 2)));
  EXPECT_LT((joint.block<3, 3>(12, 12) - cov).norm(), 0.1 * cov.norm());
  EXPECT_LT((joint.block<3, 6>(12, 6) - cross).norm(), 0.1 * cross.norm());
}

}  // namespace
}  // namespace osc
