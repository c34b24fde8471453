/// @file no_camera_info.cpp
/// @brief rostest (test/ros/no_camera_info.test): stereo images and odometry arrive but no
/// CameraInfo. The node must say so in /diagnostics (ERROR naming camera_info), publish no
/// calibration, and keep running: when camera_info finally comes, it calibrates and the
/// error goes away.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <std_srvs/Trigger.h>

#include "rostest_helpers.h"

namespace {

using diagnostic_msgs::DiagnosticStatus;

TEST(NoCameraInfo, IsAnErrorInDiagnosticsAndNothingIsPublished) {
  ros::NodeHandle nh;
  const std::string node = "online_stereo_calibration";
  osc_test::StereoInputs in(nh);
  osc_test::CalibrationCollector calibrations(nh, node + "/calibration");
  osc_test::DiagnosticsCollector diagnostics(nh);
  ASSERT_TRUE(in.waitForSubscribers(10.0));
  const cv::Mat texture = osc_test::randomTexture();
  const double t0 = ros::Time::now().toSec();
  size_t mark = 0;
  const auto publishFrame = [&](int k, bool with_info) {
    const double t = t0 + 0.1 * k;
    for (int j = 0; j < 5; ++j) in.odom.publish(osc_test::straightDriveOdometry(t0, t + 0.02 * j));
    const ros::Time stamp(t);
    in.left.publish(osc_test::textureImage(texture, 200 + 2 * k, stamp, "left_optical", "mono8"));
    in.right.publish(osc_test::textureImage(texture, 190 + 2 * k, stamp, "right_optical", "mono8"));
    if (with_info) {
      in.left_info.publish(osc_test::pinholeInfo(stamp, "left_optical"));
      in.right_info.publish(osc_test::pinholeInfo(stamp, "right_optical"));
    }
    osc_test::spinUntil([]() { return false; }, 0.1);
  };
  // 3 s without camera_info.
  for (int k = 0; k < 30; ++k) publishFrame(k, false);
  const std::string before = diagnostics.describe();
  EXPECT_EQ(calibrations.size(), 0u) << "nothing can be calibrated without intrinsics";
  EXPECT_TRUE(diagnostics.sawReason(DiagnosticStatus::ERROR,
                                    "no camera_info on left/camera_info, right/camera_info"))
      << before;
  EXPECT_TRUE(diagnostics.sawValue("images since last report (left, right)", ""));
  // Alive: its services answer (there is no estimate to save yet).
  ASSERT_TRUE(ros::service::waitForService(node + "/save_calibration", 5000));
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call(node + "/save_calibration", trigger));
  EXPECT_FALSE(trigger.response.success);

  // camera_info comes: calibration starts and later reports no longer name camera_info.
  for (int k = 30; k < 45; ++k) {
    publishFrame(k, true);
    if (k == 35) mark = diagnostics.mark();
  }
  // The worker may lag behind: wait for the last pair, then for a diagnostics report.
  EXPECT_TRUE(osc_test::spinUntil([&]() { return calibrations.has(ros::Time(t0 + 4.4)); }, 60.0));
  osc_test::spinUntil([]() { return false; }, 1.5);
  EXPECT_GE(calibrations.size(), 12u) << "of 15 pairs with camera_info";
  EXPECT_TRUE(diagnostics.noneSince(mark, "no camera_info")) << diagnostics.describe();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "no_camera_info_test");
  return RUN_ALL_TESTS();
}
