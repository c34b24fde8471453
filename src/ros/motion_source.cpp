/// @file motion_source.cpp
/// @brief Odometry / tf / IMU -> MotionIncrement.
#include "online_stereo_calibration/ros/motion_source.h"

#include <tf2/exceptions.h>

#include "online_stereo_calibration/ros/conversions.h"

namespace online_stereo_calibration {

MotionSource::MotionSource(ros::NodeHandle& nh, const RosConfig& config, tf2_ros::Buffer* tf)
    : config_(config),
      tf_(tf),
      poses_(config.motion_history, config.max_motion_gap),
      gyro_(config.motion_history, config.max_motion_gap) {
  if (config_.motion_source == MotionSourceType::kOdom) {
    odom_sub_ = nh.subscribe("odom", 200, &MotionSource::odomCallback, this);
  }
  if (config_.use_imu) imu_sub_ = nh.subscribe("imu", 1000, &MotionSource::imuCallback, this);
}

void MotionSource::odomCallback(const nav_msgs::Odometry::ConstPtr& message) {
  const std::string problem = poseProblem(message->pose.pose);
  if (!problem.empty()) {
    ++rejected_samples;
    const std::string why = "odometry with " + problem + " ignored";
    ROS_WARN_THROTTLE(5.0, "online_stereo_calibration: %s", why.c_str());
    if (on_problem) on_problem("rejected odometry", why);
    return;
  }
  std::string twist_problem, covariance_problem;
  StampedPose sample = odometrySample(*message, config_.use_odometry_covariance, &twist_problem,
                                      &covariance_problem);
  if (!covariance_problem.empty() && on_problem) {
    on_problem("unusable odometry covariance",
               covariance_problem + ": the configured motion noise is used for this interval");
  }
  PoseBuffer::Offered offered;
  double newest = 0.0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    newest = poses_.newestStamp();
    if (twist_problem.empty() && poses_.newest())
      twist_problem = unsetTwistProblem(sample, *poses_.newest());
    if (!twist_problem.empty()) sample.has_twist = false;
    offered = poses_.offer(sample);
    if (offered == PoseBuffer::Offered::kRestarted) gyro_.clear();
  }
  switch (offered) {
    case PoseBuffer::Offered::kAdded:
      break;
    case PoseBuffer::Offered::kRestarted: {
      // Time jumped back (a bag loop, a restarted player): a new history.
      const double back = newest - sample.stamp;
      ROS_WARN(
          "online_stereo_calibration: odometry time went back by %.3f s: motion history "
          "restarted",
          back);
      if (on_problem) {
        on_problem("time went backwards",
                   "odometry time went back by " + std::to_string(back) + " s");
      }
      break;
    }
    case PoseBuffer::Offered::kHeldBack:
    case PoseBuffer::Offered::kRejected: {
      ++rejected_samples;
      const std::string why =
          offered == PoseBuffer::Offered::kHeldBack
              ? "odometry stamp " + std::to_string(sample.stamp) + " is " +
                    std::to_string(newest - sample.stamp) +
                    " s behind the newest (a stale publisher?), ignored unless more follow"
              : "odometry stamp " + std::to_string(sample.stamp) +
                    " not newer than the last one, ignored";
      ROS_WARN_THROTTLE(5.0, "online_stereo_calibration: %s", why.c_str());
      if (on_problem) on_problem("rejected odometry", why);
      return;
    }
  }
  reportTwist(twist_problem);
  if (on_odom) on_odom();
}

void MotionSource::reportTwist(const std::string& problem) {
  const bool changed = problem != last_twist_problem_;
  last_twist_problem_ = problem;
  if (problem.empty()) return;
  ++samples_without_twist;
  const std::string why =
      "odometry " + problem + ": the time offset uses the trend of earlier increments there";
  // Counted in the diagnostics for every sample; logged when it starts or changes, not for
  // every sample of an odometry without twists.
  if (changed) ROS_WARN("online_stereo_calibration: %s", why.c_str());
  if (on_problem) on_problem("odometry without twist", why);
}

void MotionSource::imuCallback(const sensor_msgs::Imu::ConstPtr& message) {
  const Eigen::Vector3d rate(message->angular_velocity.x, message->angular_velocity.y,
                             message->angular_velocity.z);
  bool added = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    added = gyro_.add(message->header.stamp.toSec(), rate);
  }
  if (!added) {
    ++rejected_samples;
    ROS_WARN_THROTTLE(5.0,
                      "online_stereo_calibration: imu sample non-finite or out of order, ignored");
    if (on_problem) on_problem("rejected imu", "imu sample non-finite or out of order, ignored");
    return;
  }
  if (on_imu) on_imu();
}

LookupStatus MotionSource::poseAt(const ros::Time& stamp, Eigen::Isometry3d* pose) {
  if (config_.motion_source == MotionSourceType::kTf) {
    try {
      const geometry_msgs::TransformStamped transform =
          tf_->lookupTransform(config_.fixed_frame, config_.vehicle_frame, stamp);
      *pose = isometryFromTransform(transform.transform);
      return pose->matrix().allFinite() ? LookupStatus::kOk : LookupStatus::kGap;
    } catch (const tf2::TransformException&) {
      return LookupStatus::kNotYet;
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_.poseAt(stamp.toSec(), pose);
}

LookupStatus MotionSource::poseAvailable(const ros::Time& stamp) {
  Eigen::Isometry3d pose;
  return poseAt(stamp, &pose);
}

LookupStatus MotionSource::motionBetween(const ros::Time& previous, const ros::Time& current,
                                         osc::MotionIncrement* motion) {
  Eigen::Isometry3d pose_previous, pose_current;
  LookupStatus status = poseAt(current, &pose_current);
  if (status != LookupStatus::kOk) return status;
  status = poseAt(previous, &pose_previous);
  if (status != LookupStatus::kOk) return status;
  motion->T_prev_curr = pose_previous.inverse() * pose_current;
  motion->dt = (current - previous).toSec();
  motion->has_covariance = false;
  // The odometry's own twists at both stamps for the time offset (tf has none: the filter
  // then takes the trend of the earlier increments).
  motion->has_twists = false;
  if (config_.motion_source == MotionSourceType::kOdom) {
    std::lock_guard<std::mutex> lock(mutex_);
    motion->has_twists = poses_.twistAt(previous.toSec(), &motion->twist_start) &&
                         poses_.twistAt(current.toSec(), &motion->twist_end);
  }
  if (config_.use_odometry_covariance && config_.motion_source == MotionSourceType::kOdom &&
      !config_.use_imu) {
    std::lock_guard<std::mutex> lock(mutex_);
    motion->has_covariance =
        poses_.incrementCovariance(previous.toSec(), current.toSec(), &motion->covariance);
  }
  if (config_.use_imu) {
    Eigen::Matrix3d rotation;
    std::lock_guard<std::mutex> lock(mutex_);
    status = gyro_.rotationBetween(previous.toSec(), current.toSec(), &rotation);
    if (status != LookupStatus::kOk) return status;
    motion->T_prev_curr.linear() = rotation;
  }
  return LookupStatus::kOk;
}

void MotionSource::restart() {
  std::lock_guard<std::mutex> lock(mutex_);
  poses_.restart();
  gyro_.clear();
}

}  // namespace online_stereo_calibration
