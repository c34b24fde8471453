// Independent unit tests of the geometry module (rotation.h, pose.h, camera_model.h,
// stereo_geometry.h).
//
// Every expected value comes from a source other than the code under test: rotation matrices
// and Rodrigues' formula written out by hand, the frame definitions of interface.md, OpenCV
// (projectPoints, fisheye::projectPoints, undistortPoints, findFundamentalMat), closed forms
// derived in the comments, or brute-force minimisation. All random numbers are seeded.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

// ---------------------------------------------------------------------------------------------
// Generic helpers
// ---------------------------------------------------------------------------------------------

::testing::AssertionResult matrixNear(const Eigen::MatrixXd& actual,
                                      const Eigen::MatrixXd& expected, double tolerance) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols()) {
    return ::testing::AssertionFailure() << "size mismatch";
  }
  const double error = (actual - expected).cwiseAbs().maxCoeff();
  if (error <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "max |difference| " << error << " > " << tolerance << "\nactual:\n"
         << actual << "\nexpected:\n"
         << expected;
}

double uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

Eigen::Vector3d randomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  return v.normalized();
}

/// Angle between two vectors, well conditioned for small and large angles.
double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Angle difference mapped to [-pi, pi] with the standard library, not wrapAngle.
double angleDifference(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

// ---------------------------------------------------------------------------------------------
// Hand-written rotations (right-handed, active: R * v rotates v)
// ---------------------------------------------------------------------------------------------

Eigen::Matrix3d handRx(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}

Eigen::Matrix3d handRy(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}

Eigen::Matrix3d handRz(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

/// tf2's setRPY: R = Rz(yaw) * Ry(pitch) * Rx(roll).
Eigen::Matrix3d handRpy(double roll, double pitch, double yaw) {
  return handRz(yaw) * handRy(pitch) * handRx(roll);
}

Eigen::Matrix3d handRpy(const Eigen::Vector3d& rpy) { return handRpy(rpy(0), rpy(1), rpy(2)); }

/// Rodrigues' formula R = I + sin(a) [k]x + (1 - cos(a)) [k]x^2, written out by hand.
Eigen::Matrix3d handRodrigues(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d k = rotation_vector / angle;
  Eigen::Matrix3d kx;
  kx << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(angle) * kx + (1.0 - std::cos(angle)) * kx * kx;
}

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

// =============================================================================================
// rotation.h
// =============================================================================================

TEST(Rotation, SkewIsTheCrossProduct) {
  std::mt19937 rng(1);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d v = 3.0 * randomUnitVector(rng), w = 2.0 * randomUnitVector(rng);
    EXPECT_TRUE(matrixNear(skew(v) * w, v.cross(w), 1e-15));
    EXPECT_TRUE(matrixNear(skew(v).transpose(), -skew(v), 0.0));
  }
}

TEST(Rotation, RotationFromRpyIsTheHandWrittenProductZYX) {
  std::mt19937 rng(2);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d rpy(uniform(rng, -4, 4), uniform(rng, -4, 4), uniform(rng, -4, 4));
    EXPECT_TRUE(matrixNear(rotationFromRpy(rpy), handRpy(rpy), 1e-14)) << rpy.transpose();
  }
}

TEST(Rotation, SingleAxisRpyFollowsTheRightHandRule) {
  // roll about x takes y to z, pitch about y takes z to x, yaw about z takes x to y.
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(matrixNear(rotationFromRpy(Eigen::Vector3d(90 * kDeg, 0, 0)) * y, z, 1e-15));
  EXPECT_TRUE(matrixNear(rotationFromRpy(Eigen::Vector3d(0, 90 * kDeg, 0)) * z, x, 1e-15));
  EXPECT_TRUE(matrixNear(rotationFromRpy(Eigen::Vector3d(0, 0, 90 * kDeg)) * x, y, 1e-15));
  // Order: yaw is applied last (outermost). roll 90 then yaw 90 takes y -> z -> z.
  EXPECT_TRUE(matrixNear(rotationFromRpy(Eigen::Vector3d(90 * kDeg, 0, 90 * kDeg)) * y, z, 1e-15));
  // and x -> x -> y.
  EXPECT_TRUE(matrixNear(rotationFromRpy(Eigen::Vector3d(90 * kDeg, 0, 90 * kDeg)) * x, y, 1e-15));
}

TEST(Rotation, RpyFromRotationRoundTripsAwayFromGimbalLock) {
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d rpy(uniform(rng, -M_PI, M_PI), uniform(rng, -89 * kDeg, 89 * kDeg),
                              uniform(rng, -M_PI, M_PI));
    const Eigen::Vector3d back = rpyFromRotation(handRpy(rpy));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(angleDifference(back(k), rpy(k)), 0.0, 1e-11) << "i=" << i << " k=" << k;
      EXPECT_LE(std::abs(back(k)), M_PI) << "i=" << i;
    }
    EXPECT_LE(std::abs(back(1)), M_PI / 2) << "i=" << i;
  }
}

TEST(Rotation, RpyFromRotationPicksThePitchInMinus90To90Branch) {
  // (roll, pitch, yaw) and (roll + pi, pi - pitch, yaw + pi) are the same rotation; tf2 returns
  // the one with |pitch| <= pi/2.
  const Eigen::Vector3d other_branch(0.3 + M_PI, M_PI - 0.4, -0.2 + M_PI);
  const Eigen::Vector3d back = rpyFromRotation(handRpy(other_branch));
  EXPECT_NEAR(back(0), 0.3, 1e-12);
  EXPECT_NEAR(back(1), 0.4, 1e-12);
  EXPECT_NEAR(back(2), -0.2, 1e-12);
}

TEST(Rotation, RpyAtGimbalLockStillReproducesTheRotation) {
  std::mt19937 rng(4);
  for (double pitch : {M_PI / 2, -M_PI / 2}) {
    for (int i = 0; i < 100; ++i) {
      const Eigen::Matrix3d r =
          handRpy(uniform(rng, -M_PI, M_PI), pitch, uniform(rng, -M_PI, M_PI));
      const Eigen::Vector3d back = rpyFromRotation(r);
      EXPECT_TRUE(back.allFinite());
      EXPECT_NEAR(back(1), pitch, 1e-12);
      EXPECT_NEAR(back(2), 0.0, 1e-12);  // documented: yaw = 0, roll absorbs it
      EXPECT_TRUE(matrixNear(handRpy(back), r, 1e-12)) << "pitch=" << pitch << " i=" << i;
    }
  }
}

TEST(Rotation, RpyNearGimbalLockReproducesTheRotation) {
  // Within a hair of +-90 deg the decomposition is ill-conditioned in roll/yaw individually, but
  // the rotation they encode must still be the input one. The tolerance allows the 1e-12 margin
  // the implementation uses to switch to the singular branch (sqrt(2e-12) = 1.4e-6 rad).
  std::mt19937 rng(5);
  for (double offset : {1e-2, 1e-4, 1e-5, 1e-6, 1e-7, 1e-9, 1e-12}) {
    for (double sign : {1.0, -1.0}) {
      for (int i = 0; i < 20; ++i) {
        const Eigen::Matrix3d r =
            handRpy(uniform(rng, -M_PI, M_PI), sign * (M_PI / 2 - offset), uniform(rng, -3, 3));
        const Eigen::Vector3d back = rpyFromRotation(r);
        const double error = Eigen::AngleAxisd(handRpy(back).transpose() * r).angle();
        EXPECT_LT(error, 1.5e-6) << "offset=" << offset << " sign=" << sign << " i=" << i;
      }
    }
  }
}

TEST(Rotation, ExpSO3IsRodriguesAndAgreesWithEigenAngleAxis) {
  std::mt19937 rng(6);
  std::vector<double> angles = {0.0, 1e-14, 1e-9, 1e-6, 1e-3, 0.5, 2.0, M_PI - 1e-6, M_PI};
  for (int i = 0; i < 50; ++i) angles.push_back(uniform(rng, 0, M_PI));
  for (double angle : angles) {
    const Eigen::Vector3d axis = randomUnitVector(rng), v = angle * axis;
    const Eigen::Matrix3d r = expSO3(v);
    EXPECT_TRUE(matrixNear(r, handRodrigues(v), 1e-14)) << "angle=" << angle;
    EXPECT_TRUE(matrixNear(r, Eigen::AngleAxisd(angle, axis).toRotationMatrix(), 1e-14));
    EXPECT_TRUE(matrixNear(r * r.transpose(), Eigen::Matrix3d::Identity(), 1e-14));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
    EXPECT_TRUE(matrixNear(r * axis, axis, 1e-14));  // the axis is fixed
  }
}

TEST(Rotation, LogSO3InvertsExpSO3IncludingNearZeroAndNearPi) {
  std::mt19937 rng(7);
  std::vector<double> angles = {0.0, 1e-15, 1e-12,       1e-9,        1e-6,       1e-3,
                                1.0, 3.0,   M_PI - 1e-3, M_PI - 1e-6, M_PI - 1e-8};
  for (int i = 0; i < 200; ++i) angles.push_back(uniform(rng, 0, M_PI));
  for (double angle : angles) {
    const Eigen::Vector3d v = angle * randomUnitVector(rng);
    const Eigen::Vector3d back = logSO3(handRodrigues(v));
    // Absolute accuracy ~1e-15 near 0; near pi the axis is determined by a small quaternion
    // w-component, still far better than 1e-9.
    EXPECT_TRUE(matrixNear(back, v, 1e-9)) << "angle=" << angle;
    if (angle < 1e-3) {
      EXPECT_TRUE(matrixNear(back, v, 1e-15)) << "angle=" << angle;
    }
  }
}

TEST(Rotation, LogSO3AtExactlyPiReturnsAnAngleOfPiWithTheRightAxis) {
  std::mt19937 rng(8);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d axis = randomUnitVector(rng);
    const Eigen::Matrix3d r = handRodrigues(M_PI * axis);
    const Eigen::Vector3d back = logSO3(r);
    EXPECT_NEAR(back.norm(), M_PI, 1e-9);
    EXPECT_NEAR(std::abs(back.normalized().dot(axis)), 1.0, 1e-12);  // +axis or -axis
    EXPECT_TRUE(matrixNear(handRodrigues(back), r, 1e-12));
  }
}

TEST(Rotation, LogSO3ReturnsTheShortRotationForAnglesAbovePi) {
  // exp of angle a > pi about k is the rotation by 2 pi - a about -k.
  const Eigen::Vector3d k = Eigen::Vector3d(1, -2, 0.5).normalized();
  const Eigen::Vector3d back = logSO3(handRodrigues(1.5 * M_PI * k));
  EXPECT_TRUE(matrixNear(back, -0.5 * M_PI * k, 1e-12));
  // and a hand-built rotation about z by 0.7 rad.
  EXPECT_TRUE(matrixNear(logSO3(handRz(0.7)), Eigen::Vector3d(0, 0, 0.7), 1e-15));
  EXPECT_TRUE(matrixNear(logSO3(handRx(-2.9)), Eigen::Vector3d(-2.9, 0, 0), 1e-14));
}

TEST(Rotation, RotationDistanceIsTheRelativeAngle) {
  EXPECT_NEAR(rotationDistance(handRz(0.3), handRz(-0.4)), 0.7, 1e-14);
  EXPECT_NEAR(rotationDistance(handRx(3.0), handRx(-3.0)), 2 * M_PI - 6.0, 1e-12);
  EXPECT_NEAR(rotationDistance(handRy(0.2), handRy(0.2)), 0.0, 1e-15);
  // Invariance: d(A, B) = d(C A, C B).
  const Eigen::Matrix3d a = handRpy(0.1, 0.2, 0.3), b = handRpy(-0.5, 0.4, 1.3),
                        c = handRpy(2.0, -1.0, 0.5);
  EXPECT_NEAR(rotationDistance(a, b), rotationDistance(c * a, c * b), 1e-13);
  EXPECT_NEAR(rotationDistance(a, b), Eigen::AngleAxisd(a.transpose() * b).angle(), 1e-13);
}

TEST(Rotation, WrapAngleKeepsASmallAngleExactly) {
  // An error of a converged angle is tiny; wrapping must not round it (fmod(a + pi, 2 pi) -
  // pi kept only the bits of a that survive next to pi).
  for (double a : {1e-9, -1e-9, 3.3e-7, -2.7e-5, 1e-300}) EXPECT_EQ(wrapAngle(a), a) << a;
  EXPECT_EQ(wrapAngle(2 * M_PI + 1e-3), (2 * M_PI + 1e-3) - 2 * M_PI);
}

TEST(Rotation, WrapAngleKnownValues) {
  EXPECT_DOUBLE_EQ(wrapAngle(0.0), 0.0);
  EXPECT_NEAR(wrapAngle(0.1), 0.1, 1e-15);
  EXPECT_NEAR(wrapAngle(-0.1), -0.1, 1e-15);
  EXPECT_NEAR(wrapAngle(M_PI), M_PI, 1e-15);   // (-pi, pi]: +pi stays
  EXPECT_NEAR(wrapAngle(-M_PI), M_PI, 1e-15);  // and -pi maps to +pi
  EXPECT_NEAR(wrapAngle(3 * M_PI), M_PI, 1e-14);
  EXPECT_NEAR(wrapAngle(-3 * M_PI), M_PI, 1e-14);
  EXPECT_NEAR(wrapAngle(2 * M_PI + 0.1), 0.1, 1e-14);
  EXPECT_NEAR(wrapAngle(-1.5 * M_PI), 0.5 * M_PI, 1e-14);
  EXPECT_NEAR(wrapAngle(1.5 * M_PI), -0.5 * M_PI, 1e-14);
  EXPECT_NEAR(wrapAngle(M_PI + 1e-9), -M_PI + 1e-9, 1e-14);
  EXPECT_NEAR(wrapAngle(-M_PI + 1e-9), -M_PI + 1e-9, 1e-14);
}

TEST(Rotation, WrapAngleIsInRangeAndDiffersByWholeTurns) {
  std::mt19937 rng(9);
  for (int i = 0; i < 1000; ++i) {
    const double angle = uniform(rng, -100, 100);
    const double wrapped = wrapAngle(angle);
    EXPECT_GT(wrapped, -M_PI) << angle;
    EXPECT_LE(wrapped, M_PI) << angle;
    const double turns = (angle - wrapped) / (2 * M_PI);
    EXPECT_NEAR(turns, std::round(turns), 1e-12) << angle;
  }
}

// =============================================================================================
// pose.h
// =============================================================================================

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
  const Vector12d level = StereoExtrinsics::fromOpticalFrames(bodyFromOptical(), T_lopt_ropt)
                              .toParameters();
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

// =============================================================================================
// camera_model.h
// =============================================================================================

/// EuRoC MAV cam0 (radial-tangential, strong barrel distortion).
CameraIntrinsics eurocCam0() {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = 458.654;
  in.fy = 457.296;
  in.cx = 367.215;
  in.cy = 248.375;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return in;
}

/// plumb_bob with the optional fifth coefficient k3 (positive: r_d(r) stays monotonic, so every
/// pixel has an undistorted preimage).
CameraIntrinsics plumbBobWithK3() {
  CameraIntrinsics in = eurocCam0();
  in.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0121};
  return in;
}

/// A wide lens with the 8-coefficient rational model (values like an OpenCV calibration).
CameraIntrinsics rationalCamera() {
  CameraIntrinsics in;
  in.width = 1280;
  in.height = 720;
  in.fx = 700.2;
  in.fy = 701.9;
  in.cx = 641.3;
  in.cy = 358.9;
  in.model = DistortionModel::kRationalPolynomial;
  in.distortion = {0.82, -0.051, 0.0006, -0.0004, 0.013, 1.13, 0.11, 0.021};
  return in;
}

/// A fisheye (equidistant / Kannala-Brandt).
CameraIntrinsics fisheyeCamera() {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = 380.0;
  in.fy = 380.0;
  in.cx = 376.5;
  in.cy = 239.5;
  in.model = DistortionModel::kEquidistant;
  in.distortion = {-0.01, 0.002, -0.001, 0.0002};
  return in;
}

cv::Mat cvK(const CameraIntrinsics& in) {
  return (cv::Mat_<double>(3, 3) << in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
}

cv::Mat cvD(const CameraIntrinsics& in) { return cv::Mat(in.distortion, true).reshape(1, 1); }

/// OpenCV's projection of optical-frame points (identity pose).
std::vector<Eigen::Vector2d> openCvProject(const CameraIntrinsics& in,
                                           const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3d> object;
  for (const auto& p : points) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  const cv::Mat rvec = cv::Mat::zeros(3, 1, CV_64F), tvec = cv::Mat::zeros(3, 1, CV_64F);
  if (in.model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(object, image, rvec, tvec, cvK(in), cvD(in));
  } else {
    cv::projectPoints(object, rvec, tvec, cvK(in), cvD(in), image);
  }
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : image) out.emplace_back(q.x, q.y);
  return out;
}

/// OpenCV's undistortion to undistorted pixels (P = K), iterated to convergence.
std::vector<Eigen::Vector2d> openCvUndistortPixels(const CameraIntrinsics& in,
                                                   const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<cv::Point2d> src, dst;
  for (const auto& p : pixels) src.emplace_back(p.x(), p.y());
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 500, 1e-12);
  if (in.model == DistortionModel::kEquidistant) {
    cv::fisheye::undistortPoints(src, dst, cvK(in), cvD(in), cv::Mat::eye(3, 3, CV_64F), cvK(in),
                                 criteria);
  } else {
    cv::undistortPoints(src, dst, cvK(in), cvD(in), cv::noArray(), cvK(in), criteria);
  }
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : dst) out.emplace_back(q.x, q.y);
  return out;
}

/// Points in front of the camera on a grid of viewing directions (normalized coordinates within
/// +-max_x, +-max_y) and several depths.
std::vector<Eigen::Vector3d> pointGrid(double max_x, double max_y) {
  std::vector<Eigen::Vector3d> points;
  for (double z : {0.3, 2.0, 17.0}) {
    for (int i = -10; i <= 10; ++i) {
      for (int j = -10; j <= 10; ++j) {
        points.emplace_back(max_x * i / 10.0 * z, max_y * j / 10.0 * z, z);
      }
    }
  }
  return points;
}

/// Every step-th pixel of the image, including the last row and column.
std::vector<Eigen::Vector2d> pixelGrid(const CameraIntrinsics& in, int step) {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> us, vs;
  for (int u = 0; u < in.width; u += step) us.push_back(u);
  for (int v = 0; v < in.height; v += step) vs.push_back(v);
  us.push_back(in.width - 1);
  vs.push_back(in.height - 1);
  for (double u : us) {
    for (double v : vs) pixels.emplace_back(u + 0.25, v + 0.25);
  }
  for (double u : us) pixels.emplace_back(u, in.height - 1);  // exact border pixels
  for (double v : vs) pixels.emplace_back(0.0, v);
  return pixels;
}

void expectProjectionMatchesOpenCv(const CameraIntrinsics& in, double max_x, double max_y) {
  const CameraModel camera(in);
  const auto points = pointGrid(max_x, max_y);
  const auto expected = openCvProject(in, points);
  ASSERT_EQ(expected.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.project(points[i], &pixel));
    EXPECT_NEAR(pixel.x(), expected[i].x(), 1e-6) << points[i].transpose();
    EXPECT_NEAR(pixel.y(), expected[i].y(), 1e-6) << points[i].transpose();
  }
}

void expectPixelRoundTrip(const CameraIntrinsics& in) {
  const CameraModel camera(in);
  for (const Eigen::Vector2d& pixel : pixelGrid(in, 4)) {
    const Eigen::Vector2d normalized = camera.pixelToNormalized(pixel);
    ASSERT_TRUE(normalized.allFinite()) << pixel.transpose();
    EXPECT_TRUE(matrixNear(camera.normalizedToPixel(normalized), pixel, 1e-6))
        << "pixel " << pixel.transpose();
    // The same through project() of a 3D point on the ray.
    Eigen::Vector2d projected;
    ASSERT_TRUE(camera.project(4.2 * normalized.homogeneous(), &projected));
    EXPECT_TRUE(matrixNear(projected, pixel, 1e-6)) << "pixel " << pixel.transpose();
    // undistortPixel is K * normalized.
    EXPECT_TRUE(matrixNear(
        camera.undistortPixel(pixel),
        Eigen::Vector2d(in.fx * normalized.x() + in.cx, in.fy * normalized.y() + in.cy), 1e-9));
  }
}

void expectUndistortPixelMatchesOpenCv(const CameraIntrinsics& in) {
  const CameraModel camera(in);
  const auto pixels = pixelGrid(in, 16);
  const auto expected = openCvUndistortPixels(in, pixels);
  ASSERT_EQ(expected.size(), pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    EXPECT_TRUE(matrixNear(camera.undistortPixel(pixels[i]), expected[i], 1e-3))
        << "pixel " << pixels[i].transpose();
  }
}

TEST(CameraModel, PlumbBobProjectionMatchesOpenCv) {
  expectProjectionMatchesOpenCv(eurocCam0(), 1.1, 0.75);       // 4 coefficients
  expectProjectionMatchesOpenCv(plumbBobWithK3(), 1.1, 0.75);  // 5 coefficients
}

TEST(CameraModel, RationalPolynomialProjectionMatchesOpenCv) {
  expectProjectionMatchesOpenCv(rationalCamera(), 1.2, 0.7);
}

TEST(CameraModel, EquidistantProjectionMatchesOpenCvFisheye) {
  expectProjectionMatchesOpenCv(fisheyeCamera(), 2.5, 1.5);
}

TEST(CameraModel, ProjectRejectsPointsNotInFront) {
  const CameraModel camera(eurocCam0());
  const Eigen::Vector2d sentinel(-7, -7);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(1, 1, -3), Eigen::Vector3d(0, 0, 1e-9)}) {
    Eigen::Vector2d pixel = sentinel;
    EXPECT_FALSE(camera.project(p, &pixel)) << p.transpose();
    EXPECT_EQ(pixel, sentinel);
  }
}

TEST(CameraModel, PlumbBobPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(eurocCam0());
  expectPixelRoundTrip(plumbBobWithK3());
}

TEST(CameraModel, RationalPolynomialPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(rationalCamera());
}

TEST(CameraModel, EquidistantPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(fisheyeCamera());
}

TEST(CameraModel, UndistortPixelMatchesOpenCvUndistortPoints) {
  expectUndistortPixelMatchesOpenCv(eurocCam0());
  expectUndistortPixelMatchesOpenCv(plumbBobWithK3());
  expectUndistortPixelMatchesOpenCv(rationalCamera());
  expectUndistortPixelMatchesOpenCv(fisheyeCamera());
}

TEST(CameraModel, DistortAndUndistortAreInverseOnNormalizedCoordinates) {
  // The fisheye corner reaches theta ~ 68 deg; sample the normalized plane inside that.
  for (const CameraIntrinsics& in : {eurocCam0(), rationalCamera(), fisheyeCamera()}) {
    const CameraModel camera(in);
    for (int i = -10; i <= 10; ++i) {
      for (int j = -10; j <= 10; ++j) {
        const Eigen::Vector2d n(1.0 * i / 10.0, 0.6 * j / 10.0);
        EXPECT_TRUE(matrixNear(camera.undistort(camera.distort(n)), n, 1e-10))
            << distortionModelName(in.model) << " " << n.transpose();
      }
    }
    EXPECT_TRUE(matrixNear(camera.distort(Eigen::Vector2d::Zero()), Eigen::Vector2d::Zero(), 0.0));
  }
}

// A strong barrel polynomial (plumb_bob k1 = -0.28 alone) turns back at r = 1 / sqrt(3 * 0.28)
// = 1.09, where the distorted radius peaks at 0.727: pixels beyond that radius have no ray,
// and inside it the ray must be the one on the optical axis' side of the fold.
TEST(CameraModel, UndistortStaysOnTheUnfoldedBranchAndRejectsUnreachablePixels) {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = in.fy = 460.0;
  in.cx = 376.0;
  in.cy = 240.0;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28, 0.0, 0.0, 0.0, 0.0};
  const CameraModel camera(in);
  const double fold_radius = 1.0 / std::sqrt(3.0 * 0.28);
  const double peak = fold_radius * (1.0 - 0.28 * fold_radius * fold_radius);
  const Eigen::Vector2d direction = Eigen::Vector2d(376.0, 240.0).normalized();
  for (double rd : {0.2, 0.5, 0.7, 0.99 * peak}) {
    Eigen::Vector2d n;
    ASSERT_TRUE(camera.undistort(rd * direction, &n)) << rd;
    EXPECT_LT(n.norm(), fold_radius) << rd;  // the axis-side branch, not the folded one
    EXPECT_TRUE(matrixNear(camera.distort(n), rd * direction, 1e-9)) << rd;
  }
  // The image corner (distorted radius 0.97) is beyond the peak: no ray, nothing written.
  Eigen::Vector2d untouched(7.0, 7.0);
  EXPECT_FALSE(camera.pixelToNormalized(Eigen::Vector2d(0.0, 0.0), &untouched));
  EXPECT_EQ(untouched, Eigen::Vector2d(7.0, 7.0));
  EXPECT_FALSE(camera.undistort(1.01 * peak * direction, &untouched));
  // The best-effort form returns its input there instead of a folded ray.
  EXPECT_EQ(camera.undistort(1.01 * peak * direction), 1.01 * peak * direction);
  // Non-finite input is rejected, not iterated.
  EXPECT_FALSE(camera.undistort(Eigen::Vector2d(std::nan(""), 0.0), &untouched));
  // Equidistant: a distorted angle past 90 deg has no ray in front of the camera.
  CameraIntrinsics fisheye = in;
  fisheye.model = DistortionModel::kEquidistant;
  fisheye.distortion = {0.001, 0.0, 0.0, 0.0};  // (all zero would be a plain pinhole)
  const CameraModel equidistant(fisheye);
  EXPECT_TRUE(equidistant.undistort(Eigen::Vector2d(1.2, 0.0), &untouched));
  EXPECT_GT(untouched.x(), std::tan(1.19));
  EXPECT_TRUE(matrixNear(equidistant.distort(untouched), Eigen::Vector2d(1.2, 0.0), 1e-9));
  EXPECT_FALSE(equidistant.undistort(Eigen::Vector2d(1.7, 0.0), &untouched));
}

TEST(CameraModel, UndistortedPixelNoiseIsTheRawNoiseStretchedByTheLens) {
  // Without distortion an undistorted pixel is the raw one: the same variance, exactly.
  CameraIntrinsics pinhole = fisheyeCamera();
  pinhole.model = DistortionModel::kNone;
  pinhole.distortion.clear();
  EXPECT_EQ(CameraModel(pinhole).undistortedPixelVariance(Eigen::Vector2d(700.0, 20.0), 0.5), 0.25);
  // A fisheye 50 deg off its axis: r_u = f tan(theta) against r_d ~ f theta, so a raw pixel's
  // noise is stretched by 1 / cos^2(theta) = 2.4 radially (tan(theta) / theta = 1.4
  // tangentially); the variance takes the larger stretch.
  const CameraModel fisheye(fisheyeCamera());
  const double theta = 50.0 * M_PI / 180.0;
  const Eigen::Vector2d undistorted(376.5 + 380.0 * std::tan(theta), 239.5);
  const double radial = (1.0 / std::pow(std::cos(theta), 2)) * 0.5;
  EXPECT_NEAR(fisheye.undistortedPixelVariance(undistorted, 0.5), radial * radial,
              0.1 * radial * radial);  // the lens's small k1..k4 change it by a few percent
  // At the centre the lens barely stretches.
  EXPECT_NEAR(fisheye.undistortedPixelVariance(Eigen::Vector2d(376.5, 239.5), 0.5), 0.25, 0.01);
}

TEST(CameraModel, EquidistantDistortionIsTheKannalaBrandtPolynomial) {
  // theta = atan(r), theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),
  // distorted = normalized * theta_d / r.
  const CameraIntrinsics in = fisheyeCamera();
  const CameraModel camera(in);
  const Eigen::Vector2d n(0.7, -0.4);
  const double r = n.norm(), t = std::atan(r);
  const double theta_d = t + in.distortion[0] * std::pow(t, 3) + in.distortion[1] * std::pow(t, 5) +
                         in.distortion[2] * std::pow(t, 7) + in.distortion[3] * std::pow(t, 9);
  EXPECT_TRUE(matrixNear(camera.distort(n), n * theta_d / r, 1e-15));
}

TEST(CameraModel, LensJacobianIsTheEquidistantLensStretch) {
  // A pure equidistant lens (r_raw = f theta, r_pinhole = f tan theta): offsets along the
  // radius shrink by d theta / d tan theta = cos^2 theta, across it by theta / tan theta.
  CameraIntrinsics in = fisheyeCamera();
  in.distortion = {1e-12, 0.0, 0.0, 0.0};  // all zero would be a plain pinhole
  const CameraModel camera(in);
  const double n = 0.5, theta = std::atan(n);
  const double radial = 1.0 / (1.0 + n * n), across = theta / n;
  const Eigen::Matrix2d on_x = camera.lensJacobian(Eigen::Vector2d(in.cx + in.fx * n, in.cy));
  const Eigen::Matrix2d on_y = camera.lensJacobian(Eigen::Vector2d(in.cx, in.cy - in.fy * n));
  EXPECT_TRUE(matrixNear(on_x, Eigen::Vector2d(radial, across).asDiagonal().toDenseMatrix(), 1e-4))
      << on_x;
  EXPECT_TRUE(matrixNear(on_y, Eigen::Vector2d(across, radial).asDiagonal().toDenseMatrix(), 1e-4))
      << on_y;
  // Any lens: the Jacobian predicts where a small offset lands in the raw image.
  const CameraModel euroc(eurocCam0());
  const Eigen::Vector2d u(600.0, 50.0), du(0.3, -0.2);
  const auto toRaw = [&](const Eigen::Vector2d& x) {
    const CameraIntrinsics& k = euroc.intrinsics();
    return euroc.normalizedToPixel(Eigen::Vector2d((x.x() - k.cx) / k.fx, (x.y() - k.cy) / k.fy));
  };
  EXPECT_TRUE(matrixNear(toRaw(u + du) - toRaw(u), euroc.lensJacobian(u) * du, 1e-3));
  // Without distortion it is exactly the identity.
  CameraIntrinsics none = in;
  none.distortion = {0.0, 0.0, 0.0, 0.0};
  EXPECT_TRUE(matrixNear(CameraModel(none).lensJacobian(u), Eigen::Matrix2d::Identity(), 0.0));
}

std::string constructionError(const CameraIntrinsics& in) {
  try {
    CameraModel camera(in);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

void expectRejectedNaming(const CameraIntrinsics& in, const std::string& field) {
  EXPECT_THROW(CameraModel{in}, std::invalid_argument) << field;
  const std::string message = constructionError(in);
  EXPECT_NE(message.find(field), std::string::npos)
      << "message '" << message << "' lacks '" << field << "'";
}

TEST(CameraModel, InvalidIntrinsicsThrowNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto with = [](const std::function<void(CameraIntrinsics&)>& change) {
    CameraIntrinsics in = eurocCam0();
    change(in);
    return in;
  };
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fx = 0.0; }), "fx");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fx = -458.0; }), "fx");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.fx = inf; }), "fx");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fy = -1.0; }), "fy");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.fy = nan; }), "fy");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.cx = nan; }), "cx");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.cy = inf; }), "cy");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.width = 0; }), "size");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.height = -480; }), "size");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.distortion[1] = nan; }), "(D)");
  // Wrong number of coefficients for the model.
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.distortion = {-0.28, 0.07, 0.0};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.distortion.resize(8, 0.01); }), "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.distortion.clear(); }), "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kEquidistant;
                         in.distortion = {-0.01, 0.002, -0.001, 0.0002, 0.0001};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kEquidistant;
                         in.distortion = {-0.01, 0.002, -0.001};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kRationalPolynomial;
                         in.distortion = std::vector<double>(9, 0.01);
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kRationalPolynomial;
                         in.distortion = {0.1, 0.01};
                       }),
                       "(D)");
  // The valid base case does not throw.
  EXPECT_NO_THROW(CameraModel{eurocCam0()});
}

TEST(CameraModel, DistortionModelNamesParseAndRejectUnknownNames) {
  EXPECT_EQ(distortionModelFromName("plumb_bob"), DistortionModel::kPlumbBob);
  EXPECT_EQ(distortionModelFromName("rational_polynomial"), DistortionModel::kRationalPolynomial);
  EXPECT_EQ(distortionModelFromName("equidistant"), DistortionModel::kEquidistant);
  EXPECT_EQ(distortionModelFromName(""), DistortionModel::kNone);
  EXPECT_EQ(distortionModelFromName("none"), DistortionModel::kNone);
  for (DistortionModel m : {DistortionModel::kNone, DistortionModel::kPlumbBob,
                            DistortionModel::kRationalPolynomial, DistortionModel::kEquidistant}) {
    EXPECT_EQ(distortionModelFromName(distortionModelName(m)), m);
  }
  for (const std::string bad : {"fisheye", "Plumb_Bob", "radtan", "kannala_brandt", "plumb_bob "}) {
    try {
      distortionModelFromName(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(CameraModel, AllZeroDistortionIsAPlainPinhole) {
  // image_geometry's convention: all-zero D means no distortion, whatever the model name.
  for (const CameraIntrinsics& base : {eurocCam0(), rationalCamera(), fisheyeCamera()}) {
    CameraIntrinsics in = base;
    std::fill(in.distortion.begin(), in.distortion.end(), 0.0);
    const CameraModel camera(in);
    const Eigen::Vector3d p(1.3, -0.8, 2.1);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.project(p, &pixel));
    const Eigen::Vector2d pinhole(in.fx * p.x() / p.z() + in.cx, in.fy * p.y() / p.z() + in.cy);
    EXPECT_TRUE(matrixNear(pixel, pinhole, 1e-12)) << distortionModelName(base.model);
    EXPECT_TRUE(matrixNear(camera.pixelToNormalized(pinhole),
                           Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()), 1e-14));
    EXPECT_TRUE(matrixNear(camera.undistortPixel(Eigen::Vector2d(10.5, 400.25)),
                           Eigen::Vector2d(10.5, 400.25), 1e-12));
  }
  // model "none" likewise, and K() is the documented matrix.
  CameraIntrinsics none = eurocCam0();
  none.model = DistortionModel::kNone;
  none.distortion.clear();
  const CameraModel camera(none);
  Eigen::Matrix3d K;
  K << none.fx, 0, none.cx, 0, none.fy, none.cy, 0, 0, 1;
  EXPECT_TRUE(matrixNear(camera.K(), K, 0.0));
  EXPECT_TRUE(
      matrixNear(camera.distort(Eigen::Vector2d(0.4, -0.3)), Eigen::Vector2d(0.4, -0.3), 0.0));
}

TEST(CameraModel, IsInImageHonoursTheBordersAndTheMargin) {
  const CameraModel camera(eurocCam0());  // 752 x 480
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(751, 479)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(376, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(-0.01, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, -0.01)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(752, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 480)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(-1e6, 1e6)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(std::nan(""), 240)));
  // With a 10 px margin.
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(10, 10), 10));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(741, 469), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(9.9, 240), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 9.9), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(741.1, 240), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 469.1), 10));
}

// =============================================================================================
// stereo_geometry.h
// =============================================================================================

Eigen::Matrix3d intrinsicMatrix(double fx, double fy, double cx, double cy) {
  Eigen::Matrix3d K;
  K << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return K;
}

/// A stereo pair with different intrinsics, a small random relative rotation and a baseline of
/// about 12 cm with the right camera at +x of the left one.
struct StereoRig {
  Eigen::Matrix3d K_left = intrinsicMatrix(458.0, 457.0, 367.0, 248.0);
  Eigen::Matrix3d K_right = intrinsicMatrix(462.0, 460.5, 379.0, 255.0);
  Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
};

StereoRig randomRig(std::mt19937& rng) {
  StereoRig rig;
  rig.T_lopt_ropt.linear() =
      Eigen::AngleAxisd(uniform(rng, 0, 3 * kDeg), randomUnitVector(rng)).toRotationMatrix();
  rig.T_lopt_ropt.translation() = Eigen::Vector3d(
      uniform(rng, 0.1, 0.15), uniform(rng, -0.01, 0.01), uniform(rng, -0.01, 0.01));
  return rig;
}

Eigen::Vector2d pinholePixel(const Eigen::Matrix3d& K, const Eigen::Vector3d& p) {
  return (K * p).hnormalized();
}

Eigen::Vector3d randomPointInFront(std::mt19937& rng) {
  return Eigen::Vector3d(uniform(rng, -4, 4), uniform(rng, -2.5, 2.5), uniform(rng, 2, 30));
}

struct Correspondence {
  Eigen::Vector3d point_left;
  Eigen::Vector2d left, right;
};

Correspondence observe(const StereoRig& rig, const Eigen::Vector3d& point_left) {
  const Eigen::Vector3d point_right = rig.T_lopt_ropt.inverse() * point_left;
  return {point_left, pinholePixel(rig.K_left, point_left), pinholePixel(rig.K_right, point_right)};
}

/// The epipolar line of a left pixel, built independently of F: the right-image line through
/// the projections of two points on the left pixel's ray. Returns a unit normal n and a point.
std::pair<Eigen::Vector2d, Eigen::Vector2d> independentEpipolarLine(const StereoRig& rig,
                                                                    const Eigen::Vector2d& left) {
  const Eigen::Vector3d ray = rig.K_left.inverse() * left.homogeneous();
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  const Eigen::Vector2d a = pinholePixel(rig.K_right, T_ropt_lopt * (1.0 * ray));
  const Eigen::Vector2d b = pinholePixel(rig.K_right, T_ropt_lopt * (50.0 * ray));
  const Eigen::Vector2d direction = (b - a).normalized();
  return {Eigen::Vector2d(-direction.y(), direction.x()), a};
}

/// The gold-standard (reprojection) error of a correspondence: min over 3D points X of
/// sqrt(|pi_l(X) - left|^2 + |pi_r(X) - right|^2), by Gauss-Newton from a start point.
double goldStandardError(const StereoRig& rig, const Eigen::Vector2d& left,
                         const Eigen::Vector2d& right, Eigen::Vector3d X) {
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  auto residual = [&](const Eigen::Vector3d& x) {
    Eigen::Vector4d r;
    r << pinholePixel(rig.K_left, x) - left, pinholePixel(rig.K_right, T_ropt_lopt * x) - right;
    return r;
  };
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Matrix<double, 4, 3> J;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d h = Eigen::Vector3d::Zero();
      h(k) = 1e-6 * std::max(1.0, X.norm());
      J.col(k) = (residual(X + h) - residual(X - h)) / (2 * h(k));
    }
    X -= (J.transpose() * J).ldlt().solve(J.transpose() * residual(X));
  }
  return residual(X).norm();
}

TEST(StereoGeometry, EssentialMatrixOfAHorizontalRig) {
  // Right camera at (b, 0, 0), no rotation: T_ropt_lopt = (I, (-b, 0, 0)) and
  // E = [(-b,0,0)]x = [[0,0,0],[0,0,b],[0,-b,0]], so x_r^T E x_l = b (y_r - y_l).
  const double b = 0.12;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(b, 0, 0);
  Eigen::Matrix3d expected;
  expected << 0, 0, 0, 0, 0, b, 0, -b, 0;
  EXPECT_TRUE(matrixNear(essentialMatrix(T), expected, 1e-15));
}

TEST(StereoGeometry, FundamentalMatrixSatisfiesTheEpipolarConstraint) {
  std::mt19937 rng(20);
  for (int r = 0; r < 20; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    const Eigen::Matrix3d E = essentialMatrix(rig.T_lopt_ropt);
    const Eigen::Vector3d singular_values = Eigen::JacobiSVD<Eigen::Matrix3d>(F).singularValues();
    EXPECT_LT(singular_values(2), 1e-12 * singular_values(0));  // rank 2
    for (int i = 0; i < 50; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector3d xl = c.left.homogeneous(), xr = c.right.homogeneous();
      EXPECT_LT(std::abs(xr.dot(F * xl)) / (F.norm() * xl.norm() * xr.norm()), 1e-9);
      // In pixels: the distance of the right pixel from the line F x_l.
      EXPECT_LT(std::abs(xr.dot(F * xl)) / (F * xl).head<2>().norm(), 1e-9);
      // The same for normalized rays under E.
      const Eigen::Vector3d nl = c.point_left / c.point_left.z();
      const Eigen::Vector3d pr = rig.T_lopt_ropt.inverse() * c.point_left;
      EXPECT_LT(std::abs((pr / pr.z()).dot(E * nl)), 1e-12);
      // A wrong correspondence 5 px off the (independently computed) line is 5 px off under F.
      const auto line = independentEpipolarLine(rig, c.left);
      const Eigen::Vector3d off = (c.right + 5.0 * line.first).homogeneous();
      EXPECT_NEAR(std::abs(off.dot(F * xl)) / (F * xl).head<2>().norm(), 5.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, FundamentalMatrixMatchesOpenCvEightPoint) {
  std::mt19937 rng(21);
  for (int r = 0; r < 5; ++r) {
    const StereoRig rig = randomRig(rng);
    std::vector<cv::Point2d> left, right;
    for (int i = 0; i < 60; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      left.emplace_back(c.left.x(), c.left.y());
      right.emplace_back(c.right.x(), c.right.y());
    }
    const cv::Mat F_cv = cv::findFundamentalMat(left, right, cv::FM_8POINT);
    ASSERT_EQ(F_cv.rows, 3);
    Eigen::Matrix3d expected;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) expected(i, j) = F_cv.at<double>(i, j);
    }
    Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    // Equal up to scale and sign. OpenCV's 8-point solves the normal equations (squared
    // condition number), so even on exact data it is only good to ~1e-6 relative.
    F /= F.norm();
    expected /= expected.norm();
    if ((F - expected).norm() > (F + expected).norm()) expected = -expected;
    EXPECT_TRUE(matrixNear(F, expected, 1e-5)) << "rig " << r;
    // Both agree on the correspondences to a small fraction of a pixel.
    for (size_t i = 0; i < left.size(); ++i) {
      const Eigen::Vector3d xl(left[i].x, left[i].y, 1), xr(right[i].x, right[i].y, 1);
      EXPECT_LT(std::abs(xr.dot(expected * xl)) / (expected * xl).head<2>().norm(), 1e-3);
    }
  }
}

TEST(StereoGeometry, EpipolarLineGivesSignedPixelDistances) {
  std::mt19937 rng(22);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 30; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector3d line = epipolarLine(F, c.left);
      EXPECT_NEAR(line.head<2>().norm(), 1.0, 1e-12);
      EXPECT_NEAR(line.dot(c.right.homogeneous()), 0.0, 1e-9);
      // 3 px off along the independently computed normal: |distance| = 3, sign flips.
      const auto reference = independentEpipolarLine(rig, c.left);
      const double plus = line.dot((c.right + 3.0 * reference.first).homogeneous());
      const double minus = line.dot((c.right - 3.0 * reference.first).homogeneous());
      EXPECT_NEAR(std::abs(plus), 3.0, 1e-9);
      EXPECT_NEAR(plus, -minus, 1e-9);
      // Sliding along the line keeps the distance at 0.
      const Eigen::Vector2d along(reference.first.y(), -reference.first.x());
      EXPECT_NEAR(line.dot((c.right + 40.0 * along).homogeneous()), 0.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceIsZeroForExactCorrespondences) {
  std::mt19937 rng(23);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 30; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      EXPECT_NEAR(sampsonDistance(F, c.left, c.right), 0.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceOfARectifiedPairIsHalfTheOffsetInEachImage) {
  // Identical K, pure x baseline: epipolar lines are rows. A right pixel d rows off is best
  // explained by moving each pixel d/2 towards the other: gold-standard error sqrt(2) d / 2, and
  // Sampson is exact here (the constraint is linear in y_l, y_r).
  StereoRig rig;
  rig.K_right = rig.K_left;
  rig.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
  std::mt19937 rng(24);
  for (int i = 0; i < 30; ++i) {
    const Correspondence c = observe(rig, randomPointInFront(rng));
    for (double d : {0.5, 3.0, -3.0}) {
      const Eigen::Vector2d moved = c.right + Eigen::Vector2d(0, d);
      EXPECT_NEAR(sampsonDistance(F, c.left, moved), std::abs(d) / std::sqrt(2.0), 1e-9);
      EXPECT_NEAR(std::abs(epipolarLine(F, c.left).dot(moved.homogeneous())), std::abs(d), 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceApproximatesTheGoldStandardError) {
  // For a general rig the Sampson distance is the first-order approximation of the reprojection
  // error minimised over the 3D point (brute force here), for a right pixel moved perpendicular
  // to its epipolar line.
  std::mt19937 rng(25);
  for (int r = 0; r < 5; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 10; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector2d normal = independentEpipolarLine(rig, c.left).first;
      for (double d : {0.3, 3.0}) {
        const Eigen::Vector2d moved = c.right + d * normal;
        const double gold = goldStandardError(rig, c.left, moved, c.point_left);
        EXPECT_NEAR(sampsonDistance(F, c.left, moved), gold, 2e-3 * d) << "d=" << d;
        // Both lie between d / sqrt(2) (equal share) and d (one image only), for similar K.
        EXPECT_GT(gold, 0.6 * d);
        EXPECT_LT(gold, 0.8 * d);
      }
    }
  }
}

TEST(StereoGeometry, TriangulateMidpointRecoversTheExactPoint) {
  std::mt19937 rng(26);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d p = randomPointInFront(rng);
      // Rays of arbitrary length.
      const Eigen::Vector3d ray_left = uniform(rng, 0.1, 10) * p;
      const Eigen::Vector3d ray_right = uniform(rng, 0.1, 10) * (T_ropt_lopt * p);
      const auto result = triangulateMidpoint(ray_left, ray_right, rig.T_lopt_ropt);
      ASSERT_TRUE(result.has_value()) << p.transpose();
      EXPECT_TRUE(matrixNear(result->point_left, p, 1e-9)) << p.transpose();
      EXPECT_NEAR(result->ray_gap, 0.0, 1e-9);
      // Parallax: the angle at the point between the directions to the two camera centres.
      const double parallax = angleBetween(p, p - rig.T_lopt_ropt.translation());
      EXPECT_NEAR(result->parallax, parallax, 1e-9);
    }
  }
}

/// Brute force: minimise |s d_l - (c_r + t d_r)| over s, t >= 0 by nested ternary search (the
/// objective is jointly convex). Returns the midpoint and writes the gap.
Eigen::Vector3d bruteForceMidpoint(const Eigen::Vector3d& d_l, const Eigen::Vector3d& c_r,
                                   const Eigen::Vector3d& d_r, double max_range, double* gap) {
  auto distance = [&](double s, double t) { return (s * d_l - c_r - t * d_r).norm(); };
  auto ternary_search = [max_range](const std::function<double(double)>& f) {
    double lo = 0.0, hi = max_range;
    for (int i = 0; i < 200; ++i) {
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (f(m1) < f(m2)) {
        hi = m2;
      } else {
        lo = m1;
      }
    }
    return 0.5 * (lo + hi);
  };
  auto best_t = [&](double s) { return ternary_search([&](double t) { return distance(s, t); }); };
  const double s = ternary_search([&](double s) { return distance(s, best_t(s)); });
  const double t = best_t(s);
  *gap = distance(s, t);
  return 0.5 * (s * d_l + c_r + t * d_r);
}

TEST(StereoGeometry, TriangulateMidpointOfSkewRaysByConstruction) {
  // Build two skew rays whose common perpendicular is known: closest points P_l = s0 d_l and
  // P_r = P_l + g n with n perpendicular to both directions; place the right centre on the line
  // through P_r along d_r. The midpoint is P_l + g n / 2 and the gap is g.
  std::mt19937 rng(27);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d d_l =
        Eigen::Vector3d(uniform(rng, -0.5, 0.5), uniform(rng, -0.3, 0.3), 1).normalized();
    const Eigen::Vector3d d_r =
        (d_l + Eigen::Vector3d(uniform(rng, -0.2, 0.2), uniform(rng, -0.1, 0.1), 0)).normalized();
    const Eigen::Vector3d n = d_l.cross(d_r).normalized();
    const double s0 = uniform(rng, 2, 30), t0 = uniform(rng, 2, 30), g = uniform(rng, 0.001, 0.2);
    const Eigen::Vector3d P_l = s0 * d_l, P_r = P_l + g * n, c_r = P_r - t0 * d_r;
    Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
    T_lopt_ropt.linear() =
        Eigen::AngleAxisd(uniform(rng, 0, 0.1), randomUnitVector(rng)).toRotationMatrix();
    T_lopt_ropt.translation() = c_r;
    const Eigen::Vector3d ray_right = T_lopt_ropt.linear().transpose() * d_r * 3.7;
    const auto result = triangulateMidpoint(2.0 * d_l, ray_right, T_lopt_ropt);
    ASSERT_TRUE(result.has_value()) << "i=" << i;
    EXPECT_TRUE(matrixNear(result->point_left, P_l + 0.5 * g * n, 1e-8)) << "i=" << i;
    EXPECT_NEAR(result->ray_gap, g, 1e-8) << "i=" << i;
    EXPECT_NEAR(result->parallax, angleBetween(d_l, d_r), 1e-9) << "i=" << i;
  }
}

TEST(StereoGeometry, TriangulateMidpointOfSkewRaysAgreesWithBruteForce) {
  std::mt19937 rng(28);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    for (int i = 0; i < 5; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      // Perturb both pixels so the back-projected rays are skew.
      const Eigen::Vector2d left =
          c.left + Eigen::Vector2d(uniform(rng, -2, 2), uniform(rng, -2, 2));
      const Eigen::Vector2d right =
          c.right + Eigen::Vector2d(uniform(rng, -2, 2), uniform(rng, -2, 2));
      const Eigen::Vector3d ray_left = rig.K_left.inverse() * left.homogeneous();
      const Eigen::Vector3d ray_right = rig.K_right.inverse() * right.homogeneous();
      const auto result = triangulateMidpoint(ray_left, ray_right, rig.T_lopt_ropt);
      if (!result) continue;  // the perturbation may make a far point diverge: checked elsewhere
      double gap = 0.0;
      const Eigen::Vector3d expected =
          bruteForceMidpoint(ray_left.normalized(), rig.T_lopt_ropt.translation(),
                             (rig.T_lopt_ropt.linear() * ray_right).normalized(), 2000.0, &gap);
      EXPECT_TRUE(matrixNear(result->point_left, expected, 1e-6 * expected.norm()));
      EXPECT_NEAR(result->ray_gap, gap, 1e-7);
    }
  }
}

TEST(StereoGeometry, TriangulateMidpointRejectsParallelRays) {
  std::mt19937 rng(29);
  const StereoRig rig = randomRig(rng);
  const Eigen::Matrix3d R_ropt_lopt = rig.T_lopt_ropt.linear().transpose();
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.3, -0.2, 1), Eigen::Vector3d(-1, 0, 0.2)}) {
    // Same direction in the left frame, expressed in the right frame: parallel.
    EXPECT_FALSE(triangulateMidpoint(direction, R_ropt_lopt * direction, rig.T_lopt_ropt));
    EXPECT_FALSE(triangulateMidpoint(direction, 5.0 * R_ropt_lopt * direction, rig.T_lopt_ropt));
    // Nearly parallel (1e-9 rad): a point ~1e8 m away is no measurement either.
    const Eigen::Vector3d tilted = Eigen::AngleAxisd(1e-9, direction.unitOrthogonal()) * direction;
    EXPECT_FALSE(triangulateMidpoint(direction, R_ropt_lopt * tilted, rig.T_lopt_ropt));
  }
  EXPECT_FALSE(
      triangulateMidpoint(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1), rig.T_lopt_ropt));
  // Converging but only 1e-7 rad apart (a point ~1200 km away with a 12 cm baseline): nearly
  // parallel, rejected; 1e-4 rad apart (1.2 km) is still a valid point.
  StereoRig horizontal;
  horizontal.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  EXPECT_FALSE(triangulateMidpoint(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-1e-7, 0, 1),
                                   horizontal.T_lopt_ropt));
  const auto far = triangulateMidpoint(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-1e-4, 0, 1),
                                       horizontal.T_lopt_ropt);
  ASSERT_TRUE(far.has_value());
  EXPECT_NEAR(far->point_left.z(), 0.12 / 1e-4, 1e-6 * 1200);
  EXPECT_NEAR(far->parallax, 1e-4, 1e-10);
}

TEST(StereoGeometry, TriangulateMidpointRejectsPointsBehindTheCameras) {
  std::mt19937 rng(30);
  const StereoRig rig = randomRig(rng);
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d front = randomPointInFront(rng);
    const Eigen::Vector3d behind(front.x(), front.y(), -front.z());
    // Rays pointing at a point behind both cameras.
    EXPECT_FALSE(triangulateMidpoint(behind, T_ropt_lopt * behind, rig.T_lopt_ropt))
        << behind.transpose();
    // Forward-pointing rays whose lines meet behind the cameras.
    EXPECT_FALSE(triangulateMidpoint(-behind, -(T_ropt_lopt * behind), rig.T_lopt_ropt))
        << behind.transpose();
    // Lines meeting at a point in front of the left camera, but against the direction of one
    // ray: the right ray points away from it, or the left one does.
    const Eigen::Vector3d in_right = T_ropt_lopt * front;
    EXPECT_FALSE(triangulateMidpoint(front, -in_right, rig.T_lopt_ropt)) << front.transpose();
    EXPECT_FALSE(triangulateMidpoint(-front, in_right, rig.T_lopt_ropt)) << front.transpose();
  }
  // Diverging rays: left looks slightly left, right slightly right; the lines cross behind.
  StereoRig horizontal;
  horizontal.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  EXPECT_FALSE(triangulateMidpoint(Eigen::Vector3d(-0.01, 0, 1), Eigen::Vector3d(0.01, 0, 1),
                                   horizontal.T_lopt_ropt));
  // The same rays converging give a point in front at z = 0.12 / 0.02 = 6 m.
  const auto converging = triangulateMidpoint(Eigen::Vector3d(0.01, 0, 1),
                                              Eigen::Vector3d(-0.01, 0, 1), horizontal.T_lopt_ropt);
  ASSERT_TRUE(converging.has_value());
  EXPECT_TRUE(matrixNear(converging->point_left, Eigen::Vector3d(0.06, 0, 6), 1e-10));
}

/// Bearings of random points in front of a camera, and the same seen after turning it.
struct TurnedBearings {
  std::vector<Eigen::Vector3d> before, after;
};

TurnedBearings turnedBearings(const Eigen::Matrix3d& R, int count, int outliers, double noise_angle,
                              std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, noise_angle);
  TurnedBearings b;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p(0.6 * u(*rng), 0.4 * u(*rng), 1.0);
    b.before.push_back(p);
    Eigen::Vector3d q = R * p.normalized();
    q += Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
    // An outlier: a direction 5-10 deg away from where the turn puts it.
    if (i < outliers) q = expSO3(Eigen::Vector3d(u(*rng), u(*rng), 0).normalized() * 7 * kDeg) * q;
    b.after.push_back(3.0 * q);  // the length does not matter
  }
  return b;
}

TEST(BearingRotationFit, RecoversTheTurnExactlyFromCleanBearings) {
  std::mt19937_64 rng(5);
  const Eigen::Matrix3d R = rotationFromRpy(Eigen::Vector3d(0.3, -4.0, 8.8) * kDeg);
  const TurnedBearings b = turnedBearings(R, 30, 0, 0.0, &rng);
  BearingRotationFit fit;
  ASSERT_TRUE(fitBearingRotation(b.before, b.after, 1e-3, 8, &fit));
  EXPECT_LT(rotationDistance(fit.rotation, R), 1e-12);
  EXPECT_EQ(fit.inliers, 30);
  EXPECT_LT(fit.rms_angle, 1e-12);
}

TEST(BearingRotationFit, TrimsOutliersAndStaysWithinTheNoise) {
  std::mt19937_64 rng(6);
  const Eigen::Matrix3d R = rotationFromRpy(Eigen::Vector3d(0.0, 0.0, -5.0) * kDeg);
  const double noise = 1.0 / 600.0;  // one pixel at 600 px focal length
  const TurnedBearings b = turnedBearings(R, 100, 25, noise, &rng);
  BearingRotationFit fit;
  ASSERT_TRUE(fitBearingRotation(b.before, b.after, 5.0 / 600.0, 8, &fit));
  EXPECT_EQ(fit.inliers, 75);  // the 25 directions 7 deg off are all trimmed
  // 75 bearings with 1 px of noise determine the turn to ~0.01 deg; the outliers, kept,
  // would pull it by ~1 deg.
  EXPECT_LT(rotationDistance(fit.rotation, R), 0.03 * kDeg);
  EXPECT_LT(fit.rms_angle, 3.0 * noise);
}

TEST(BearingRotationFit, RefusesTooFewPairsAndNonFiniteDirections) {
  std::mt19937_64 rng(7);
  TurnedBearings b = turnedBearings(Eigen::Matrix3d::Identity(), 6, 0, 0.0, &rng);
  BearingRotationFit fit;
  fit.inliers = -1;
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 8, &fit));
  EXPECT_TRUE(fitBearingRotation(b.before, b.after, 1e-3, 6, &fit));
  b.after[2].x() = std::numeric_limits<double>::quiet_NaN();
  fit.inliers = -1;
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 6, &fit));
  EXPECT_EQ(fit.inliers, -1);  // untouched
  b.after.pop_back();
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 3, &fit));  // sizes differ
}

}  // namespace
}  // namespace osc
