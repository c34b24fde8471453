/// @file pose.h
/// @brief The interface's conventions in one place: 6-vector <-> rigid transform, body <->
/// optical frames, and the stereo extrinsics (the paper's x_caml and x_camr).
///
/// Naming: T_a_b maps coordinates in frame b into frame a (the pose of b in a), so
/// p_a = T_a_b * p_b and T_a_c = T_a_b * T_b_c.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace osc {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// [x, y, z, roll, pitch, yaw] (m, rad) -> T_parent_child, R = Rz*Ry*Rx (tf2 setRPY).
Eigen::Isometry3d poseFromParameters(const Vector6d& parameters);

/// T_parent_child -> [x, y, z, roll, pitch, yaw] (tf2 getRPY branch).
Vector6d parametersFromPose(const Eigen::Isometry3d& pose);

/// R_body_optical of interface.md: columns are the optical axes (z forward, x right,
/// y down) in body coordinates (x forward, y left, z up).
const Eigen::Matrix3d& rotationBodyOptical();

/// T_body_optical as a transform (rotation only).
Eigen::Isometry3d bodyFromOptical();

/// Right-perturbation on a pose used by the filter: t + dt, R * Exp(dtheta).
/// delta = [dt (3), dtheta (3)]; dtheta is expressed in the child frame.
Eigen::Isometry3d boxPlus(const Eigen::Isometry3d& pose, const Vector6d& delta);

/// Inverse of boxPlus: the delta with boxPlus(reference, delta) == pose.
Vector6d boxMinus(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& reference);

/// The group exponential of SE(3): the pose reached after a unit time at the constant body
/// twist [v (3), w (3)] (velocity and angular rate in the moving frame):
/// R = Exp(w), t = V(w) v (V: the left Jacobian of SO(3)).
Eigen::Isometry3d expSE3(const Vector6d& twist);

/// Inverse of expSE3 (rotation angle below pi).
Vector6d logSE3(const Eigen::Isometry3d& pose);

/// The two extrinsic transforms the package estimates (seed eq. 1-2, interface.md).
struct StereoExtrinsics {
  /// x_caml: pose of the left camera *body* frame in the vehicle frame.
  Eigen::Isometry3d T_veh_caml = Eigen::Isometry3d::Identity();
  /// x_camr: pose of the right camera *body* frame in the left camera body frame.
  Eigen::Isometry3d T_caml_camr = Eigen::Isometry3d::Identity();

  /// From the interface's 12 parameters [xl..yaw_l, xr..yaw_r].
  static StereoExtrinsics fromParameters(const Vector12d& parameters);
  /// To the interface's 12 parameters.
  Vector12d toParameters() const;
  /// From the two optical-frame transforms (the inverse of vehicleToLeftOptical() and
  /// leftToRightOptical()): T_veh_lopt and T_lopt_ropt.
  static StereoExtrinsics fromOpticalFrames(const Eigen::Isometry3d& T_veh_lopt,
                                            const Eigen::Isometry3d& T_lopt_ropt);

  /// T_veh_lopt: vehicle frame <- left optical frame (the published tf).
  Eigen::Isometry3d vehicleToLeftOptical() const;
  /// T_lopt_ropt: left optical frame <- right optical frame (the published tf).
  Eigen::Isometry3d leftToRightOptical() const;
};

/// Jacobian of the 12 interface parameters w.r.t. the filter's tangent error
/// [dt_l, dtheta_l, dt_r, dtheta_r] (boxPlus on each pose), by central differences.
/// Used to report the covariance in RPY; it is singular only where RPY itself is
/// (pitch = +-90 deg), which never enters the filter's arithmetic.
Matrix12d parameterJacobian(const StereoExtrinsics& extrinsics);

}  // namespace osc
