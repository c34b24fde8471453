/// @file robustness.cpp
/// @brief rostest (test/ros/robustness.test): feeds the nodelet awkward input (unsupported
/// encoding, NaN odometry, duplicated and backwards stamps, missing odometry) and checks it
/// keeps running, publishes no NaN, and that ~save_calibration writes the file.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/StereoCalibration.h"
#include "online_stereo_calibration/tools/calibration_file.h"

namespace {

sensor_msgs::Image image(const cv::Mat& texture, int x, const ros::Time& stamp,
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

sensor_msgs::CameraInfo info(const ros::Time& stamp, const std::string& frame) {
  sensor_msgs::CameraInfo message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.width = 320;
  message.height = 240;
  message.K = {300, 0, 160, 0, 300, 120, 0, 0, 1};
  message.distortion_model = "plumb_bob";
  message.D = {0, 0, 0, 0, 0};
  return message;
}

TEST(Robustness, AwkwardInputNeverKillsTheNodeNorPublishesNaN) {
  ros::NodeHandle nh;
  std::string node = "online_stereo_calibration";
  ros::param::get("~node", node);
  std::string file;
  ros::param::get("~calibration_file", file);
  auto left = nh.advertise<sensor_msgs::Image>("left/image_raw", 10);
  auto right = nh.advertise<sensor_msgs::Image>("right/image_raw", 10);
  auto left_info = nh.advertise<sensor_msgs::CameraInfo>("left/camera_info", 10);
  auto right_info = nh.advertise<sensor_msgs::CameraInfo>("right/camera_info", 10);
  auto odom = nh.advertise<nav_msgs::Odometry>("odom", 100);
  int received = 0;
  bool any_nan = false;
  auto sub = nh.subscribe<online_stereo_calibration::StereoCalibration>(
      node + "/calibration", 100,
      [&](const online_stereo_calibration::StereoCalibration::ConstPtr& m) {
        ++received;
        for (double v : m->parameters) any_nan = any_nan || !std::isfinite(v);
        for (double v : m->covariance) any_nan = any_nan || !std::isfinite(v);
      });
  ros::WallDuration(1.0).sleep();
  cv::Mat texture(480, 1200, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0);
  const double t0 = ros::Time::now().toSec();
  for (int k = 0; k < 40; ++k) {
    const double t = t0 + 0.1 * k;
    if (k < 25 || k > 28) {  // 25..28: odometry missing
      for (int j = 0; j < 5; ++j) {
        nav_msgs::Odometry o;
        o.header.stamp = ros::Time(t + 0.02 * j);
        o.pose.pose.position.x = 2.0 * (t + 0.02 * j - t0);
        o.pose.pose.orientation.w = 1.0;
        if (k == 12 && j == 0) o.pose.pose.position.y = std::nan("");  // NaN pose
        odom.publish(o);
      }
    }
    ros::Time stamp(t);
    if (k == 15) stamp = ros::Time(t - 0.1);                   // duplicated stamp
    if (k == 30) stamp = ros::Time(t - 2.0);                   // time goes backwards
    const std::string encoding = k == 8 ? "yuv422" : "mono8";  // unsupported encoding
    left.publish(image(texture, 200 + 2 * k, stamp, "left_optical", encoding));
    right.publish(image(texture, 190 + 2 * k, stamp, "right_optical", encoding));
    left_info.publish(info(stamp, "left_optical"));
    right_info.publish(info(stamp, "right_optical"));
    ros::WallDuration(0.1).sleep();
    ros::spinOnce();
  }
  ros::WallDuration(1.0).sleep();
  ros::spinOnce();
  EXPECT_GT(received, 10);
  EXPECT_FALSE(any_nan);

  ASSERT_TRUE(ros::service::waitForService(node + "/save_calibration", 5000));
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call(node + "/save_calibration", trigger));
  EXPECT_TRUE(trigger.response.success) << trigger.response.message;
  const osc::CalibrationFile saved = osc::readCalibrationFile(file);
  EXPECT_TRUE(saved.sigmas.has_value());
  EXPECT_TRUE(saved.extrinsics.toParameters().allFinite());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robustness_test");
  return RUN_ALL_TESTS();
}
