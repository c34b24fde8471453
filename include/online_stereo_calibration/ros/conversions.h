/// @file conversions.h
/// @brief Pure conversions between ROS messages and the core's plain types (no node handle,
/// no master): CameraInfo -> CameraIntrinsics, poses, transforms, and pose interpolation.
#pragma once

#include <string>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace online_stereo_calibration {

/// K, D, size and distortion model of a CameraInfo (the raw camera's intrinsics).
/// @throws std::invalid_argument naming the problem (uncalibrated K, unknown model, wrong
/// number of coefficients, non-positive size).
osc::CameraIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info);

/// The CameraInfo of the rectification that follows the calibration: the input's header,
/// size, binning, ROI, distortion model, K and D, with @p R (raw optical -> rectified) and
/// @p P (rectified projection, px) of osc::StereoRectification. A D that is all zero (or
/// empty) gets k1 = 1e-12: image_geometry leaves such an image unrectified whatever R says.
sensor_msgs::CameraInfo rectifiedCameraInfo(const sensor_msgs::CameraInfo& input,
                                            const Eigen::Matrix3d& R,
                                            const Eigen::Matrix<double, 3, 4>& P);

/// Why an image message's buffer cannot hold its pixels (step shorter than a row, data
/// shorter than step x height), or "" if it can. @p bytes_per_pixel: of its encoding.
/// Checked before the pixels are touched: a short buffer would be read past its end.
std::string imageBufferProblem(const sensor_msgs::Image& image, int bytes_per_pixel);

/// True if two intrinsics differ in any field (camera_info changed).
bool intrinsicsDiffer(const osc::CameraIntrinsics& a, const osc::CameraIntrinsics& b);

/// geometry_msgs/Pose -> isometry; the quaternion is normalised.
Eigen::Isometry3d isometryFromPose(const geometry_msgs::Pose& pose);
/// geometry_msgs/Transform -> isometry; the quaternion is normalised.
Eigen::Isometry3d isometryFromTransform(const geometry_msgs::Transform& transform);
/// isometry -> geometry_msgs/Transform.
geometry_msgs::Transform transformFromIsometry(const Eigen::Isometry3d& pose);

/// The filter's tangent-space covariance whose parameter covariance (interface order, m and
/// rad) at @p extrinsics is @p parameter_covariance: J^-1 P J^-T with J = parameterJacobian
/// (the inverse of CalibrationFilter::parameterCovariance), symmetrised. Used to seed the
/// filter from a calibration file's covariance (or its sigmas).
osc::Matrix12d tangentCovarianceFromParameterCovariance(const osc::StereoExtrinsics& extrinsics,
                                                        const osc::Matrix12d& parameter_covariance);

/// Why a pose cannot be used (a NaN or Inf field, a quaternion far from unit norm, e.g. all
/// zero), or "" if it can.
std::string poseProblem(const geometry_msgs::Pose& pose);

/// A pose with its time (s).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  /// The covariance of the twist [v, w] that led to this sample since the one before
  /// (nav_msgs/Odometry twist.covariance, vehicle frame), when the odometry gives a usable one.
  bool has_twist_covariance = false;
  Eigen::Matrix<double, 6, 6> twist_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  /// The body twist [v (m/s), w (rad/s)] of the vehicle (the odometry's child frame) at this
  /// stamp (nav_msgs/Odometry twist.twist), when the odometry gives a usable one: the time
  /// offset's model (osc::MotionIncrement::has_twists) uses it.
  bool has_twist = false;
  osc::Vector6d twist = osc::Vector6d::Zero();
};

/// The sample of a nav_msgs/Odometry message whose pose is usable (poseProblem): header
/// stamp, pose.pose, twist.twist (has_twist when all six values are finite, else
/// @p twist_problem says why) and, with @p with_covariance, twist.covariance when it is
/// usable (finite, symmetric, non-negative variances, not all zero; else
/// @p covariance_problem says why). Problems not met are left "".
StampedPose odometrySample(const nav_msgs::Odometry& message, bool with_covariance,
                           std::string* twist_problem, std::string* covariance_problem);

/// Why @p sample's twist looks unset ("" if it does not): exactly zero in all six values
/// while the pose moved since @p previous (by > 1 mm or 1 mrad). Drivers that do not fill
/// the twist leave it zero; a moving vehicle's own estimate is never exactly zero.
std::string unsetTwistProblem(const StampedPose& sample, const StampedPose& previous);

/// The pose at @p stamp between @p before and @p after: translation linear, rotation SLERP
/// (shortest arc). @p stamp may be outside [before, after] (extrapolation); equal stamps
/// return @p before.
Eigen::Isometry3d interpolatePose(const StampedPose& before, const StampedPose& after,
                                  double stamp);

}  // namespace online_stereo_calibration
