/// @file output_publisher.cpp
/// @brief Calibration message, point cloud, markers and their publishers.
#include "online_stereo_calibration/ros/output_publisher.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "online_stereo_calibration/ros/conversions.h"

namespace online_stereo_calibration {

uint8_t calibrationState(const osc::CalibrationEstimate& estimate, bool jump_detected,
                         int min_tracked_points, const osc::ConvergenceThresholds& thresholds) {
  if (jump_detected) return StereoCalibration::STATE_DIVERGED;
  if (static_cast<int>(estimate.tracked_points) < min_tracked_points) {
    return StereoCalibration::STATE_INITIALIZING;
  }
  return osc::isConverged(estimate, thresholds) ? StereoCalibration::STATE_CONVERGED
                                                : StereoCalibration::STATE_CONVERGING;
}

StereoCalibration makeCalibrationMessage(const osc::CalibrationEstimate& estimate,
                                         const ros::Time& stamp, const OutputFrames& frames,
                                         uint8_t state, double processing_time) {
  StereoCalibration message;
  message.header.stamp = stamp;
  message.header.frame_id = frames.vehicle;
  message.left_frame_id = frames.left_optical;
  message.right_frame_id = frames.right_optical;
  message.vehicle_to_left = transformFromIsometry(estimate.extrinsics.vehicleToLeftOptical());
  message.left_to_right = transformFromIsometry(estimate.extrinsics.leftToRightOptical());
  const osc::Vector12d sigma = estimate.sigmas();
  for (int i = 0; i < 12; ++i) {
    message.parameters[i] = estimate.parameters(i);
    message.sigma[i] = sigma(i);
    for (int j = 0; j < 12; ++j)
      message.covariance[12 * i + j] = estimate.parameter_covariance(i, j);
  }
  message.tracked_points = static_cast<uint32_t>(estimate.tracked_points);
  message.processing_time = processing_time;
  message.time_offset = estimate.time_offset;
  message.time_offset_sigma = estimate.time_offset_sigma;
  message.state = state;
  return message;
}

void setQualityFields(const osc::CalibrationQuality& quality, StereoCalibration* message) {
  message->rectification_error =
      quality.rectification_error ? quality.rectification_error->median_px : -1.0;
  message->rectification_pairs =
      quality.rectification_error ? static_cast<uint32_t>(quality.rectification_error->pairs) : 0;
  message->depth_sigma_10m = quality.depth_sigma_10m;
  message->depth_sigma_50m = quality.depth_sigma_50m;
}

sensor_msgs::PointCloud2 makePointCloud(const std::vector<osc::PointEstimate>& points,
                                        const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header = header;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (const osc::PointEstimate& point : points) {
    *x = static_cast<float>(point.position_lopt.x());
    *y = static_cast<float>(point.position_lopt.y());
    *z = static_cast<float>(point.position_lopt.z());
    ++x;
    ++y;
    ++z;
  }
  return cloud;
}

namespace {

/// A sphere marker scaled and oriented as the 1-sigma ellipsoid of @p covariance.
visualization_msgs::Marker ellipsoid(const Eigen::Vector3d& center,
                                     const Eigen::Matrix3d& covariance, int id,
                                     const std_msgs::Header& header, float r, float g, float b) {
  visualization_msgs::Marker marker;
  marker.header = header;
  marker.ns = "sigma_ellipsoids";
  marker.id = id;
  marker.type = visualization_msgs::Marker::SPHERE;
  marker.action = visualization_msgs::Marker::ADD;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 *
                                                        (covariance + covariance.transpose()));
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(1e-12);
  const Eigen::Quaterniond q(axes);
  marker.pose.position.x = center.x();
  marker.pose.position.y = center.y();
  marker.pose.position.z = center.z();
  marker.pose.orientation.w = q.w();
  marker.pose.orientation.x = q.x();
  marker.pose.orientation.y = q.y();
  marker.pose.orientation.z = q.z();
  marker.scale.x = 2.0 * std::sqrt(values(0));
  marker.scale.y = 2.0 * std::sqrt(values(1));
  marker.scale.z = 2.0 * std::sqrt(values(2));
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = 0.5f;
  return marker;
}

visualization_msgs::Marker label(const Eigen::Vector3d& position, const std::string& text, int id,
                                 const std_msgs::Header& header) {
  visualization_msgs::Marker marker;
  marker.header = header;
  marker.ns = "labels";
  marker.id = id;
  marker.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.position.x = position.x();
  marker.pose.position.y = position.y();
  marker.pose.position.z = position.z() + 0.1;
  marker.pose.orientation.w = 1.0;
  marker.scale.z = 0.12;  // m, readable from a few metres
  marker.color.r = marker.color.g = marker.color.b = marker.color.a = 1.0f;
  marker.text = text;
  return marker;
}

}  // namespace

visualization_msgs::MarkerArray makeMarkers(const osc::CalibrationEstimate& estimate,
                                            const std_msgs::Header& header) {
  visualization_msgs::MarkerArray markers;
  const Eigen::Isometry3d& T_veh_caml = estimate.extrinsics.T_veh_caml;
  const Eigen::Vector3d left = T_veh_caml.translation();
  const Eigen::Vector3d right = T_veh_caml * estimate.extrinsics.T_caml_camr.translation();
  const Eigen::Matrix3d cov_left = estimate.parameter_covariance.block<3, 3>(0, 0);
  // Right origin: left origin plus the rotated baseline (rotation uncertainty of the left
  // camera neglected in this display).
  const Eigen::Matrix3d R = T_veh_caml.linear();
  const Eigen::Matrix3d cov_right =
      cov_left + R * estimate.parameter_covariance.block<3, 3>(6, 6) * R.transpose() +
      estimate.parameter_covariance.block<3, 3>(0, 6) * R.transpose() +
      R * estimate.parameter_covariance.block<3, 3>(6, 0);
  const osc::Vector12d sigma = estimate.sigmas();
  markers.markers.push_back(ellipsoid(left, cov_left, 0, header, 0.2f, 0.8f, 0.2f));
  markers.markers.push_back(ellipsoid(right, cov_right, 1, header, 0.2f, 0.4f, 1.0f));
  char text[128];
  std::snprintf(text, sizeof(text), "left (1s: %.1f %.1f %.1f mm)", 1e3 * sigma(0), 1e3 * sigma(1),
                1e3 * sigma(2));
  markers.markers.push_back(label(left, text, 0, header));
  std::snprintf(text, sizeof(text), "right (1s: %.1f %.1f %.1f mm)", 1e3 * sigma(6), 1e3 * sigma(7),
                1e3 * sigma(8));
  markers.markers.push_back(label(right, text, 1, header));
  return markers;
}

OutputPublisher::OutputPublisher(ros::NodeHandle& /*nh*/, ros::NodeHandle& private_nh,
                                 bool publish_tf)
    : publish_tf_(publish_tf) {
  calibration_pub_ = private_nh.advertise<StereoCalibration>("calibration", 10);
  points_pub_ = private_nh.advertise<sensor_msgs::PointCloud2>("tracked_points", 2);
  markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("markers", 2);
  left_info_pub_ = private_nh.advertise<sensor_msgs::CameraInfo>("left/camera_info", 10);
  right_info_pub_ = private_nh.advertise<sensor_msgs::CameraInfo>("right/camera_info", 10);
  image_transport::ImageTransport it(private_nh);
  debug_pub_ = it.advertise("debug_image", 1);
}

bool OutputPublisher::publishCalibration(const StereoCalibration& message,
                                         const osc::CalibrationEstimate& estimate) {
  for (double v : message.parameters) {
    if (!std::isfinite(v)) return false;
  }
  for (double v : message.covariance) {
    if (!std::isfinite(v)) return false;
  }
  if (publish_tf_) {
    std::vector<geometry_msgs::TransformStamped> transforms(2);
    transforms[0].header = message.header;
    transforms[0].child_frame_id = message.left_frame_id;
    transforms[0].transform = message.vehicle_to_left;
    transforms[1].header.stamp = message.header.stamp;
    transforms[1].header.frame_id = message.left_frame_id;
    transforms[1].child_frame_id = message.right_frame_id;
    transforms[1].transform = message.left_to_right;
    broadcaster_.sendTransform(transforms);
  }
  calibration_pub_.publish(message);
  if (markers_pub_.getNumSubscribers() > 0) {
    markers_pub_.publish(makeMarkers(estimate, message.header));
  }
  return true;
}

void OutputPublisher::publishPoints(const std::vector<osc::PointEstimate>& points,
                                    const std_msgs::Header& header) {
  if (points_pub_.getNumSubscribers() == 0) return;
  points_pub_.publish(makePointCloud(points, header));
}

void OutputPublisher::publishRectifiedCameraInfo(const sensor_msgs::CameraInfo& left_input,
                                                 const sensor_msgs::CameraInfo& right_input,
                                                 const osc::StereoRectification& rectification) {
  left_info_pub_.publish(
      rectifiedCameraInfo(left_input, rectification.R_left, rectification.P_left));
  right_info_pub_.publish(
      rectifiedCameraInfo(right_input, rectification.R_right, rectification.P_right));
}

bool OutputPublisher::debugImageWanted() const { return debug_pub_.getNumSubscribers() > 0; }

void OutputPublisher::publishDebugImage(const cv::Mat& bgr, const std_msgs::Header& header) {
  if (bgr.empty()) return;
  debug_pub_.publish(cv_bridge::CvImage(header, "bgr8", bgr).toImageMsg());
}

}  // namespace online_stereo_calibration
