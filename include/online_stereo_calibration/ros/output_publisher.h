/// @file output_publisher.h
/// @brief Everything the nodelet publishes after an image pair: /tf, ~calibration,
/// ~tracked_points, ~debug_image (only when subscribed), ~markers and the rectified
/// ~left/camera_info, ~right/camera_info.
#pragma once

#include <string>
#include <vector>

#include <image_transport/image_transport.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>
#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/StereoCalibration.h"
#include "online_stereo_calibration/core/estimator/convergence.h"
#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/pipeline/live_rectification.h"

namespace online_stereo_calibration {

/// Frame names of one published calibration.
struct OutputFrames {
  std::string vehicle;        ///< vehicle frame (parent)
  std::string left_optical;   ///< left optical frame
  std::string right_optical;  ///< right optical frame
};

/// INITIALIZING / CONVERGING / CONVERGED / DIVERGED (StereoCalibration.msg). CONVERGED:
/// osc::isConverged.
/// @param jump_detected the filter reported a sudden calibration change in this step.
uint8_t calibrationState(const osc::CalibrationEstimate& estimate, bool jump_detected,
                         int min_tracked_points, const osc::ConvergenceThresholds& thresholds);

/// The ~calibration message of one estimate (pure: the transforms are computed from the
/// estimate's extrinsics under interface.md's conventions).
StereoCalibration makeCalibrationMessage(const osc::CalibrationEstimate& estimate,
                                         const ros::Time& stamp, const OutputFrames& frames,
                                         uint8_t state, double processing_time);

/// Sets the quality fields of @p message (rectification_error -1 when the pair had no stereo
/// pair; StereoCalibration.msg).
void setQualityFields(const osc::CalibrationQuality& quality, StereoCalibration* message);

/// The tracked points as an x, y, z float32 cloud in the left optical frame.
sensor_msgs::PointCloud2 makePointCloud(const std::vector<osc::PointEstimate>& points,
                                        const std_msgs::Header& header);

/// 1-sigma ellipsoids of both camera origins (vehicle frame) and their labels.
visualization_msgs::MarkerArray makeMarkers(const osc::CalibrationEstimate& estimate,
                                            const std_msgs::Header& header);

/// Owns the publishers. Call from one thread.
class OutputPublisher {
 public:
  /// @param nh public node handle (tf); @param private_nh the nodelet's private handle.
  OutputPublisher(ros::NodeHandle& nh, ros::NodeHandle& private_nh, bool publish_tf);

  /// Publishes tf, ~calibration and ~markers. Returns false (nothing published) if the
  /// message holds a non-finite number.
  bool publishCalibration(const StereoCalibration& message,
                          const osc::CalibrationEstimate& estimate);
  /// Publishes ~tracked_points.
  void publishPoints(const std::vector<osc::PointEstimate>& points, const std_msgs::Header& header);
  /// Publishes ~left/camera_info and ~right/camera_info: the inputs with R and P of
  /// @p rectification (one pair of CameraInfo per processed image pair).
  void publishRectifiedCameraInfo(const sensor_msgs::CameraInfo& left_input,
                                  const sensor_msgs::CameraInfo& right_input,
                                  const osc::StereoRectification& rectification);
  /// True if anyone subscribes to ~debug_image (render it only then).
  bool debugImageWanted() const;
  /// Publishes a BGR debug image.
  void publishDebugImage(const cv::Mat& bgr, const std_msgs::Header& header);

 private:
  bool publish_tf_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Publisher calibration_pub_;
  ros::Publisher points_pub_;
  ros::Publisher markers_pub_;
  ros::Publisher left_info_pub_, right_info_pub_;
  image_transport::Publisher debug_pub_;
};

}  // namespace online_stereo_calibration
