// Independent unit tests of pose.h: poses from and to [t, rpy] parameters, composition, the
// optical and body frames of interface.md, the extrinsics' parameters, boxplus/boxminus and the
// parameter Jacobian.
//
// Every expected value comes from a source other than the code under test: rotations written
// out by hand (geometry_test_support.h), the frame definitions of interface.md, closed forms
// derived in the comments, or finite differences. All random numbers are seeded.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "geometry_test_support.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Roll, pitch, yaw of R = Rz Ry Rx away from pitch = +-90 deg: R(2,0) = -sin(pitch),
/// R(2,1)/R(2,2) = tan(roll), R(1,0)/R(0,0) = tan(yaw).
Eigen::Vector3d handRpyFromRotation(const Eigen::Matrix3d& r) {
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), std::asin(-r(2, 0)),
                         std::atan2(r(1, 0), r(0, 0)));
}

Eigen::Isometry3d handPose(const Eigen::Vector3d& translation, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = handRpy(rpy);
  pose.translation() = translation;
  return pose;
}

Vector6d randomParameters(std::mt19937& rng, double max_pitch = 80 * kDeg) {
  Vector6d p;
  p << uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -M_PI, M_PI),
      uniform(rng, -max_pitch, max_pitch), uniform(rng, -M_PI, M_PI);
  return p;
}

Eigen::Isometry3d randomPose(std::mt19937& rng) {
  const Vector6d p = randomParameters(rng);
  return handPose(p.head<3>(), p.tail<3>());
}

TEST(Pose, PoseFromParametersMapsChildIntoParent) {
  // Child origin at (1, 2, 3), yawed by 90 deg: the child's x axis is the parent's y axis.
  Vector6d p;
  p << 1, 2, 3, 0, 0, 90 * kDeg;
  const Eigen::Isometry3d T = poseFromParameters(p);
  EXPECT_TRUE(matrixNear(T * Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3), 1e-15));
  EXPECT_TRUE(matrixNear(T * Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 3, 3), 1e-15));
  EXPECT_TRUE(matrixNear(T * Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 2, 3), 1e-15));

  std::mt19937 rng(10);
  for (int i = 0; i < 100; ++i) {
    const Vector6d q = randomParameters(rng, M_PI);
    const Eigen::Isometry3d pose = poseFromParameters(q);
    EXPECT_TRUE(matrixNear(pose.translation(), q.head<3>(), 0.0));
    EXPECT_TRUE(matrixNear(pose.linear(), handRpy(q.tail<3>()), 1e-14));
    EXPECT_TRUE(matrixNear(pose.matrix().row(3), Eigen::RowVector4d(0, 0, 0, 1), 0.0));
  }
}

TEST(Pose, ParametersFromPoseRoundTrips) {
  std::mt19937 rng(11);
  for (int i = 0; i < 500; ++i) {
    const Vector6d p = randomParameters(rng, 89 * kDeg);
    const Vector6d back = parametersFromPose(handPose(p.head<3>(), p.tail<3>()));
    EXPECT_TRUE(matrixNear(back.head<3>(), p.head<3>(), 1e-15));
    for (int k = 3; k < 6; ++k) EXPECT_NEAR(angleDifference(back(k), p(k)), 0.0, 1e-11);
    EXPECT_TRUE(matrixNear(poseFromParameters(back).matrix(),
                           handPose(p.head<3>(), p.tail<3>()).matrix(), 1e-12));
  }
}

TEST(Pose, CompositionAndInversionAreConsistent) {
  // T_a_c = T_a_b T_b_c: R_ac = R_ab R_bc, t_ac = R_ab t_bc + t_ab; T_b_a = (R^T, -R^T t).
  std::mt19937 rng(12);
  for (int i = 0; i < 50; ++i) {
    const Vector6d pab = randomParameters(rng), pbc = randomParameters(rng);
    const Eigen::Isometry3d T_a_b = poseFromParameters(pab), T_b_c = poseFromParameters(pbc);
    const Eigen::Isometry3d T_a_c = T_a_b * T_b_c;
    const Eigen::Matrix3d R_ab = handRpy(pab.tail<3>()), R_bc = handRpy(pbc.tail<3>());
    EXPECT_TRUE(matrixNear(T_a_c.linear(), R_ab * R_bc, 1e-13));
    EXPECT_TRUE(matrixNear(T_a_c.translation(), R_ab * pbc.head<3>() + pab.head<3>(), 1e-13));
    const Eigen::Vector3d p_c(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
    EXPECT_TRUE(matrixNear(T_a_c * p_c, T_a_b * (T_b_c * p_c), 1e-13));
    EXPECT_TRUE(matrixNear(T_a_b.inverse().linear(), R_ab.transpose(), 1e-14));
    EXPECT_TRUE(
        matrixNear(T_a_b.inverse().translation(), -R_ab.transpose() * pab.head<3>(), 1e-13));
    // Round trip through the parameters of the composed pose.
    EXPECT_TRUE(
        matrixNear(poseFromParameters(parametersFromPose(T_a_c)).matrix(), T_a_c.matrix(), 1e-11));
  }
}

TEST(Pose, RotationBodyOpticalMapsTheOpticalAxesToTheBodyAxes) {
  const Eigen::Matrix3d& R = rotationBodyOptical();
  // optical z (forward) -> body x (forward); optical x (right) -> body -y (y is left);
  // optical y (down) -> body -z (z is up).
  EXPECT_TRUE(matrixNear(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 0, 0), 0.0));
  EXPECT_TRUE(matrixNear(R * Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, -1, 0), 0.0));
  EXPECT_TRUE(matrixNear(R * Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 0, -1), 0.0));
  EXPECT_NEAR(R.determinant(), 1.0, 0.0);
  // The matrix of interface.md, written out.
  Eigen::Matrix3d documented;
  documented << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  EXPECT_TRUE(matrixNear(R, documented, 0.0));
  const Eigen::Isometry3d T = bodyFromOptical();
  EXPECT_TRUE(matrixNear(T.linear(), documented, 0.0));
  EXPECT_TRUE(matrixNear(T.translation(), Eigen::Vector3d::Zero(), 0.0));
}

TEST(Pose, FromOpticalFramesInvertsThePublishedTransforms) {
  Vector12d p;
  p << 1.2, -0.3, 0.7, 0.02, -0.05, 0.3, 0.01, -0.54, 0.004, 0.003, -0.01, 0.02;
  const StereoExtrinsics e = StereoExtrinsics::fromParameters(p);
  const StereoExtrinsics back =
      StereoExtrinsics::fromOpticalFrames(e.vehicleToLeftOptical(), e.leftToRightOptical());
  EXPECT_TRUE(matrixNear(back.toParameters(), p, 1e-12));
  // A left optical frame whose z (viewing direction) is the vehicle's x: the body frame is the
  // vehicle's own, so all six parameters are zero; a right one 0.5 m along optical +x: yr -0.5.
  Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
  T_lopt_ropt.translation() = Eigen::Vector3d(0.5, 0, 0);
  const Vector12d level =
      StereoExtrinsics::fromOpticalFrames(bodyFromOptical(), T_lopt_ropt).toParameters();
  Vector12d expected = Vector12d::Zero();
  expected(7) = -0.5;
  EXPECT_TRUE(matrixNear(level, expected, 1e-15));
}

TEST(Pose, HorizontalRigPutsTheRightCameraAtPlusXInTheLeftOpticalFrame) {
  for (double b : {0.05, 0.12, 0.5}) {
    Vector12d p = Vector12d::Zero();
    p(7) = -b;  // yr = -b: the right camera is to the right, i.e. at -y in the left body frame
    const Eigen::Isometry3d T = StereoExtrinsics::fromParameters(p).leftToRightOptical();
    EXPECT_TRUE(matrixNear(T.translation(), Eigen::Vector3d(b, 0, 0), 1e-15));
    EXPECT_TRUE(matrixNear(T.linear(), Eigen::Matrix3d::Identity(), 1e-15));
    // A point 10 m ahead on the left optical axis lies at x = -b in the right optical frame,
    // so its disparity u_l - u_r = f b / z is positive.
    EXPECT_TRUE(
        matrixNear(T.inverse() * Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(-b, 0, 10), 1e-15));
  }
}

TEST(Pose, RightCameraRotationsAppearAboutTheMatchingOpticalAxes) {
  // Body roll is about forward (= optical +z), body pitch about left (= optical -x), body yaw
  // about up (= optical -y). So R_lopt_ropt is a rotation about those optical axes.
  const double a = 0.03;
  const std::vector<std::pair<int, Eigen::Vector3d>> cases = {{9, Eigen::Vector3d(0, 0, 1)},
                                                              {10, Eigen::Vector3d(-1, 0, 0)},
                                                              {11, Eigen::Vector3d(0, -1, 0)}};
  for (const auto& c : cases) {
    Vector12d p = Vector12d::Zero();
    p(7) = -0.12;
    p(c.first) = a;
    const Eigen::Isometry3d T = StereoExtrinsics::fromParameters(p).leftToRightOptical();
    EXPECT_TRUE(matrixNear(T.linear(), Eigen::AngleAxisd(a, c.second).toRotationMatrix(), 1e-15))
        << "parameter " << c.first;
    EXPECT_TRUE(matrixNear(T.translation(), Eigen::Vector3d(0.12, 0, 0), 1e-15));
  }
}

TEST(Pose, LeftToRightOpticalConjugatesTheBodyTransform) {
  // T_lopt_ropt = T_lopt_lbody * T_lbody_rbody * T_rbody_ropt with T_body_opt = (R_bo, 0).
  Eigen::Matrix3d R_bo;
  R_bo << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  std::mt19937 rng(13);
  for (int i = 0; i < 50; ++i) {
    const Vector6d pr = randomParameters(rng);
    StereoExtrinsics e;
    e.T_caml_camr = handPose(pr.head<3>(), pr.tail<3>());
    const Eigen::Isometry3d T = e.leftToRightOptical();
    EXPECT_TRUE(matrixNear(T.linear(), R_bo.transpose() * handRpy(pr.tail<3>()) * R_bo, 1e-14));
    EXPECT_TRUE(matrixNear(T.translation(), R_bo.transpose() * pr.head<3>(), 1e-14));
  }
}

TEST(Pose, VehicleToLeftOpticalAppendsTheBodyToOpticalRotation) {
  Eigen::Matrix3d R_bo;
  R_bo << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  std::mt19937 rng(14);
  for (int i = 0; i < 50; ++i) {
    const Vector6d pl = randomParameters(rng);
    StereoExtrinsics e;
    e.T_veh_caml = handPose(pl.head<3>(), pl.tail<3>());
    const Eigen::Isometry3d T = e.vehicleToLeftOptical();
    EXPECT_TRUE(matrixNear(T.linear(), handRpy(pl.tail<3>()) * R_bo, 1e-14));
    EXPECT_TRUE(matrixNear(T.translation(), pl.head<3>(), 0.0));
  }
  // A left camera yawed by +90 deg looks along the vehicle's +y (left).
  Vector12d p = Vector12d::Zero();
  p << 1.5, 0.2, 1.3, 0, 0, 90 * kDeg, 0, -0.12, 0, 0, 0, 0;
  const Eigen::Isometry3d T = StereoExtrinsics::fromParameters(p).vehicleToLeftOptical();
  EXPECT_TRUE(matrixNear(T.linear() * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 1, 0), 1e-15));
  EXPECT_TRUE(matrixNear(T * Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1.5, 2.2, 1.3), 1e-15));
}

TEST(Pose, ExtrinsicsParametersRoundTrip) {
  std::mt19937 rng(15);
  for (int i = 0; i < 200; ++i) {
    Vector12d p;
    p << randomParameters(rng, 89 * kDeg), randomParameters(rng, 89 * kDeg);
    const StereoExtrinsics e = StereoExtrinsics::fromParameters(p);
    EXPECT_TRUE(matrixNear(e.T_veh_caml.matrix(),
                           handPose(p.segment<3>(0), p.segment<3>(3)).matrix(), 1e-14));
    EXPECT_TRUE(matrixNear(e.T_caml_camr.matrix(),
                           handPose(p.segment<3>(6), p.segment<3>(9)).matrix(), 1e-14));
    const Vector12d back = e.toParameters();
    for (int k = 0; k < 12; ++k) {
      EXPECT_NEAR(k % 6 < 3 ? back(k) - p(k) : angleDifference(back(k), p(k)), 0.0, 1e-11)
          << "i=" << i << " k=" << k;
    }
  }
}

TEST(Pose, BoxPlusPerturbsTranslationInParentAndRotationInChild) {
  const Eigen::Isometry3d T = handPose(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0.1, -0.2, 0.3));
  Vector6d delta;
  delta << 0.01, -0.02, 0.03, 0, 0, 0.05;
  const Eigen::Isometry3d P = boxPlus(T, delta);
  EXPECT_TRUE(matrixNear(P.translation(), Eigen::Vector3d(1.01, 1.98, 3.03), 1e-15));
  EXPECT_TRUE(matrixNear(P.linear(), T.linear() * handRz(0.05), 1e-15));
  delta << 0, 0, 0, 0.2, -0.1, 0.3;
  EXPECT_TRUE(matrixNear(boxPlus(T, delta).linear(),
                         T.linear() * handRodrigues(Eigen::Vector3d(0.2, -0.1, 0.3)), 1e-15));
}

TEST(Pose, BoxPlusAndBoxMinusRoundTrip) {
  std::mt19937 rng(16);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Isometry3d T = randomPose(rng), U = randomPose(rng);
    Vector6d delta;
    delta.head<3>() =
        Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    delta.tail<3>() = uniform(rng, 0, M_PI - 1e-3) * randomUnitVector(rng);
    EXPECT_TRUE(matrixNear(boxMinus(boxPlus(T, delta), T), delta, 1e-11)) << "i=" << i;
    EXPECT_TRUE(matrixNear(boxPlus(T, boxMinus(U, T)).matrix(), U.matrix(), 1e-12)) << "i=" << i;
    EXPECT_TRUE(matrixNear(boxMinus(T, T), Vector6d::Zero(), 1e-15));
  }
}

/// Independent finite-difference Jacobian of [t, rpy] w.r.t. [dt, dtheta] of one pose, with a
/// hand-written boxPlus, RPY extraction and angle wrapping, and a different step than the code.
Matrix6d referencePoseJacobian(const Eigen::Isometry3d& pose) {
  const double h = 1e-5;
  auto parameters = [&](const Vector6d& delta) {
    const Eigen::Matrix3d r = pose.linear() * handRodrigues(delta.tail<3>());
    Vector6d p;
    p << pose.translation() + delta.head<3>(), handRpyFromRotation(r);
    return p;
  };
  Matrix6d jacobian;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta(k) = h;
    Vector6d diff = parameters(delta) - parameters(-delta);
    for (int a = 3; a < 6; ++a) diff(a) = std::remainder(diff(a), 2 * M_PI);
    jacobian.col(k) = diff / (2 * h);
  }
  return jacobian;
}

TEST(Pose, ParameterJacobianMatchesIndependentFiniteDifferences) {
  std::mt19937 rng(17);
  for (int i = 0; i < 50; ++i) {
    Vector12d p;
    p << randomParameters(rng, 70 * kDeg), randomParameters(rng, 70 * kDeg);
    if (i == 0) p(5) = M_PI - 1e-7;   // yaw about to wrap: differences must be wrapped
    if (i == 1) p(9) = -M_PI + 1e-7;  // roll about to wrap
    const StereoExtrinsics e = StereoExtrinsics::fromParameters(p);
    Matrix12d expected = Matrix12d::Zero();
    expected.topLeftCorner<6, 6>() = referencePoseJacobian(e.T_veh_caml);
    expected.bottomRightCorner<6, 6>() = referencePoseJacobian(e.T_caml_camr);
    EXPECT_TRUE(matrixNear(parameterJacobian(e), expected, 1e-6)) << "i=" << i;
  }
}

/// d(rpy)/d(dtheta) for R(rpy) * Exp(dtheta): the body rate is w = E(roll, pitch) * rpy_dot with
/// columns e_x, Rx^T e_y, Rx^T Ry^T e_z (derived by hand from R = Rz Ry Rx), so the Jacobian is
/// E^-1.
Eigen::Matrix3d rpyRateJacobian(double roll, double pitch) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  Eigen::Matrix3d E;
  E << 1, 0, -sp, 0, cr, sr * cp, 0, -sr, cr * cp;
  return E.inverse();
}

TEST(Pose, ParameterJacobianFollowsTheRpyRateRelation) {
  std::mt19937 rng(18);
  for (int i = 0; i < 50; ++i) {
    // First half: pitch near 0 (where E^-1 is a rotation about x by roll); then general.
    const double max_pitch = i < 25 ? 1e-3 : 80 * kDeg;
    Vector12d p;
    p << randomParameters(rng, max_pitch), randomParameters(rng, max_pitch);
    const Matrix12d J = parameterJacobian(StereoExtrinsics::fromParameters(p));
    for (int block = 0; block < 2; ++block) {
      const int o = 6 * block;
      EXPECT_TRUE(matrixNear(J.block<3, 3>(o, o), Eigen::Matrix3d::Identity(), 1e-9));
      EXPECT_TRUE(matrixNear(J.block<3, 3>(o, o + 3), Eigen::Matrix3d::Zero(), 1e-9));
      EXPECT_TRUE(matrixNear(J.block<3, 3>(o + 3, o), Eigen::Matrix3d::Zero(), 1e-9));
      EXPECT_TRUE(
          matrixNear(J.block<3, 3>(o + 3, o + 3), rpyRateJacobian(p(o + 3), p(o + 4)), 1e-7))
          << "i=" << i << " block=" << block;
      if (i < 25) {
        // pitch ~ 0: d(roll)/d(theta_x) = 1 and the (pitch, yaw) rows are Rx(roll) in 2D.
        const double c = std::cos(p(o + 3)), s = std::sin(p(o + 3));
        Eigen::Matrix3d near_level;
        near_level << 1, 0, 0, 0, c, -s, 0, s, c;
        EXPECT_TRUE(matrixNear(J.block<3, 3>(o + 3, o + 3), near_level, 2e-3));
      }
    }
    EXPECT_TRUE(matrixNear(J.topRightCorner<6, 6>(), Matrix6d::Zero(), 0.0));
    EXPECT_TRUE(matrixNear(J.bottomLeftCorner<6, 6>(), Matrix6d::Zero(), 0.0));
  }
}

TEST(Pose, ParameterJacobianIsIdentityAtZero) {
  const Matrix12d J = parameterJacobian(StereoExtrinsics());
  EXPECT_TRUE(matrixNear(J, Matrix12d::Identity(), 1e-9));
}

}  // namespace
}  // namespace osc
