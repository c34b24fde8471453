/// @file robustness.cpp
/// @brief rostest (test/ros/robustness.test): feeds the nodelet awkward input and checks that
/// it keeps running, publishes no NaN, names every problem in /diagnostics, and that
/// ~save_calibration writes the file. At 10 Hz, frame k:
///   8: unsupported encoding (yuv422)         12: NaN odometry pose
///   15: duplicated pair stamp                18-19: right camera_info 640x480 (left 320x240)
///   22-46: no odometry (2.5 s)               50: pair stamp 2 s in the past
///   60-74: a bag loop: images AND odometry start again at the first stamps
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <std_srvs/Trigger.h>

#include "online_stereo_calibration/tools/calibration_file.h"
#include "rostest_helpers.h"

namespace {

using diagnostic_msgs::DiagnosticStatus;
using osc_test::pinholeInfo;
using osc_test::textureImage;

TEST(Robustness, AwkwardInputIsDiagnosedAndNeverKillsTheNodeNorPublishesNaN) {
  ros::NodeHandle nh;
  std::string node = "online_stereo_calibration";
  ros::param::get("~node", node);
  std::string file;
  ros::param::get("~calibration_file", file);
  osc_test::StereoInputs in(nh);
  osc_test::CalibrationCollector calibrations(nh, node + "/calibration");
  osc_test::DiagnosticsCollector diagnostics(nh);
  ASSERT_TRUE(in.waitForSubscribers(10.0));
  const cv::Mat texture = osc_test::randomTexture();
  const double t0 = ros::Time::now().toSec();
  ros::Time last_before_loop;
  for (int k = 0; k < 75; ++k) {
    const int drive_k = k < 60 ? k : k - 60;  // the loop replays the first stamps
    const double t = t0 + 0.1 * drive_k;
    if (k < 22 || k > 46) {
      for (int j = 0; j < 5; ++j) {
        nav_msgs::Odometry o = osc_test::straightDriveOdometry(t0, t + 0.02 * j);
        if (k == 12 && j == 0) o.pose.pose.position.y = std::nan("");
        in.odom.publish(o);
      }
    }
    ros::Time stamp(t);
    if (k == 15) stamp = ros::Time(t - 0.1);
    if (k == 50) stamp = ros::Time(t - 2.0);
    const std::string encoding = k == 8 ? "yuv422" : "mono8";
    const int shift = 2 * drive_k;
    in.left.publish(textureImage(texture, 200 + shift, stamp, "left_optical", encoding));
    in.right.publish(textureImage(texture, 190 + shift, stamp, "right_optical", encoding));
    in.left_info.publish(pinholeInfo(stamp, "left_optical"));
    in.right_info.publish(k == 18 || k == 19 ? pinholeInfo(stamp, "right_optical", 640, 480)
                                             : pinholeInfo(stamp, "right_optical"));
    if (k == 59) last_before_loop = stamp;
    osc_test::spinUntil([]() { return false; }, 0.1);
    // Checkpoints at ordinary pairs: the worker may lag on a loaded machine; let it catch up
    // so that each case meets the node in the state it is meant for (the loop in particular
    // restarts the odometry history, which pairs still queued from before could not use).
    if (k == 7 || k == 21 || k == 49 || k == 59) {
      EXPECT_TRUE(osc_test::spinUntil([&]() { return calibrations.has(stamp); }, 30.0))
          << "pair " << k << " not processed";
    }
  }
  // The worker may lag behind: wait for the last pair, then for a diagnostics report.
  EXPECT_TRUE(osc_test::spinUntil(
      [&]() {
        const auto messages = calibrations.messages();
        return std::count_if(messages.begin(), messages.end(), [&](const auto& m) {
                 return m.header.stamp == ros::Time(t0 + 0.1 * 14);
               }) >= 2;
      },
      60.0));
  osc_test::spinUntil([]() { return false; }, 2.5);

  double processing = 0.0;
  for (const auto& m : calibrations.messages()) processing += m.processing_time;
  std::printf("  %zu calibrations, mean processing time %.3f s\n", calibrations.size(),
              processing / std::max<size_t>(1, calibrations.size()));
  EXPECT_GT(calibrations.size(), 20u);
  EXPECT_FALSE(calibrations.anyNonFinite());
  // After the loop the node processes the replayed stamps again (tracks reset, odometry
  // history restarted): at least 12 of the 15 replayed pairs are published.
  // Messages are in processing order: the replay's are those after the last pre-loop stamp.
  const auto messages = calibrations.messages();
  auto loop_start = std::find_if(messages.rbegin(), messages.rend(), [&](const auto& m) {
                      return m.header.stamp > ros::Time(t0 + 0.1 * 20);
                    }).base();
  int replayed = 0;
  for (int j = 0; j < 15; ++j) {
    replayed += std::any_of(loop_start, messages.end(), [&](const auto& m) {
      return m.header.stamp == ros::Time(t0 + 0.1 * j);
    });
  }
  EXPECT_GE(replayed, 12) << "of 15 replayed pairs";
  EXPECT_LT(ros::Time(t0), last_before_loop);

  const uint8_t warn = DiagnosticStatus::WARN;
  const std::string all = diagnostics.describe();
  EXPECT_TRUE(diagnostics.sawReason(warn, "rejected images")) << all;
  EXPECT_TRUE(diagnostics.sawValue("rejected images (last)", "yuv422")) << all;
  EXPECT_TRUE(diagnostics.sawReason(warn, "rejected odometry")) << all;
  EXPECT_TRUE(diagnostics.sawValue("rejected odometry (last)", "non-finite")) << all;
  EXPECT_TRUE(diagnostics.sawReason(warn, "duplicated stamps")) << all;
  EXPECT_TRUE(diagnostics.sawReason(warn, "left/right camera_info disagree")) << all;
  EXPECT_TRUE(diagnostics.sawValue("left/right camera_info disagree (last)", "right 640x480"))
      << all;
  EXPECT_TRUE(diagnostics.sawReason(warn, "motion missing or late")) << all;
  EXPECT_TRUE(diagnostics.sawReason(DiagnosticStatus::ERROR, "no odometry")) << all;
  EXPECT_TRUE(diagnostics.sawReason(warn, "time went backwards")) << all;
  // Three of them: the pair 2 s in the past, the odometry jumping back at the loop and the
  // first pair of the loop (the latest detail is whichever came last).
  EXPECT_GE(diagnostics.maxValue("time went backwards (total)"), 3.0) << all;
  // Never a camera_info complaint: every image came with one.
  EXPECT_FALSE(diagnostics.sawReason(DiagnosticStatus::OK, "no camera_info")) << all;

  ASSERT_TRUE(ros::service::waitForService(node + "/save_calibration", 5000));
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call(node + "/save_calibration", trigger));
  EXPECT_TRUE(trigger.response.success) << trigger.response.message;
  const osc::CalibrationFile saved = osc::readCalibrationFile(file);
  EXPECT_TRUE(saved.sigmas.has_value());
  EXPECT_TRUE(saved.covariance.has_value());
  EXPECT_TRUE(saved.extrinsics.toParameters().allFinite());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robustness_test");
  return RUN_ALL_TESTS();
}
