#include "online_stereo_calibration/core/geometry/rotation.h"

#include <cmath>

namespace osc {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(rotation_vector);
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& rotation) {
  // Via the quaternion: well conditioned for every angle including pi.
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double sin_half = v.norm();
  if (sin_half < 1e-12) return 2.0 * v;
  const double angle = 2.0 * std::atan2(sin_half, q.w());
  return v * (angle / sin_half);
}

Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d rpyFromRotation(const Eigen::Matrix3d& r) {
  // Same formulas and branch as tf2::Matrix3x3::getEulerYPR (solution 1).
  double roll, pitch, yaw;
  if (std::abs(r(2, 0)) >= 1.0 - 1e-12) {
    yaw = 0.0;
    if (r(2, 0) < 0.0) {
      pitch = M_PI / 2.0;
      roll = std::atan2(r(0, 1), r(0, 2));
    } else {
      pitch = -M_PI / 2.0;
      roll = std::atan2(-r(0, 1), -r(0, 2));
    }
  } else {
    pitch = -std::asin(r(2, 0));
    const double c = std::cos(pitch);
    roll = std::atan2(r(2, 1) / c, r(2, 2) / c);
    yaw = std::atan2(r(1, 0) / c, r(0, 0) / c);
  }
  return Eigen::Vector3d(roll, pitch, yaw);
}

double rotationDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return logSO3(a.transpose() * b).norm();
}

double wrapAngle(double angle) {
  // std::remainder is exact (fmod(angle + pi) lost the low bits of a small angle).
  angle = std::remainder(angle, 2.0 * M_PI);  // [-pi, pi]
  return angle <= -M_PI ? angle + 2.0 * M_PI : angle;
}

}  // namespace osc
