/// @file motion_source.h
/// @brief The vehicle motion between two image stamps from odometry (nav_msgs/Odometry,
/// interpolated) or tf (fixed frame -> vehicle frame), optionally with the rotation from
/// an IMU's angular rate. Thread-safe: callbacks on the nodelet's queue, lookups from the
/// worker thread.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <tf2_ros/buffer.h>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/ros/motion_buffers.h"
#include "online_stereo_calibration/ros/ros_config.h"

namespace online_stereo_calibration {

/// Subscribes to what the configuration asks for and answers motion lookups.
class MotionSource {
 public:
  /// @param tf a buffer fed by a listener (used for motion_source tf).
  MotionSource(ros::NodeHandle& nh, const RosConfig& config, tf2_ros::Buffer* tf);

  /// T_prev_curr and dt between two stamps (prev < curr).
  LookupStatus motionBetween(const ros::Time& previous, const ros::Time& current,
                             osc::MotionIncrement* motion);
  /// Whether the vehicle pose at @p stamp is known.
  LookupStatus poseAvailable(const ros::Time& stamp);
  /// A new time line (the images went back in time): forgets the history but keeps the
  /// odometry already held back as the start of the new one (PoseBuffer::restart()).
  void restart();

  /// Called for each accepted odometry / imu sample (frequency diagnostics).
  std::function<void()> on_odom;
  std::function<void()> on_imu;
  /// Called with a reason for each ignored sample (non-finite, out of order, a single
  /// sample far in the past) and with a description when odometry time jumped back for good
  /// (PoseBuffer::offer(): a bag loop; the history then restarts from the new samples).
  std::function<void(const std::string& kind, const std::string& message)> on_problem;
  /// Samples ignored (non-finite, duplicated or out-of-order stamps).
  std::atomic<int> rejected_samples{0};
  /// Odometry samples used without their twist (not finite, or unset: unsetTwistProblem);
  /// increments touching them get no twists (the time offset then uses the trend).
  std::atomic<int> samples_without_twist{0};

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& message);
  void imuCallback(const sensor_msgs::Imu::ConstPtr& message);
  LookupStatus poseAt(const ros::Time& stamp, Eigen::Isometry3d* pose);
  /// Counts a sample without twist and says why when the reason starts or changes.
  void reportTwist(const std::string& problem);

  RosConfig config_;
  tf2_ros::Buffer* tf_;
  std::mutex mutex_;
  PoseBuffer poses_;
  GyroIntegrator gyro_;
  ros::Subscriber odom_sub_;
  ros::Subscriber imu_sub_;
  std::string last_twist_problem_;  ///< odometry callback only
};

}  // namespace online_stereo_calibration
