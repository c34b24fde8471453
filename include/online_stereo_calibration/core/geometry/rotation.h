/// @file rotation.h
/// @brief Rotations: SO(3) exponential/logarithm and roll-pitch-yaw as tf2 uses it.
///
/// The filter estimates rotations on the manifold (R = R_hat * Exp(delta)), so it never meets
/// the roll/pitch/yaw singularity; RPY exists only at the interface (interface.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace osc {

/// Skew-symmetric matrix [v]x such that [v]x * w = v.cross(w).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// SO(3) exponential map: rotation vector (axis * angle, rad) -> rotation matrix.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& rotation_vector);

/// SO(3) logarithm: rotation matrix -> rotation vector with angle in [0, pi].
Eigen::Vector3d logSO3(const Eigen::Matrix3d& rotation);

/// R = Rz(yaw) * Ry(pitch) * Rx(roll), as tf2::Matrix3x3::setRPY.
Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& roll_pitch_yaw);

/// Inverse of rotationFromRpy with tf2::Matrix3x3::getRPY's branch (pitch in [-pi/2, pi/2]).
/// At pitch = +-pi/2 roll and yaw are not unique; then yaw is set to 0 and roll absorbs it.
Eigen::Vector3d rpyFromRotation(const Eigen::Matrix3d& rotation);

/// Angle (rad) of the rotation that takes a to b: |log(a^T b)|.
double rotationDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

/// Wraps an angle to (-pi, pi].
double wrapAngle(double angle);

}  // namespace osc
