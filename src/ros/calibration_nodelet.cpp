/// @file calibration_nodelet.cpp
/// @brief CalibrationNodelet: start-up (parameters, initial guess, subscriptions), services,
/// saving; the pairs' processing in calibration_nodelet_processing.cpp. Adapts only.
#include "online_stereo_calibration/ros/calibration_nodelet.h"

#include <fstream>
#include <sstream>

#include <pluginlib/class_list_macros.hpp>

#include "online_stereo_calibration/ros/conversions.h"
#include "online_stereo_calibration/tools/calibration_file.h"

namespace online_stereo_calibration {

CalibrationNodelet::~CalibrationNodelet() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  if (!config_.ros.calibration_file.empty()) {
    std::string error;
    if (!saveCalibration(&error) && !error.empty()) {
      NODELET_ERROR("online_stereo_calibration: saving on shutdown failed: %s", error.c_str());
    }
  }
}

void CalibrationNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& pnh = getPrivateNodeHandle();
  std::vector<std::string> problems;
  config_ = loadNodeConfig(pnh, &problems);
  if (problems.empty()) {
    try {
      loadInitialGuess();
    } catch (const std::exception& e) {
      problems.push_back(e.what());
    }
  }
  if (!problems.empty()) {
    std::ostringstream out;
    out << "invalid configuration (" << problems.size() << " problems):";
    for (const std::string& problem : problems) out << "\n  - " << problem;
    NODELET_FATAL("%s", out.str().c_str());
    config_.ros.calibration_file.clear();  // nothing to save
    throw std::runtime_error(out.str());
  }

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(config_.ros.motion_history + 5.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  diagnostics_ = std::make_unique<CalibrationDiagnostics>(nh, pnh, config_.ros);
  motion_ = std::make_unique<MotionSource>(nh, config_.ros, tf_buffer_.get());
  motion_->on_odom = [this]() { diagnostics_->tickOdom(); };
  motion_->on_problem = [this](const std::string& kind, const std::string& message) {
    diagnostics_->recordProblem(kind, message);
  };
  diagnostics_->setInitialGuess(initial_guess_description_);
  output_ = std::make_unique<OutputPublisher>(nh, pnh, config_.ros.publish_tf);
  osc::RectificationSettings rectification;
  rectification.alpha = config_.ros.rectification_alpha;
  rectification.width = config_.ros.rectification_width;
  rectification.height = config_.ros.rectification_height;
  rectification_ =
      std::make_unique<osc::LiveRectification>(rectification, config_.ros.rectification_update_px);

  reset_srv_ = pnh.advertiseService("reset", &CalibrationNodelet::resetService, this);
  save_srv_ = pnh.advertiseService("save_calibration", &CalibrationNodelet::saveService, this);
  diagnostics_timer_ = nh.createTimer(ros::Duration(0.5),
                                      [this](const ros::TimerEvent&) { diagnostics_->update(); });
  if (config_.ros.save_interval > 0.0 && !config_.ros.calibration_file.empty()) {
    save_timer_ =
        nh.createTimer(ros::Duration(config_.ros.save_interval), [this](const ros::TimerEvent&) {
          std::string error;
          if (!saveCalibration(&error) && !error.empty()) {
            NODELET_WARN("online_stereo_calibration: periodic save failed: %s", error.c_str());
          }
        });
  }

  worker_ = std::thread(&CalibrationNodelet::workerLoop, this);

  it_ = std::make_unique<image_transport::ImageTransport>(nh);
  const int q = config_.ros.queue_size;
  left_sub_.subscribe(*it_, "left/image_raw", q);
  right_sub_.subscribe(*it_, "right/image_raw", q);
  left_info_sub_.subscribe(nh, "left/camera_info", q);
  right_info_sub_.subscribe(nh, "right/camera_info", q);
  // Count each input before pairing: images without camera_info never reach pairCallback.
  left_sub_.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr&) { diagnostics_->tickInput(true, false); }));
  right_sub_.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr&) { diagnostics_->tickInput(false, false); }));
  left_info_sub_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const sensor_msgs::CameraInfoConstPtr&) { diagnostics_->tickInput(true, true); }));
  right_info_sub_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const sensor_msgs::CameraInfoConstPtr&) { diagnostics_->tickInput(false, true); }));
  if (config_.ros.approximate_sync) {
    approximate_sync_ = std::make_unique<message_filters::Synchronizer<ApproximatePolicy>>(
        ApproximatePolicy(q), left_sub_, left_info_sub_, right_sub_, right_info_sub_);
    approximate_sync_->registerCallback(&CalibrationNodelet::pairCallback, this);
  } else {
    exact_sync_ = std::make_unique<message_filters::Synchronizer<ExactPolicy>>(
        ExactPolicy(q), left_sub_, left_info_sub_, right_sub_, right_info_sub_);
    exact_sync_->registerCallback(&CalibrationNodelet::pairCallback, this);
  }
  NODELET_INFO("online_stereo_calibration: ready (vehicle frame %s, %s sync)",
               config_.ros.vehicle_frame.c_str(),
               config_.ros.approximate_sync ? "approximate" : "exact");
}

void CalibrationNodelet::loadInitialGuess() {
  const RosConfig& ros_config = config_.ros;
  if (ros_config.resume) {
    std::ifstream probe(ros_config.calibration_file);
    if (probe.good()) {
      seedFromFile(ros_config.calibration_file, "resumed from");
      resumed_ = true;
      NODELET_INFO("online_stereo_calibration: %s", initial_guess_description_.c_str());
      return;
    }
    NODELET_WARN("online_stereo_calibration: resume: %s does not exist, using the initial guess",
                 ros_config.calibration_file.c_str());
  }
  switch (ros_config.initial_guess_source) {
    case InitialGuessSource::kParameters: {
      osc::Vector12d parameters;
      parameters << ros_config.vehicle_to_left, ros_config.left_to_right;
      initial_guess_ = osc::StereoExtrinsics::fromParameters(parameters);
      initial_guess_description_ = "from parameters, covariance from the configured sigmas";
      break;
    }
    case InitialGuessSource::kFile: {
      seedFromFile(ros_config.initial_guess_file, "from");
      break;
    }
    case InitialGuessSource::kTf:
      // Looked up at the first pair, when the optical frames are known.
      initial_guess_description_ = "from tf, covariance from the configured sigmas";
      break;
  }
}

void CalibrationNodelet::seedFromFile(const std::string& path, const std::string& verb) {
  const osc::CalibrationFile file = osc::readCalibrationFile(path);
  initial_guess_ = file.extrinsics;
  initial_covariance_.reset();
  const std::optional<osc::Matrix12d> covariance = osc::parameterCovariance(file);
  if (covariance) {
    initial_covariance_ = tangentCovarianceFromParameterCovariance(file.extrinsics, *covariance);
  }
  initial_guess_description_ =
      verb + " " + path + ", " +
      (file.covariance ? "full 12x12 covariance"
       : file.sigmas   ? "diagonal covariance from its sigmas (no covariance key)"
                       : "covariance from the configured sigmas (file has none)");
}

bool CalibrationNodelet::resetService(std_srvs::Trigger::Request&,
                                      std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  if (pipeline_) {
    if (initial_covariance_) {
      pipeline_->reset(initial_guess_, *initial_covariance_);
    } else {
      pipeline_->reset(initial_guess_);
    }
  }
  last_estimate_.reset();
  diagnostics_->recordReset();
  response.success = true;
  response.message = "calibration reset to the initial guess";
  NODELET_INFO("online_stereo_calibration: %s", response.message.c_str());
  return true;
}

bool CalibrationNodelet::saveService(std_srvs::Trigger::Request&,
                                     std_srvs::Trigger::Response& response) {
  std::string error;
  response.success = saveCalibration(&error);
  response.message = response.success ? "saved to " + config_.ros.calibration_file : error;
  return true;
}

bool CalibrationNodelet::saveCalibration(std::string* error) {
  if (config_.ros.calibration_file.empty()) {
    *error = "calibration_file is not set";
    return false;
  }
  osc::CalibrationFile file;
  {
    std::lock_guard<std::mutex> lock(pipeline_mutex_);
    if (!last_estimate_) {
      *error = "";
      if (!pipeline_) *error = "no estimate yet";
      if (!pipeline_) return false;
      last_estimate_ = pipeline_->estimate();
    }
    file.extrinsics = last_estimate_->extrinsics;
    file.sigmas = last_estimate_->sigmas();
    file.covariance = last_estimate_->parameter_covariance;
    file.stamp = last_saved_stamp_.toSec();
    if (last_estimate_->time_offset_sigma > 0.0) {
      file.time_offset = last_estimate_->time_offset;
      file.time_offset_sigma = last_estimate_->time_offset_sigma;
    }
  }
  try {
    osc::writeCalibrationFileAtomic(config_.ros.calibration_file, file);
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  return true;
}

}  // namespace online_stereo_calibration

PLUGINLIB_EXPORT_CLASS(online_stereo_calibration::CalibrationNodelet, nodelet::Nodelet)
