/// @file calibration_nodelet_processing.cpp
/// @brief CalibrationNodelet's pairs: queued by the synchroniser, processed on the worker
/// thread (images, the pipeline's start, the motion, the estimate) and published.
#include "online_stereo_calibration/ros/calibration_nodelet.h"

#include <algorithm>
#include <chrono>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

#include "online_stereo_calibration/ros/conversions.h"

namespace online_stereo_calibration {
namespace {

/// Image -> cv::Mat in an encoding the pipeline takes; empty with @p error if unsupported.
cv_bridge::CvImageConstPtr toPipelineImage(const sensor_msgs::ImageConstPtr& image,
                                           std::string* error) {
  namespace enc = sensor_msgs::image_encodings;
  try {
    const std::string& e = image->encoding;
    const bool supported = e == enc::MONO8 || e == enc::MONO16 || e == enc::BGR8 ||
                           e == enc::BGRA8 || e == enc::RGB8 || e == enc::RGBA8;
    if (!supported) {
      *error = "unsupported image encoding '" + e + "'";
      return nullptr;
    }
    *error = imageBufferProblem(*image, enc::numChannels(e) * enc::bitDepth(e) / 8);
    if (!error->empty()) return nullptr;
    if (e == enc::RGB8) return cv_bridge::toCvShare(image, enc::BGR8);
    if (e == enc::RGBA8) return cv_bridge::toCvShare(image, enc::BGRA8);
    return cv_bridge::toCvShare(image);
  } catch (const cv_bridge::Exception& exception) {
    *error = std::string("cv_bridge: ") + exception.what();
  }
  return nullptr;
}

}  // namespace

void CalibrationNodelet::pairCallback(const sensor_msgs::ImageConstPtr& left,
                                      const sensor_msgs::CameraInfoConstPtr& left_info,
                                      const sensor_msgs::ImageConstPtr& right,
                                      const sensor_msgs::CameraInfoConstPtr& right_info) {
  diagnostics_->tickPair();
  bool dropped = false;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back({left, right, left_info, right_info});
    while (static_cast<int>(queue_.size()) > config_.ros.processing_queue_size) {
      queue_.pop_front();
      ++dropped_pairs_;
      dropped = true;
    }
  }
  queue_cv_.notify_one();
  if (dropped) {
    diagnostics_->recordProblem("dropped pairs", "processing fell behind: oldest pair dropped");
    NODELET_WARN_THROTTLE(
        5.0, "online_stereo_calibration: processing fell behind, %d pairs dropped", dropped_pairs_);
  }
}

void CalibrationNodelet::workerLoop() {
  while (true) {
    StereoPair pair;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [this]() { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      pair = queue_.front();
      queue_.pop_front();
    }
    try {
      processPair(pair);
    } catch (const std::exception& e) {
      diagnostics_->recordProblem("processing errors", e.what());
      NODELET_ERROR_THROTTLE(5.0, "online_stereo_calibration: pair skipped: %s", e.what());
    }
  }
}

bool CalibrationNodelet::preparePipeline(const StereoPair& pair, const cv::Mat& left_image,
                                         const cv::Mat& right_image) {
  osc::CameraIntrinsics left, right;
  try {
    left = intrinsicsFromCameraInfo(*pair.left_info);
    right = intrinsicsFromCameraInfo(*pair.right_info);
  } catch (const std::exception& e) {
    diagnostics_->recordProblem("bad camera_info", e.what());
    NODELET_ERROR_THROTTLE(5.0, "online_stereo_calibration: pair skipped, bad camera_info: %s",
                           e.what());
    return false;
  }
  if (left.width != right.width || left.height != right.height || left.model != right.model) {
    diagnostics_->recordProblem(
        "left/right camera_info disagree",
        "left " + std::to_string(left.width) + "x" + std::to_string(left.height) + " " +
            osc::distortionModelName(left.model) + ", right " + std::to_string(right.width) + "x" +
            std::to_string(right.height) + " " + osc::distortionModelName(right.model));
    NODELET_WARN_THROTTLE(10.0,
                          "online_stereo_calibration: left (%dx%d, %s) and right (%dx%d, %s) "
                          "camera_info differ in size or model",
                          left.width, left.height, osc::distortionModelName(left.model).c_str(),
                          right.width, right.height, osc::distortionModelName(right.model).c_str());
  }
  // A camera_info that does not describe its own image is bad input, not a new camera: refuse
  // the pair before it could restart the pipeline.
  const auto describes = [this](const osc::CameraIntrinsics& info, const cv::Mat& image,
                                const std::string& side) {
    if (image.cols == info.width && image.rows == info.height) return true;
    const std::string problem = side + " image " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + " does not match its camera_info (" +
                                std::to_string(info.width) + "x" + std::to_string(info.height) +
                                ")";
    diagnostics_->recordProblem("rejected images", problem);
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: pair skipped: %s", problem.c_str());
    return false;
  };
  if (!describes(left, left_image, "left") || !describes(right, right_image, "right")) {
    return false;
  }
  if (pipeline_ && !intrinsicsDiffer(left, left_intrinsics_) &&
      !intrinsicsDiffer(right, right_intrinsics_)) {
    return true;
  }
  frames_.vehicle = config_.ros.vehicle_frame;
  frames_.left_optical = config_.ros.left_optical_frame.empty() ? pair.left->header.frame_id
                                                                : config_.ros.left_optical_frame;
  frames_.right_optical = config_.ros.right_optical_frame.empty() ? pair.right->header.frame_id
                                                                  : config_.ros.right_optical_frame;
  osc::StereoExtrinsics guess = initial_guess_;
  std::optional<osc::Matrix12d> covariance = initial_covariance_;
  if (pipeline_) {
    NODELET_WARN(
        "online_stereo_calibration: camera_info changed, restarting the front end "
        "(calibration kept)");
    const osc::CalibrationEstimate estimate = pipeline_->estimate();
    guess = estimate.extrinsics;
    covariance = estimate.tangent_covariance;
  } else if (config_.ros.initial_guess_source == InitialGuessSource::kTf && !resumed_) {
    try {
      const ros::Duration timeout(config_.ros.tf_guess_timeout);
      const Eigen::Isometry3d T_veh_lopt = isometryFromTransform(
          tf_buffer_->lookupTransform(frames_.vehicle, frames_.left_optical, ros::Time(0), timeout)
              .transform);
      const Eigen::Isometry3d T_lopt_ropt = isometryFromTransform(
          tf_buffer_
              ->lookupTransform(frames_.left_optical, frames_.right_optical, ros::Time(0), timeout)
              .transform);
      guess = osc::StereoExtrinsics::fromOpticalFrames(T_veh_lopt, T_lopt_ropt);
    } catch (const std::exception& e) {
      diagnostics_->recordProblem("no initial guess", e.what());
      NODELET_ERROR_THROTTLE(5.0, "online_stereo_calibration: initial guess from tf: %s", e.what());
      return false;
    }
  }
  auto pipeline = std::make_unique<osc::CalibrationPipeline>(config_.filter, config_.front_end,
                                                             left, right, guess);
  if (covariance) pipeline->reset(guess, *covariance);
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  pipeline_ = std::move(pipeline);
  left_intrinsics_ = left;
  right_intrinsics_ = right;
  last_stamp_ = ros::Time();
  return true;
}

bool CalibrationNodelet::waitForMotion(const ros::Time& stamp, osc::MotionIncrement* motion) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.ros.motion_wait);
  // The odometry is read where the estimator believes the images were: at the stamps minus
  // its time-offset estimate (MotionIncrement::time_shift); unshifted where that would reach
  // before time 0.
  double shift = 0.0;
  {
    std::lock_guard<std::mutex> lock(pipeline_mutex_);
    if (pipeline_) shift = pipeline_->estimator().odometryTimeShift();
  }
  if (!last_stamp_.isZero() && std::min(last_stamp_.toSec(), stamp.toSec()) - shift <= 0.0) {
    shift = 0.0;
  }
  const ros::Duration read_shift(shift);
  LookupStatus status = LookupStatus::kEmpty;
  while (true) {
    if (last_stamp_.isZero()) {
      status = motion_->poseAvailable(stamp);
    } else {
      status = motion_->motionBetween(last_stamp_ - read_shift, stamp - read_shift, motion);
      motion->time_shift = shift;
      const bool previous_lost = status == LookupStatus::kTooOld || status == LookupStatus::kGap;
      if (previous_lost && motion_->poseAvailable(stamp) == LookupStatus::kOk) {
        // The last processed pair's pose is gone (a pause longer than motion_history, the
        // clock jumping forward): the motion since then can never be known. Start tracking
        // afresh from this pair instead of skipping every pair from now on.
        const std::string problem = "no motion from the last processed pair at " +
                                    std::to_string(last_stamp_.toSec()) + " to " +
                                    std::to_string(stamp.toSec()) + " (" +
                                    lookupStatusName(status) + "): tracks reset";
        diagnostics_->recordProblem("motion missing or late", problem);
        NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: %s", problem.c_str());
        std::lock_guard<std::mutex> lock(pipeline_mutex_);
        pipeline_->resetTracking();
        last_stamp_ = ros::Time();
        return true;  // a first pair: its motion is not used
      }
    }
    if (status == LookupStatus::kOk) return true;
    const bool may_come = status == LookupStatus::kNotYet || status == LookupStatus::kEmpty;
    if (!may_come || std::chrono::steady_clock::now() > deadline) break;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      if (queue_cv_.wait_for(lock, std::chrono::milliseconds(5), [this]() { return stopping_; })) {
        return false;
      }
    }
  }
  diagnostics_->recordProblem("motion missing or late", "no motion for the pair at " +
                                                            std::to_string(stamp.toSec()) + ": " +
                                                            lookupStatusName(status));
  NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: pair at %.6f skipped: %s", stamp.toSec(),
                        lookupStatusName(status).c_str());
  return false;
}

void CalibrationNodelet::processPair(const StereoPair& pair) {
  const ros::Time stamp = pair.left->header.stamp;
  const double skew = std::abs((pair.left->header.stamp - pair.right->header.stamp).toSec());
  if (skew > config_.ros.max_stamp_skew) {
    diagnostics_->recordProblem("stamp skew",
                                "left/right stamps differ by " + std::to_string(skew) + " s");
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: left/right stamps differ by %.6f s",
                          skew);
  }
  if (!last_stamp_.isZero() && stamp <= last_stamp_) {
    if (stamp == last_stamp_) {
      diagnostics_->recordProblem("duplicated stamps", "pair with the stamp of the previous one");
      NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: duplicated pair stamp %.6f skipped",
                            stamp.toSec());
      return;
    }
    diagnostics_->recordProblem("time went backwards",
                                "pair stamp " + std::to_string(stamp.toSec()) + " before " +
                                    std::to_string(last_stamp_.toSec()));
    NODELET_WARN("online_stereo_calibration: time went backwards (%.6f < %.6f): tracks reset",
                 stamp.toSec(), last_stamp_.toSec());
    {
      std::lock_guard<std::mutex> lock(pipeline_mutex_);
      if (pipeline_) pipeline_->resetTracking();
    }
    // Odometry that already jumped back itself (a bag loop) is kept; a history that holds
    // only later stamps cannot serve the new time line.
    if (motion_->poseAvailable(stamp) == LookupStatus::kTooOld) motion_->restart();
    last_stamp_ = ros::Time();
  }
  std::string error;
  cv_bridge::CvImageConstPtr left = toPipelineImage(pair.left, &error);
  cv_bridge::CvImageConstPtr right = left ? toPipelineImage(pair.right, &error) : nullptr;
  if (!left || !right) {
    diagnostics_->recordProblem("rejected images", error);
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: pair skipped: %s", error.c_str());
    return;
  }
  if (!preparePipeline(pair, left->image, right->image)) return;
  osc::MotionIncrement motion;
  if (!waitForMotion(stamp, &motion)) return;

  osc::PipelineResult result;
  std::vector<osc::PointEstimate> points;
  cv::Mat debug;
  {
    std::lock_guard<std::mutex> lock(pipeline_mutex_);
    result = pipeline_->process(left->image, right->image, motion);
    if (result.processed) {
      points = pipeline_->points();
      if (output_->debugImageWanted()) debug = pipeline_->debugImage();
    }
  }
  if (!result.processed) {
    // last_stamp_ stays: the next pair's motion spans from the last processed pair
    // (CalibrationPipeline::process), so the refused pair's motion is not counted twice.
    diagnostics_->recordProblem("rejected images", result.status);
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: pair skipped: %s",
                          result.status.c_str());
    return;
  }
  last_stamp_ = stamp;
  diagnostics_->tickProcessed();
  // The estimator's event log (frame_event.h): what each component did, and why the filter
  // cannot learn (issue 14), one diagnostics entry per kind.
  for (const osc::FrameEventLine& event : result.estimator.events) {
    diagnostics_->recordProblem(osc::frameEventName(event.kind), event.text);
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: %s", event.text.c_str());
  }
  if (result.right_camera_reopened) {
    NODELET_WARN("online_stereo_calibration: %s", result.status.c_str());
  }
  // A change found by the filter's jump test, or by the pipeline (a knocked right camera).
  const bool jump = result.estimator.step.jump != osc::JumpBlock::kNone ||
                    result.estimator.has(osc::FrameEvent::kRightRotationWidened) ||
                    result.right_camera_reopened;
  const uint8_t state = calibrationState(result.estimate, jump, config_.ros.min_tracked_points,
                                         config_.ros.converged);
  StereoCalibration message =
      makeCalibrationMessage(result.estimate, stamp, frames_, state, result.processing_time);
  osc::CalibrationQuality quality;
  bool have_quality = false;
  if (result.estimate.parameters.allFinite() && result.estimate.tangent_covariance.allFinite()) {
    try {
      quality = rectification_->quality(left_intrinsics_, right_intrinsics_, result.stereo_pairs,
                                        result.estimate);
      have_quality = true;
    } catch (const std::exception& e) {
      diagnostics_->recordProblem("processing errors", std::string("quality figures: ") + e.what());
    }
  }
  setQualityFields(quality, &message);
  diagnostics_->recordEstimate(result.estimate, state);
  diagnostics_->recordTempering(result.estimator.step.tempering);
  if (have_quality) diagnostics_->recordQuality(quality);
  if (!output_->publishCalibration(message, result.estimate)) {
    diagnostics_->recordProblem("non-finite estimate", "estimate not published");
    NODELET_ERROR_THROTTLE(5.0, "online_stereo_calibration: non-finite estimate not published");
    return;
  }
  if (config_.ros.publish_rectification) publishRectification(pair, result.estimate.extrinsics);
  {
    std::lock_guard<std::mutex> lock(pipeline_mutex_);
    last_estimate_ = result.estimate;
    last_saved_stamp_ = stamp;
  }
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frames_.left_optical;
  output_->publishPoints(points, header);
  if (!debug.empty()) output_->publishDebugImage(debug, header);
}

void CalibrationNodelet::publishRectification(const StereoPair& pair,
                                              const osc::StereoExtrinsics& estimate) {
  try {
    rectification_->update(left_intrinsics_, right_intrinsics_, estimate);
  } catch (const std::exception& e) {
    diagnostics_->recordProblem("processing errors", std::string("rectification: ") + e.what());
    NODELET_WARN_THROTTLE(5.0, "online_stereo_calibration: rectification: %s", e.what());
  }
  if (!rectification_->rectification()) return;
  // Stamped like the input images and both framed like the left one: R and P put both
  // cameras into the left rectified frame, and image_geometry's StereoCameraModel (used by
  // stereo_image_proc) requires one frame for the pair (Debian's build asserts on it).
  sensor_msgs::CameraInfo left_info = *pair.left_info, right_info = *pair.right_info;
  left_info.header = pair.left->header;
  right_info.header = pair.right->header;
  right_info.header.frame_id = pair.left->header.frame_id;
  output_->publishRectifiedCameraInfo(left_info, right_info, *rectification_->rectification());
}

}  // namespace online_stereo_calibration
