// Independent unit tests of rotation.h: skew, roll-pitch-yaw in both directions (gimbal lock
// included), Exp/Log of SO(3), the rotation distance and angle wrapping.
//
// Every expected value comes from a source other than the code under test: rotation matrices
// and Rodrigues' formula written out by hand (geometry_test_support.h), Eigen's AngleAxis, or
// the standard library. All random numbers are seeded.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "geometry_test_support.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

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

}  // namespace
}  // namespace osc
