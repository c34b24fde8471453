/// @file bag_io.h
/// @brief ROS message conversions and bag reading shared by `simulate`, `evaluate` and their
/// tests (header-only: the bag tools have no library of their own). No ROS master needed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <geometry_msgs/Transform.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_msgs/String.h>
#include <Eigen/Geometry>

#include "online_stereo_calibration/StereoCalibration.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/ros/conversions.h"
#include "online_stereo_calibration/ros/motion_buffers.h"

namespace osc::bag {

/// Topic and frame names of a simulated drive (what `evaluate` reads by default).
struct DriveTopics {
  std::string left_image = "/stereo/left/image_raw";
  std::string right_image = "/stereo/right/image_raw";
  std::string left_info = "/stereo/left/camera_info";
  std::string right_info = "/stereo/right/camera_info";
  std::string odom = "/odom";
  std::string truth = "/ground_truth/calibration";
  /// std_msgs/String: "fingerprint: <hex>" then the scenario file (the cache key).
  std::string scenario = "/simulation/scenario";
  std::string odom_frame = "odom";
  std::string vehicle_frame = "base_link";
  std::string left_frame = "left_camera_optical";
  std::string right_frame = "right_camera_optical";
};

/// sensor_msgs/CameraInfo of unrectified intrinsics: K, D, distortion_model, R = I,
/// P = [K | 0] (the left camera's convention for a raw stream).
inline sensor_msgs::CameraInfo toCameraInfo(const CameraIntrinsics& c, const ros::Time& stamp,
                                            const std::string& frame_id) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = frame_id;
  info.width = c.width;
  info.height = c.height;
  info.distortion_model =
      c.model == DistortionModel::kNone ? "plumb_bob" : distortionModelName(c.model);
  info.D = c.distortion;
  if (c.model == DistortionModel::kNone) info.D.assign(5, 0.0);
  info.K = {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0};
  return info;
}

/// A StereoCalibration message of known parameters (covariance and sigma zero): the truth.
inline online_stereo_calibration::StereoCalibration toCalibrationMessage(
    const Vector12d& parameters, const ros::Time& stamp, const DriveTopics& names) {
  online_stereo_calibration::StereoCalibration msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = names.vehicle_frame;
  msg.left_frame_id = names.left_frame;
  msg.right_frame_id = names.right_frame;
  const StereoExtrinsics e = StereoExtrinsics::fromParameters(parameters);
  msg.vehicle_to_left = online_stereo_calibration::transformFromIsometry(e.vehicleToLeftOptical());
  msg.left_to_right = online_stereo_calibration::transformFromIsometry(e.leftToRightOptical());
  for (int i = 0; i < 12; ++i) msg.parameters[i] = parameters(i);
  msg.state = online_stereo_calibration::StereoCalibration::STATE_CONVERGED;
  return msg;
}

/// nav_msgs/Odometry of a pose and its body twist [v, w] (vehicle frame; covariances zero).
inline nav_msgs::Odometry toOdometry(const StampedPose& pose, const Vector6d& twist,
                                     const DriveTopics& names) {
  nav_msgs::Odometry msg;
  msg.header.stamp.fromSec(pose.stamp);
  msg.header.frame_id = names.odom_frame;
  msg.child_frame_id = names.vehicle_frame;
  const geometry_msgs::Transform t = online_stereo_calibration::transformFromIsometry(pose.pose);
  msg.pose.pose.position.x = t.translation.x;
  msg.pose.pose.position.y = t.translation.y;
  msg.pose.pose.position.z = t.translation.z;
  msg.pose.pose.orientation = t.rotation;
  msg.twist.twist.linear.x = twist(0);
  msg.twist.twist.linear.y = twist(1);
  msg.twist.twist.linear.z = twist(2);
  msg.twist.twist.angular.x = twist(3);
  msg.twist.twist.angular.y = twist(4);
  msg.twist.twist.angular.z = twist(5);
  return msg;
}

/// The odometry and StereoCalibration messages of a bag.
struct OdometryAndCalibration {
  /// Every pose of the odometry topic, in stamp order (out-of-order messages are sorted).
  PoseTrajectory odometry;
  /// The same samples with their twists (twist.twist, for the time offset), as the node
  /// keeps them: a twist not finite or unset (online_stereo_calibration::unsetTwistProblem)
  /// is not used. twistAt() interpolates them at any stamp.
  online_stereo_calibration::PoseBuffer odometry_twists{1e300, 1e300};
  /// Odometry messages whose twist is not used, and the last reason.
  int samples_without_twist = 0;
  std::string twist_problem;
  /// The parameters of every StereoCalibration message: (header stamp in ns, parameters), in
  /// bag order.
  std::vector<std::pair<std::int64_t, Vector12d>> calibration;
};

/// Reads both topics in one pass over the bag (an empty topic name is skipped): rosbag reads
/// whole chunks, and odometry and truth are spread over every chunk of an image bag, so a view
/// per topic would read the whole bag once per topic.
inline OdometryAndCalibration readOdometryAndCalibration(const rosbag::Bag& bag,
                                                         const std::string& odom_topic,
                                                         const std::string& calibration_topic) {
  std::vector<std::string> topics;
  for (const std::string& topic : {odom_topic, calibration_topic}) {
    if (!topic.empty()) topics.push_back(topic);
  }
  OdometryAndCalibration out;
  std::vector<online_stereo_calibration::StampedPose> poses;
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  for (const rosbag::MessageInstance& m : view) {
    if (!odom_topic.empty() && m.getTopic() == odom_topic) {
      const auto odom = m.instantiate<nav_msgs::Odometry>();
      std::string twist_problem, covariance_problem;
      if (odom) {
        poses.push_back(online_stereo_calibration::odometrySample(*odom, false, &twist_problem,
                                                                  &covariance_problem));
        if (!twist_problem.empty()) out.twist_problem = twist_problem;
      }
    }
    if (!calibration_topic.empty() && m.getTopic() == calibration_topic) {
      const auto msg = m.instantiate<online_stereo_calibration::StereoCalibration>();
      if (!msg) continue;
      Vector12d p;
      for (int i = 0; i < 12; ++i) p(i) = msg->parameters[i];
      out.calibration.emplace_back(static_cast<std::int64_t>(msg->header.stamp.toNSec()), p);
    }
  }
  using Sample = online_stereo_calibration::StampedPose;
  std::stable_sort(poses.begin(), poses.end(),
                   [](const Sample& a, const Sample& b) { return a.stamp < b.stamp; });
  for (Sample& p : poses) {
    out.odometry.append(p.stamp, p.pose);
    if (const Sample* previous = out.odometry_twists.newest()) {
      const std::string unset = online_stereo_calibration::unsetTwistProblem(p, *previous);
      if (!unset.empty()) {
        p.has_twist = false;
        out.twist_problem = unset;
      }
    }
    if (!p.has_twist) ++out.samples_without_twist;
    out.odometry_twists.add(p);  // of a duplicated stamp, the first twist is kept
  }
  return out;
}

/// Every pose of an odometry topic, in stamp order.
inline PoseTrajectory readOdometry(const rosbag::Bag& bag, const std::string& topic) {
  return readOdometryAndCalibration(bag, topic, "").odometry;
}

/// The parameters of every StereoCalibration message on a topic, in bag order.
inline std::vector<std::pair<std::int64_t, Vector12d>> readCalibrationTopic(
    const rosbag::Bag& bag, const std::string& topic) {
  return readOdometryAndCalibration(bag, "", topic).calibration;
}

/// The scenario fingerprint stored in a bag by `simulate`, or "" (no such topic, unreadable).
inline std::string readScenarioFingerprint(const std::string& bag_path,
                                           const DriveTopics& names = DriveTopics()) {
  try {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    rosbag::View view(bag, rosbag::TopicQuery(names.scenario));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<std_msgs::String>();
      if (!msg) continue;
      const std::string prefix = "fingerprint: ";
      if (msg->data.rfind(prefix, 0) != 0) return "";
      const auto end = msg->data.find('\n');
      return msg->data.substr(prefix.size(),
                              end == std::string::npos ? std::string::npos : end - prefix.size());
    }
  } catch (const std::exception&) {
  }
  return "";
}

/// One topic of a bag: name, message type and number of messages.
struct BagTopic {
  std::string name, type;
  std::size_t messages = 0;
};

/// Every topic of a bag, sorted by name.
inline std::vector<BagTopic> listTopics(const rosbag::Bag& bag) {
  std::map<std::string, BagTopic> topics;
  rosbag::View all(bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    BagTopic& t = topics[c->topic];
    t.name = c->topic;
    t.type = c->datatype;
  }
  std::vector<BagTopic> out;
  for (auto& [name, topic] : topics) {
    topic.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
    out.push_back(topic);
  }
  return out;
}

/// A topic a tool needs: the option that sets it, its name and its message type.
struct RequiredTopic {
  std::string option;  ///< e.g. "--left-image"
  std::string topic;   ///< e.g. "/stereo/left/image_raw"
  std::string type;    ///< e.g. "sensor_msgs/Image"
};

/// Checks that every required topic has messages of its type in the bag.
/// @throws std::runtime_error naming each missing or mistyped topic with its option, and
/// listing the bag's topics (name, type, count).
inline void requireTopics(const rosbag::Bag& bag, const std::string& bag_name,
                          const std::vector<RequiredTopic>& required) {
  const std::vector<BagTopic> topics = listTopics(bag);
  std::string problems;
  for (const RequiredTopic& r : required) {
    const auto found = std::find_if(topics.begin(), topics.end(),
                                    [&](const BagTopic& t) { return t.name == r.topic; });
    if (found == topics.end() || found->messages == 0) {
      problems += "\n  " + r.option + " " + r.topic + ": not in the bag";
    } else if (found->type != r.type) {
      problems += "\n  " + r.option + " " + r.topic + ": holds " + found->type + ", not " + r.type;
    }
  }
  if (problems.empty()) return;
  std::string message = bag_name +
                        ": missing topics (set them with the options named):" + problems +
                        "\nthe bag holds:";
  if (topics.empty()) message += " no topics";
  for (const BagTopic& t : topics) {
    message += "\n  " + t.name + "  " + t.type + "  (" + std::to_string(t.messages) + " messages)";
  }
  throw std::runtime_error(message);
}

}  // namespace osc::bag
