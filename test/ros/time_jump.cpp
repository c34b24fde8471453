/// @file time_jump.cpp
/// @brief rostest (test/ros/time_jump.test), issue 17: with simulated time the test plays a
/// 5 s drive (10 Hz pairs, 50 Hz odometry, /clock at each pair), then plays it again from
/// its first stamp (the clock jumps back, as in `rosbag play -l`), calls ~reset, and plays
/// it once more 100 s later (the clock jumps forward). Asserts in each play: calibration
/// statuses keep coming on /diagnostics (diagnostic_updater alone stays silent until the
/// report time it computed before a jump back), pairs keep being calibrated, and the jump
/// back and the reset are reported.
#include <cstdio>

#include <gtest/gtest.h>
#include <rosgraph_msgs/Clock.h>
#include <std_srvs/Trigger.h>

#include "rostest_helpers.h"

namespace {

using osc_test::spinUntil;

TEST(TimeJump, DiagnosticsAndCalibrationKeepComingAcrossJumpsOfTheClock) {
  ros::NodeHandle nh;
  const std::string node = "online_stereo_calibration";
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  osc_test::StereoInputs in(nh);
  osc_test::CalibrationCollector calibrations(nh, node + "/calibration");
  osc_test::DiagnosticsCollector diagnostics(nh);
  const cv::Mat texture = osc_test::randomTexture();
  const double t0 = 1000.0;
  const auto set_clock = [&](double t) {
    rosgraph_msgs::Clock message;
    message.clock = ros::Time(t);
    clock.publish(message);
  };
  set_clock(t0);
  ASSERT_TRUE(in.waitForSubscribers(20.0));
  ASSERT_TRUE(calibrations.waitForPublisher(20.0));

  constexpr int kFrames = 50;
  const auto play = [&](double start, const char* name) {
    const size_t statuses_before = diagnostics.mark();
    const size_t calibrations_before = calibrations.size();
    for (int k = 0; k < kFrames; ++k) {
      const double t = start + 0.1 * k;
      for (int j = 0; j < 5; ++j)
        in.odom.publish(osc_test::straightDriveOdometry(start, t + 0.02 * j));
      set_clock(t);
      const ros::Time stamp(t);
      in.left.publish(osc_test::textureImage(texture, 200 + 2 * k, stamp, "left_optical", "mono8"));
      in.right.publish(
          osc_test::textureImage(texture, 190 + 2 * k, stamp, "right_optical", "mono8"));
      in.left_info.publish(osc_test::pinholeInfo(stamp, "left_optical"));
      in.right_info.publish(osc_test::pinholeInfo(stamp, "right_optical"));
      const size_t expected = calibrations.size() + 1;
      spinUntil([&]() { return calibrations.size() >= expected; }, 3.0);
      spinUntil([]() { return false; }, 0.02);  // the node's timers see the new clock
    }
    const size_t statuses = diagnostics.mark() - statuses_before;
    const size_t published = calibrations.size() - calibrations_before;
    std::printf("  %s: %zu calibration statuses, %zu calibrations in %.1f s of sim time\n", name,
                statuses, published, 0.1 * kFrames);
    // 5 s of simulated time at the default 1 s diagnostic period.
    EXPECT_GE(statuses, 3u) << name << diagnostics.describe();
    EXPECT_GE(published, static_cast<size_t>(kFrames - 5)) << name;
    return statuses_before;
  };

  play(t0, "first play");
  const size_t second = play(t0, "second play (clock back)");
  EXPECT_FALSE(diagnostics.noneSince(second, "time went backwards")) << diagnostics.describe();

  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call(node + "/reset", trigger));
  const size_t third = play(t0 + 100.0, "third play (after ~reset, clock 100 s ahead)");
  EXPECT_FALSE(diagnostics.noneSince(third, "motion missing or late")) << diagnostics.describe();
  EXPECT_GE(diagnostics.maxValue("resets (total)"), 1.0) << diagnostics.describe();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "time_jump_test");
  return RUN_ALL_TESTS();
}
