/// @file rostest_helpers.h
/// @brief Shared by the rostests in test/ros: collectors for /diagnostics and ~calibration,
/// a textured synthetic image source, and a rendered drive (the core renderer through
/// osc::DriveSimulator, the same one `simulate` writes to bags) published as the node's
/// inputs in lockstep with its output.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "../../src/tools/ros/bag_io.h"
#include "online_stereo_calibration/StereoCalibration.h"
#include "online_stereo_calibration/core/geometry/stereo_rectification.h"
#include "online_stereo_calibration/tools/drive_simulation.h"
#include "online_stereo_calibration/tools/scenario_file.h"

namespace osc_test {

using online_stereo_calibration::StereoCalibration;

/// Spins (single-threaded) until @p done or @p timeout wall seconds; returns done().
inline bool spinUntil(const std::function<bool()>& done, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.002).sleep();
  }
  ros::spinOnce();
  return done();
}

/// Every "...: calibration" status published on /diagnostics (only those whose name starts
/// with @p node_prefix, e.g. "dirty/", if given: one of several nodes).
class DiagnosticsCollector {
 public:
  explicit DiagnosticsCollector(ros::NodeHandle& nh, const std::string& node_prefix = "") {
    sub_ = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100,
        [this, node_prefix](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
          std::lock_guard<std::mutex> lock(mutex_);
          for (const auto& status : array->status) {
            const std::string suffix = ": calibration";
            if (status.name.compare(0, node_prefix.size(), node_prefix) != 0) continue;
            if (status.name.size() >= suffix.size() &&
                status.name.compare(status.name.size() - suffix.size(), suffix.size(), suffix) ==
                    0) {
              statuses_.push_back(status);
            }
          }
        });
  }

  /// True if a status of at least @p level had a message containing @p reason.
  bool sawReason(uint8_t level, const std::string& reason) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : statuses_) {
      if (s.level >= level && s.message.find(reason) != std::string::npos) return true;
    }
    return false;
  }
  /// True if a status had a key @p key whose value contains @p text.
  bool sawValue(const std::string& key, const std::string& text) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : statuses_) {
      for (const auto& kv : s.values) {
        if (kv.key == key && kv.value.find(text) != std::string::npos) return true;
      }
    }
    return false;
  }
  /// Every value of key @p key, in the order the statuses came.
  std::vector<std::string> values(const std::string& key) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& s : statuses_) {
      for (const auto& kv : s.values) {
        if (kv.key == key) out.push_back(kv.value);
      }
    }
    return out;
  }
  /// Largest value of key @p key read as a number (-1 if never seen).
  double maxValue(const std::string& key) const {
    std::lock_guard<std::mutex> lock(mutex_);
    double largest = -1.0;
    for (const auto& s : statuses_) {
      for (const auto& kv : s.values) {
        if (kv.key == key) largest = std::max(largest, std::atof(kv.value.c_str()));
      }
    }
    return largest;
  }
  /// Index of the next status to arrive (to look only at later ones).
  size_t mark() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_.size();
  }
  /// True if every status from @p from on lacks @p reason (and there is at least one).
  bool noneSince(size_t from, const std::string& reason) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (statuses_.size() <= from) return false;
    for (size_t i = from; i < statuses_.size(); ++i) {
      if (statuses_[i].message.find(reason) != std::string::npos) return false;
    }
    return true;
  }
  /// All messages with their levels, for failure output.
  std::string describe() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream out;
    for (const auto& s : statuses_) out << "\n  [" << int(s.level) << "] " << s.message;
    return out.str();
  }

 private:
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses_;
};

/// Every ~calibration message of one node.
class CalibrationCollector {
 public:
  CalibrationCollector(ros::NodeHandle& nh, const std::string& topic) {
    sub_ = nh.subscribe<StereoCalibration>(topic, 1000,
                                           [this](const StereoCalibration::ConstPtr& message) {
                                             std::lock_guard<std::mutex> lock(mutex_);
                                             messages_.push_back(*message);
                                           });
  }
  /// Waits until connected to the node's publisher (messages before that are lost).
  bool waitForPublisher(double timeout) {
    return spinUntil([this]() { return sub_.getNumPublishers() > 0; }, timeout);
  }
  std::vector<StereoCalibration> messages() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_.size();
  }
  /// True if a message with exactly this stamp arrived.
  bool has(const ros::Time& stamp) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& m : messages_) {
      if (m.header.stamp == stamp) return true;
    }
    return false;
  }
  bool anyNonFinite() const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& m : messages_) {
      for (double v : m.parameters) {
        if (!std::isfinite(v)) return true;
      }
      for (double v : m.covariance) {
        if (!std::isfinite(v)) return true;
      }
    }
    return false;
  }

 private:
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::vector<StereoCalibration> messages_;
};

/// Publishers of the node's inputs (interface.md topics, relative to the test's namespace).
struct StereoInputs {
  explicit StereoInputs(ros::NodeHandle& nh)
      : left(nh.advertise<sensor_msgs::Image>("left/image_raw", 10)),
        right(nh.advertise<sensor_msgs::Image>("right/image_raw", 10)),
        left_info(nh.advertise<sensor_msgs::CameraInfo>("left/camera_info", 10)),
        right_info(nh.advertise<sensor_msgs::CameraInfo>("right/camera_info", 10)),
        odom(nh.advertise<nav_msgs::Odometry>("odom", 100)) {}
  /// Waits until the node subscribes to the images, camera_info and odometry.
  bool waitForSubscribers(double timeout) const {
    return spinUntil(
        [&]() {
          return left.getNumSubscribers() > 0 && left_info.getNumSubscribers() > 0 &&
                 odom.getNumSubscribers() > 0;
        },
        timeout);
  }
  ros::Publisher left, right, left_info, right_info, odom;
};

/// Odometry of a straight drive at 2 m/s along x that started at @p t0 (s), at time @p t.
inline nav_msgs::Odometry straightDriveOdometry(double t0, double t) {
  nav_msgs::Odometry o;
  o.header.stamp = ros::Time(t);
  o.pose.pose.position.x = 2.0 * (t - t0);
  o.pose.pose.orientation.w = 1.0;
  return o;
}

/// A 320x240 window of a random texture shifted by @p x (cheap, not a 3D scene).
inline sensor_msgs::Image textureImage(const cv::Mat& texture, int x, const ros::Time& stamp,
                                       const std::string& frame, const std::string& encoding) {
  sensor_msgs::Image message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.height = 240;
  message.width = 320;
  message.encoding = encoding;
  message.step = 320;
  const cv::Mat roi = texture(cv::Rect(x, 100, 320, 240)).clone();
  message.data.assign(roi.datastart, roi.dataend);
  return message;
}

/// A pinhole camera_info (fx = 300) of the given size.
inline sensor_msgs::CameraInfo pinholeInfo(const ros::Time& stamp, const std::string& frame,
                                           int width = 320, int height = 240) {
  sensor_msgs::CameraInfo message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.width = width;
  message.height = height;
  message.K = {300, 0, width / 2.0, 0, 300, height / 2.0, 0, 0, 1};
  message.distortion_model = "plumb_bob";
  message.D = {0, 0, 0, 0, 0};
  return message;
}

inline cv::Mat randomTexture() {
  cv::Mat texture(480, 1200, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0);
  return texture;
}

/// The paper's off-road drive (config/scenarios/paper_offroad.yaml, no step) rendered at a
/// small size, published as stereo images, camera_info and 100 Hz noisy odometry.
class RenderedDrive {
 public:
  /// @param ns namespace of left/ and right/ (e.g. "/stereo" or ""), @param odom_topic.
  RenderedDrive(ros::NodeHandle& nh, const std::string& ns, const std::string& odom_topic,
                int frames, int width, int height, double start_stamp) {
    osc::SimulationScenario scenario =
        osc::readScenarioFile(std::string(OSC_SOURCE_DIR) + "/config/scenarios/paper_offroad.yaml");
    for (osc::CameraIntrinsics* c : {&scenario.measurement.left, &scenario.measurement.right}) {
      const double scale = static_cast<double>(width) / c->width;
      c->fx *= scale;
      c->fy *= scale;
      c->cx = (c->cx + 0.5) * scale - 0.5;
      c->cy = (c->cy + 0.5) * scale - 0.5;
      c->width = width;
      c->height = height;
    }
    scenario.measurement.step_frame = -1;
    scenario.rendering.start_stamp = start_stamp;
    simulator_ = std::make_unique<osc::DriveSimulator>(scenario, frames);
    odometry_ = simulator_->odometry();
    left_ = nh.advertise<sensor_msgs::Image>(ns + "/left/image_raw", 5);
    right_ = nh.advertise<sensor_msgs::Image>(ns + "/right/image_raw", 5);
    left_info_ = nh.advertise<sensor_msgs::CameraInfo>(ns + "/left/camera_info", 5);
    right_info_ = nh.advertise<sensor_msgs::CameraInfo>(ns + "/right/camera_info", 5);
    odom_ = nh.advertise<nav_msgs::Odometry>(odom_topic, 500);
  }

  /// Waits until the node subscribes to all five inputs.
  bool waitForSubscribers(double timeout) {
    return spinUntil(
        [this]() {
          return left_.getNumSubscribers() > 0 && right_.getNumSubscribers() > 0 &&
                 left_info_.getNumSubscribers() > 0 && right_info_.getNumSubscribers() > 0 &&
                 odom_.getNumSubscribers() > 0;
        },
        timeout);
  }

  /// Waits until nobody subscribes any more (a node was shut down or unloaded).
  bool waitForNoSubscribers(double timeout) {
    return spinUntil(
        [this]() {
          return left_.getNumSubscribers() == 0 && right_.getNumSubscribers() == 0 &&
                 left_info_.getNumSubscribers() == 0 && right_info_.getNumSubscribers() == 0 &&
                 odom_.getNumSubscribers() == 0;
        },
        timeout);
  }

  int frames() const { return simulator_->frames(); }
  ros::Time stamp(int frame) const {
    ros::Time t;
    t.fromSec(simulator_->frameStamp(frame));
    return t;
  }
  osc::Vector12d truth(int frame) const { return simulator_->truthAt(frame); }
  const osc::DriveSimulator& simulator() const { return *simulator_; }

  /// Publishes the odometry up to two samples past the frame's stamp (and past it on either
  /// clock when they differ), then the pair. Returns the wall seconds spent rendering.
  double publish(int frame) {
    publishOdometryUntil(simulator_->frameStamp(frame) + 0.025 + std::abs(odometry_time_offset_));
    const ros::WallTime start = ros::WallTime::now();
    const osc::SimulatedImagePair pair = simulator_->renderFrame(frame);
    const double render = (ros::WallTime::now() - start).toSec();
    publishPair(pair, stamp(frame));
    return render;
  }

  /// Publishes the odometry samples not yet published with stamps up to @p until (s).
  void publishOdometryUntil(double until) {
    while (next_odom_ < odometry_.size() &&
           odometry_[next_odom_].stamp - odometry_time_offset_ <= until) {
      osc::StampedPose sample = odometry_[next_odom_];
      const osc::Vector6d twist = simulator_->odometryTwist(sample.stamp);
      sample.stamp -= odometry_time_offset_;
      odom_.publish(osc::bag::toOdometry(sample, twist, names_));
      ++next_odom_;
    }
  }

  /// From now on the odometry runs on a clock @p offset (s) behind the cameras' (interface.md:
  /// the time offset is camera clock minus odometry clock): the sample of the vehicle at camera
  /// time t is stamped t - offset. Stated here on the messages' stamps, independently of the
  /// simulators' own time_offset, so that a test checks the node's reading of the convention.
  void setOdometryTimeOffset(double offset) { odometry_time_offset_ = offset; }

  /// Publishes @p pair's images and the drive's camera_info, all stamped @p t.
  void publishPair(const osc::SimulatedImagePair& pair, const ros::Time& t) {
    std_msgs::Header header;
    header.stamp = t;
    header.seq = pair.frame;
    header.frame_id = names_.left_frame;
    left_.publish(cv_bridge::CvImage(header, "mono8", pair.left).toImageMsg());
    left_info_.publish(leftInfo(t));
    header.frame_id = names_.right_frame;
    right_.publish(cv_bridge::CvImage(header, "mono8", pair.right).toImageMsg());
    right_info_.publish(rightInfo(t));
  }

  sensor_msgs::CameraInfo leftInfo(const ros::Time& t) const {
    sensor_msgs::CameraInfo info =
        osc::bag::toCameraInfo(simulator_->scenario().measurement.left, t, names_.left_frame);
    if (factory_) {
      info =
          online_stereo_calibration::rectifiedCameraInfo(info, factory_->R_left, factory_->P_left);
    }
    return info;
  }
  sensor_msgs::CameraInfo rightInfo(const ros::Time& t) const {
    sensor_msgs::CameraInfo info =
        osc::bag::toCameraInfo(simulator_->scenario().measurement.right, t, names_.right_frame);
    if (factory_) {
      info = online_stereo_calibration::rectifiedCameraInfo(info, factory_->R_right,
                                                            factory_->P_right);
      info.header.frame_id = names_.left_frame;  // one frame for a rectified pair
    }
    return info;
  }
  /// From now on the camera_info carries this rectification's R and P (as a stereo camera's
  /// factory calibration does; rectifiedCameraInfo, so a pinhole D gets the k1 that makes
  /// image_geometry rectify) instead of R = I, P = [K | 0], and the right camera_info the
  /// left camera's frame (image_geometry's StereoCameraModel requires one frame).
  void setFactoryRectification(const osc::StereoRectification& rectification) {
    factory_ = rectification;
  }

  const osc::bag::DriveTopics& names() const { return names_; }

 private:
  osc::bag::DriveTopics names_;
  std::optional<osc::StereoRectification> factory_;
  std::unique_ptr<osc::DriveSimulator> simulator_;
  std::vector<osc::StampedPose> odometry_;
  size_t next_odom_ = 0;
  double odometry_time_offset_ = 0.0;  ///< s, camera clock minus odometry clock
  ros::Publisher left_, right_, left_info_, right_info_, odom_;
};

}  // namespace osc_test
