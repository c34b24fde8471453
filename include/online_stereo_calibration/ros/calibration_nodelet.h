/// @file calibration_nodelet.h
/// @brief The nodelet online_stereo_calibration/CalibrationNodelet: synchronises the stereo
/// pair, hands it with the measured motion to osc::CalibrationPipeline on one worker
/// thread, and publishes the result. It only adapts: no estimation logic here.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <nodelet/nodelet.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/ros/calibration_diagnostics.h"
#include "online_stereo_calibration/ros/motion_source.h"
#include "online_stereo_calibration/ros/output_publisher.h"
#include "online_stereo_calibration/ros/param_loader.h"

namespace online_stereo_calibration {

/// The calibration nodelet (see docs/ros.md for topics, parameters and services).
class CalibrationNodelet : public nodelet::Nodelet {
 public:
  CalibrationNodelet() = default;
  ~CalibrationNodelet() override;

 private:
  /// One synchronised stereo pair waiting for the worker.
  struct StereoPair {
    sensor_msgs::ImageConstPtr left, right;
    sensor_msgs::CameraInfoConstPtr left_info, right_info;
  };
  using ExactPolicy =
      message_filters::sync_policies::ExactTime<sensor_msgs::Image, sensor_msgs::CameraInfo,
                                                sensor_msgs::Image, sensor_msgs::CameraInfo>;
  using ApproximatePolicy =
      message_filters::sync_policies::ApproximateTime<sensor_msgs::Image, sensor_msgs::CameraInfo,
                                                      sensor_msgs::Image, sensor_msgs::CameraInfo>;

  void onInit() override;
  void pairCallback(const sensor_msgs::ImageConstPtr& left,
                    const sensor_msgs::CameraInfoConstPtr& left_info,
                    const sensor_msgs::ImageConstPtr& right,
                    const sensor_msgs::CameraInfoConstPtr& right_info);
  void workerLoop();
  void processPair(const StereoPair& pair);
  /// Publishes ~left/camera_info and ~right/camera_info for a processed pair: R and P of the
  /// current estimate (recomputed only past rectification_update_px).
  void publishRectification(const StereoPair& pair, const osc::StereoExtrinsics& estimate);
  /// Creates or re-creates the pipeline for new intrinsics; false (pair refused, reported) if
  /// they are unusable or do not describe the images.
  bool preparePipeline(const StereoPair& pair, const cv::Mat& left_image,
                       const cv::Mat& right_image);
  /// Waits up to motion_wait for the motion; false (pair skipped) if it does not come.
  bool waitForMotion(const ros::Time& stamp, osc::MotionIncrement* motion);
  bool resetService(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool saveService(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  /// Writes the current estimate to calibration_file; false with @p error on failure.
  bool saveCalibration(std::string* error);
  /// The initial guess (and tangent covariance if it comes from a file with sigmas).
  void loadInitialGuess();
  /// Initial guess and covariance from a calibration file: its full covariance if it has
  /// one, else diag(sigmas^2), else the configured initial sigmas. @p verb starts the
  /// description shown in diagnostics ("resumed from", "from").
  void seedFromFile(const std::string& path, const std::string& verb);

  NodeConfig config_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<MotionSource> motion_;
  std::unique_ptr<OutputPublisher> output_;
  std::unique_ptr<CalibrationDiagnostics> diagnostics_;

  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::SubscriberFilter left_sub_, right_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> left_info_sub_, right_info_sub_;
  std::unique_ptr<message_filters::Synchronizer<ExactPolicy>> exact_sync_;
  std::unique_ptr<message_filters::Synchronizer<ApproximatePolicy>> approximate_sync_;
  ros::ServiceServer reset_srv_, save_srv_;
  ros::Timer diagnostics_timer_, save_timer_;

  // Worker queue.
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<StereoPair> queue_;
  bool stopping_ = false;
  int dropped_pairs_ = 0;
  std::thread worker_;

  // Estimator state (pipeline_mutex_: worker vs services and timers).
  std::mutex pipeline_mutex_;
  std::unique_ptr<osc::CalibrationPipeline> pipeline_;
  osc::StereoExtrinsics initial_guess_;
  std::optional<osc::Matrix12d> initial_covariance_;  ///< tangent space
  std::string initial_guess_description_;
  bool resumed_ = false;  ///< the guess came from calibration_file (resume)
  std::optional<osc::CalibrationEstimate> last_estimate_;
  ros::Time last_stamp_;
  ros::Time last_saved_stamp_;
  osc::CameraIntrinsics left_intrinsics_, right_intrinsics_;
  /// R and P of the published ~left/camera_info, ~right/camera_info; quality figures.
  std::unique_ptr<osc::LiveRectification> rectification_;
  OutputFrames frames_;
};

}  // namespace online_stereo_calibration
