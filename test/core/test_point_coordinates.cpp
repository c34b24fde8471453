// Inverse-depth points (FilterConfig::inverse_depth_points): the conversions, the models on
// homogeneous points and inverse-depth triangulation. (A new far point's uncertainty against
// Monte Carlo is in test_calibration_filter.cpp.)
#include <cmath>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/filter/measurement_model.h"
#include "online_stereo_calibration/core/filter/point_coordinates.h"
#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "test_intrinsics.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

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
  const StereoIntrinsics K = testIntrinsics();
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
  const StereoIntrinsics K = testIntrinsics();
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

}  // namespace
}  // namespace osc
