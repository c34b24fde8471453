/// @file time_offset.cpp
/// @brief rostest (test/ros/time_offset.test, which includes launch/calibrate.launch): the
/// rendered off-road drive of convergence.cpp, with every odometry message stamped
/// `odometry_time_offset_ms` before the camera time of the pose it holds. interface.md and the
/// message say time_offset is "camera clock minus odometry clock: the odometry stamped t holds
/// the vehicle at camera time t + time_offset", so the node must estimate it with that sign
/// and size, from the messages alone. The simulators and the offline evaluator share the
/// core's convention; this is the one test of the node's own reading of the stamps.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "rostest_helpers.h"

namespace {

using osc_test::StereoCalibration;

TEST(TimeOffset, TheNodeEstimatesTheOdometrysClockOffsetWithItsSign) {
  ros::NodeHandle nh;
  int frames = 300;
  double offset_ms = 25.0;
  ros::param::get("~frames", frames);
  ros::param::get("~odometry_time_offset_ms", offset_ms);
  ASSERT_GT(std::abs(offset_ms), 10.0) << "too small an offset to tell its sign";
  const std::string node = "/stereo/online_stereo_calibration";
  osc_test::RenderedDrive drive(nh, "/stereo", "/odom", frames, 320, 240,
                                std::floor(ros::Time::now().toSec()));
  drive.setOdometryTimeOffset(offset_ms * 1e-3);
  osc_test::CalibrationCollector calibrations(nh, node + "/calibration");
  ASSERT_TRUE(drive.waitForSubscribers(20.0));
  ASSERT_TRUE(calibrations.waitForPublisher(20.0));

  int answered = 0;
  for (int k = 0; k < frames; ++k) {
    drive.publish(k);
    const ros::Time stamp = drive.stamp(k);
    answered += osc_test::spinUntil([&]() { return calibrations.has(stamp); }, 5.0);
  }
  EXPECT_GE(answered, frames - 5) << "pairs without an answer (skipped or lost)";

  const std::vector<StereoCalibration> messages = calibrations.messages();
  ASSERT_GE(messages.size(), 2u);
  const StereoCalibration& first = messages.front();
  const StereoCalibration& last = messages.back();
  ASSERT_EQ(last.header.stamp, drive.stamp(frames - 1));
  std::printf("  time offset: truth %+.1f ms, start %+.1f +- %.1f ms, end %+.2f +- %.2f ms\n",
              offset_ms, first.time_offset * 1e3, first.time_offset_sigma * 1e3,
              last.time_offset * 1e3, last.time_offset_sigma * 1e3);
  // The default config estimates it from 0 +- 20 ms.
  EXPECT_DOUBLE_EQ(first.time_offset, 0.0);
  ASSERT_GT(first.time_offset_sigma, 0.0) << "the time offset is not estimated";
  // Its sign, its size, and honest about both: a reading of the stamps the wrong way round
  // converges towards -offset, more than 20 ms away from the truth.
  const double truth = offset_ms * 1e-3;
  EXPECT_GT(last.time_offset * truth, 0.0) << "the time offset has the wrong sign";
  EXPECT_NEAR(last.time_offset, truth, 0.005);
  EXPECT_LT(last.time_offset_sigma, 0.5 * first.time_offset_sigma) << "learned nothing";
  EXPECT_LT(std::abs(last.time_offset - truth), 3.0 * last.time_offset_sigma);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "time_offset_test");
  return RUN_ALL_TESTS();
}
