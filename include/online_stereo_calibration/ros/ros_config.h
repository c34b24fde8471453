/// @file ros_config.h
/// @brief The ROS adapter's own parameters (frames, synchronisation, motion source,
/// initial guess, saving, convergence thresholds), each with its doc line and default.
/// The estimator's parameters are FilterConfig (core/config/filter_config.h).
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/estimator/convergence.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace online_stereo_calibration {

/// Where the initial guess comes from.
enum class InitialGuessSource {
  kParameters,  ///< the `vehicle_to_left` and `left_to_right` parameters
  kFile,        ///< a calibration file (`initial_guess_file`)
  kTf,          ///< tf at start: vehicle frame -> left optical -> right optical
};

/// Where the vehicle motion comes from.
enum class MotionSourceType {
  kOdom,  ///< nav_msgs/Odometry on `odom`
  kTf,    ///< tf, `fixed_frame` -> `vehicle_frame`
};

/// Parameters of the ROS adapter (config/ros.yaml documents every key).
struct RosConfig {
  std::string vehicle_frame = "base_link";  ///< parent of the published left optical frame
  std::string left_optical_frame;           ///< "" = frame_id of the left image
  std::string right_optical_frame;          ///< "" = frame_id of the right image
  bool publish_tf = true;                   ///< publish the two transforms on /tf

  bool approximate_sync = false;  ///< ApproximateTime instead of ExactTime pairing
  int queue_size = 10;            ///< message_filters queue size
  int processing_queue_size = 2;  ///< image pairs waiting for the worker; oldest dropped
  double max_stamp_skew = 0.005;  ///< s, left/right stamp difference that is warned about

  MotionSourceType motion_source = MotionSourceType::kOdom;
  std::string fixed_frame = "odom";  ///< fixed frame for motion_source tf
  bool use_imu = false;              ///< rotation from `imu` angular rate, translation from odom/tf
  /// The motion noise of each increment from the odometry's twist covariances (motion_source
  /// odom without use_imu; PoseBuffer::incrementCovariance) instead of the configured one.
  bool use_odometry_covariance = false;
  double motion_history = 10.0;  ///< s of odometry / IMU kept
  double max_motion_gap = 0.5;   ///< s, largest gap between bracketing motion samples
  double motion_wait = 0.3;      ///< s to wait for a motion sample after an image pair

  InitialGuessSource initial_guess_source = InitialGuessSource::kParameters;
  osc::Vector6d vehicle_to_left = osc::Vector6d::Zero();  ///< xl..yaw_l (m, rad)
  osc::Vector6d left_to_right = osc::Vector6d::Zero();    ///< xr..yaw_r (m, rad)
  std::string initial_guess_file;                         ///< for initial_guess_source file
  double tf_guess_timeout = 2.0;  ///< s to wait for tf at start (initial_guess_source tf)
  std::string calibration_file;   ///< where the result is saved ("" = never saved)
  bool resume = false;            ///< start from calibration_file (guess and sigmas) if it exists
  double save_interval = 60.0;    ///< s between periodic saves (0 = only on shutdown/service)

  int min_tracked_points = 10;  ///< fewer points: INITIALIZING, diagnostics warn
  /// CONVERGED: every parameter's 3-sigma below these (per block; values a good drive
  /// reaches: docs/ros.md), except x_caml translations the motion does not determine.
  osc::ConvergenceThresholds converged;
  double min_rate = 1.0;    ///< Hz, input rates below are warned about
  double max_rate = 100.0;  ///< Hz, input rates above are warned about

  // Rectified camera_info (~left/camera_info, ~right/camera_info) from the current estimate.
  bool publish_rectification = true;  ///< publish the pair of rectified camera_info
  /// cv::stereoRectify's free scaling: 0 = only valid pixels, 1 = all pixels, -1 = default.
  double rectification_alpha = 0.0;
  int rectification_width = 0;   ///< px, rectified image width; 0 = the input's
  int rectification_height = 0;  ///< px, rectified image height; 0 = the input's
  /// px: R and P are recomputed only when the estimate moved the rectified images by more
  /// (osc::rectificationChangePx).
  double rectification_update_px = 0.1;

  /// Every problem, each naming the parameter, its value and what is allowed.
  std::vector<std::string> validate() const;
};

}  // namespace online_stereo_calibration
