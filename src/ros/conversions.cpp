/// @file conversions.cpp
/// @brief Pure message <-> core conversions.
#include "online_stereo_calibration/ros/conversions.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

namespace online_stereo_calibration {

osc::CameraIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info) {
  osc::CameraIntrinsics intrinsics;
  if (info.width == 0 || info.height == 0) {
    throw std::invalid_argument("camera_info has zero width or height (" +
                                std::to_string(info.width) + "x" + std::to_string(info.height) +
                                ")");
  }
  if (!(info.K[0] > 0.0) || !(info.K[4] > 0.0) || !std::isfinite(info.K[0]) ||
      !std::isfinite(info.K[4]) || !std::isfinite(info.K[2]) || !std::isfinite(info.K[5])) {
    throw std::invalid_argument("camera_info is uncalibrated (K[0] or K[4] not positive)");
  }
  intrinsics.width = static_cast<int>(info.width);
  intrinsics.height = static_cast<int>(info.height);
  intrinsics.fx = info.K[0];
  intrinsics.fy = info.K[4];
  intrinsics.cx = info.K[2];
  intrinsics.cy = info.K[5];
  intrinsics.model = osc::distortionModelFromName(info.distortion_model);
  intrinsics.distortion.assign(info.D.begin(), info.D.end());
  // An all-zero D means no distortion, whatever its length; "none" takes no coefficients.
  bool all_zero = true;
  for (double d : intrinsics.distortion) all_zero = all_zero && d == 0.0;
  if (intrinsics.model == osc::DistortionModel::kNone && all_zero) intrinsics.distortion.clear();
  // The core validates the number of coefficients and finiteness.
  osc::CameraModel check(intrinsics);
  (void)check;
  return intrinsics;
}

osc::Matrix12d tangentCovarianceFromParameterCovariance(
    const osc::StereoExtrinsics& extrinsics, const osc::Matrix12d& parameter_covariance) {
  const osc::Matrix12d J_inv = osc::parameterJacobian(extrinsics).inverse();
  const osc::Matrix12d tangent = J_inv * parameter_covariance * J_inv.transpose();
  return 0.5 * (tangent + tangent.transpose());
}

std::string imageBufferProblem(const sensor_msgs::Image& image, int bytes_per_pixel) {
  const uint64_t row = static_cast<uint64_t>(image.width) * static_cast<uint64_t>(bytes_per_pixel);
  const uint64_t needed = static_cast<uint64_t>(image.step) * image.height;
  if (image.step < row) {
    return "image step " + std::to_string(image.step) + " shorter than a row of " +
           std::to_string(image.width) + " px x " + std::to_string(bytes_per_pixel) + " bytes";
  }
  if (image.data.size() < needed) {
    return "image data of " + std::to_string(image.data.size()) + " bytes shorter than step x " +
           "height (" + std::to_string(image.step) + " x " + std::to_string(image.height) + ")";
  }
  return "";
}

bool intrinsicsDiffer(const osc::CameraIntrinsics& a, const osc::CameraIntrinsics& b) {
  return a.width != b.width || a.height != b.height || a.fx != b.fx || a.fy != b.fy ||
         a.cx != b.cx || a.cy != b.cy || a.model != b.model || a.distortion != b.distortion;
}

Eigen::Isometry3d isometryFromPose(const geometry_msgs::Pose& pose) {
  Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                       pose.orientation.z);
  q.normalize();
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = q.toRotationMatrix();
  result.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return result;
}

Eigen::Isometry3d isometryFromTransform(const geometry_msgs::Transform& transform) {
  geometry_msgs::Pose pose;
  pose.position.x = transform.translation.x;
  pose.position.y = transform.translation.y;
  pose.position.z = transform.translation.z;
  pose.orientation = transform.rotation;
  return isometryFromPose(pose);
}

geometry_msgs::Transform transformFromIsometry(const Eigen::Isometry3d& pose) {
  geometry_msgs::Transform transform;
  transform.translation.x = pose.translation().x();
  transform.translation.y = pose.translation().y();
  transform.translation.z = pose.translation().z();
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  transform.rotation.w = q.w();
  transform.rotation.x = q.x();
  transform.rotation.y = q.y();
  transform.rotation.z = q.z();
  return transform;
}

std::string poseProblem(const geometry_msgs::Pose& pose) {
  const double values[] = {pose.position.x,    pose.position.y,    pose.position.z,
                           pose.orientation.w, pose.orientation.x, pose.orientation.y,
                           pose.orientation.z};
  for (double v : values) {
    if (!std::isfinite(v)) return "a non-finite pose";
  }
  const double norm2 =
      pose.orientation.w * pose.orientation.w + pose.orientation.x * pose.orientation.x +
      pose.orientation.y * pose.orientation.y + pose.orientation.z * pose.orientation.z;
  // Normalising anything between half and twice unit length is a harmless convention
  // difference; a zero (or near-zero) quaternion is no rotation at all.
  if (!(norm2 > 0.25 && norm2 < 4.0)) {
    return "a quaternion of norm " + std::to_string(std::sqrt(norm2)) + " (not a rotation)";
  }
  return "";
}

StampedPose odometrySample(const nav_msgs::Odometry& message, bool with_covariance,
                           std::string* twist_problem, std::string* covariance_problem) {
  StampedPose sample{message.header.stamp.toSec(), isometryFromPose(message.pose.pose)};
  const geometry_msgs::Twist& t = message.twist.twist;
  sample.twist << t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z;
  sample.has_twist = sample.twist.allFinite();
  if (!sample.has_twist) {
    sample.twist.setZero();
    *twist_problem = "twist not finite";
  }
  if (with_covariance) {
    Eigen::Matrix<double, 6, 6> c;
    for (int r = 0; r < 6; ++r)
      for (int k = 0; k < 6; ++k)
        c(r, k) = message.twist.covariance[static_cast<size_t>(6 * r + k)];
    // Many drivers leave it zero, or mark it unknown with -1.
    const bool usable = c.allFinite() && c.diagonal().minCoeff() >= 0.0 &&
                        c.diagonal().maxCoeff() > 0.0 &&
                        (c - c.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * c.cwiseAbs().maxCoeff();
    sample.has_twist_covariance = usable;
    if (usable) sample.twist_covariance = c;
    if (!usable)
      *covariance_problem = "twist covariance not finite, negative, asymmetric or all zero";
  }
  return sample;
}

std::string unsetTwistProblem(const StampedPose& sample, const StampedPose& previous) {
  if (!sample.has_twist || !sample.twist.isZero(0.0)) return "";
  const Eigen::Isometry3d moved = previous.pose.inverse() * sample.pose;
  const double angle = Eigen::AngleAxisd(moved.linear()).angle();
  if (moved.translation().norm() <= 1e-3 && angle <= 1e-3) return "";
  return "twist exactly zero while the pose moved (not filled in by the odometry?)";
}

Eigen::Isometry3d interpolatePose(const StampedPose& before, const StampedPose& after,
                                  double stamp) {
  const double span = after.stamp - before.stamp;
  if (!(std::abs(span) > 0.0)) return before.pose;
  const double s = (stamp - before.stamp) / span;
  const Eigen::Quaterniond q0(before.pose.linear());
  const Eigen::Quaterniond q1(after.pose.linear());
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.translation() =
      before.pose.translation() + s * (after.pose.translation() - before.pose.translation());
  result.linear() = q0.slerp(s, q1).normalized().toRotationMatrix();
  return result;
}

sensor_msgs::CameraInfo rectifiedCameraInfo(const sensor_msgs::CameraInfo& input,
                                            const Eigen::Matrix3d& R,
                                            const Eigen::Matrix<double, 3, 4>& P) {
  sensor_msgs::CameraInfo info = input;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) info.R[3 * i + j] = R(i, j);
    for (int j = 0; j < 4; ++j) info.P[4 * i + j] = P(i, j);
  }
  // image_geometry's PinholeCameraModel (image_proc/rectify, 1.16-1.17) copies the raw image
  // unchanged when every D is zero, whatever R and P say: a lens without distortion would
  // not be rectified at all. A k1 of 1e-12 moves no pixel by more than 1e-9 px and makes it
  // rectify.
  bool all_zero = true;
  for (double d : info.D) all_zero = all_zero && d == 0.0;
  if (all_zero) {
    if (info.distortion_model.empty()) info.distortion_model = "plumb_bob";
    if (info.D.empty()) info.D.assign(info.distortion_model == "equidistant" ? 4 : 5, 0.0);
    info.D[0] = 1e-12;
  }
  return info;
}

}  // namespace online_stereo_calibration
