/// @file geometry_test_support.h
/// @brief Helpers of the geometry tests (test_rotation, test_pose, test_camera_model,
/// test_stereo_geometry, test_bearing_rotation_fit): a matrix comparison, seeded random numbers
/// and rotations written out by hand, independent of the code under test.
#pragma once

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Dense>

namespace osc {

inline constexpr double kDeg = M_PI / 180.0;

// ---------------------------------------------------------------------------------------------
// Generic helpers
// ---------------------------------------------------------------------------------------------

inline ::testing::AssertionResult matrixNear(const Eigen::MatrixXd& actual,
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

inline double uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

inline Eigen::Vector3d randomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  return v.normalized();
}

/// Angle difference mapped to [-pi, pi] with the standard library, not wrapAngle.
inline double angleDifference(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

// ---------------------------------------------------------------------------------------------
// Hand-written rotations (right-handed, active: R * v rotates v)
// ---------------------------------------------------------------------------------------------

inline Eigen::Matrix3d handRx(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}

inline Eigen::Matrix3d handRy(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}

inline Eigen::Matrix3d handRz(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

/// tf2's setRPY: R = Rz(yaw) * Ry(pitch) * Rx(roll).
inline Eigen::Matrix3d handRpy(double roll, double pitch, double yaw) {
  return handRz(yaw) * handRy(pitch) * handRx(roll);
}

inline Eigen::Matrix3d handRpy(const Eigen::Vector3d& rpy) {
  return handRpy(rpy(0), rpy(1), rpy(2));
}

/// Rodrigues' formula R = I + sin(a) [k]x + (1 - cos(a)) [k]x^2, written out by hand.
inline Eigen::Matrix3d handRodrigues(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d k = rotation_vector / angle;
  Eigen::Matrix3d kx;
  kx << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(angle) * kx + (1.0 - std::cos(angle)) * kx * kx;
}

}  // namespace osc
