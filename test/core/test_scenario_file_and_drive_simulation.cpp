/// Tests of scenario files' campaign keys (scenario_file.h: stops, odometry errors, blind
/// frames, moving points, recorded TUM trajectories), of TUM trajectory files
/// (tum_trajectory.h), and of the image-level drive they make (drive_simulation.h).
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include "temp_dir.h"

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/tools/drive_simulation.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/scenario_file.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {
namespace {

/// The parse error of a scenario text, or "" if it parses.
std::string scenarioError(const std::string& text, const std::string& directory = ".") {
  try {
    parseScenarioYaml(text, "test.yaml", directory);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioFileCampaignKeys, ParseIntoTheMeasurementScenario) {
  const SimulationScenario s = parseScenarioYaml(
      "frames: 400\n"
      "motion: {speed: 5, stops: [[10, 4.5], [25, 2]], stop_ramp: 1.5, yaw_phase: 3.1}\n"
      "odometry_error: {time_offset: -0.03, scale_error: 0.01, rotation_rate_bias: 1e-4,\n"
      "                 velocity_bias: 0.02, bias_correlation_time: 12}\n"
      "blind_frames: [[100, 109], [300, 300]]\n"
      "moving_point_fraction: 0.2\n"
      "moving_point_speed: 1.5\n",
      "test.yaml", ".");
  const MeasurementScenario& m = s.measurement;
  ASSERT_EQ(m.motion.stops.size(), 2u);
  EXPECT_EQ(m.motion.stops[0].start, 10.0);
  EXPECT_EQ(m.motion.stops[0].duration, 4.5);
  EXPECT_EQ(m.motion.stops[1].start, 25.0);
  EXPECT_EQ(m.motion.stops[1].duration, 2.0);
  EXPECT_EQ(m.motion.stop_ramp, 1.5);
  EXPECT_EQ(m.motion.speed, 5.0);
  EXPECT_EQ(m.motion.yaw_phase, 3.1);
  EXPECT_EQ(m.odometry_error.time_offset, -0.03);
  EXPECT_EQ(m.odometry_error.scale_error, 0.01);
  EXPECT_EQ(m.odometry_error.rotation_rate_bias, 1e-4);
  EXPECT_EQ(m.odometry_error.velocity_bias, 0.02);
  EXPECT_EQ(m.odometry_error.bias_correlation_time, 12.0);
  ASSERT_EQ(m.blind_frames.size(), 2u);
  EXPECT_EQ(m.blind_frames[0].first, 100);
  EXPECT_EQ(m.blind_frames[0].last, 109);
  EXPECT_EQ(m.blind_frames[1].first, 300);
  EXPECT_EQ(m.blind_frames[1].last, 300);
  EXPECT_EQ(m.moving_point_fraction, 0.2);
  EXPECT_EQ(m.moving_point_speed, 1.5);
  EXPECT_FALSE(m.recorded_trajectory);
  // Left out: the preset's values.
  const SimulationScenario plain = parseScenarioYaml("frames: 400\n", "plain.yaml", ".");
  EXPECT_TRUE(plain.measurement.motion.stops.empty());
  EXPECT_EQ(plain.measurement.motion.yaw_phase, 0.0);
  EXPECT_EQ(plain.measurement.odometry_error.scale_error, 0.0);
  EXPECT_TRUE(plain.measurement.blind_frames.empty());
}

TEST(ScenarioFileCampaignKeys, ErrorsNameTheKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"motion: {stops: 3}\n", "motion.stops"},
      {"motion: {stops: [[1, 2], [5]]}\n", "motion.stops[1]"},
      {"motion: {stops: [[1, x]]}\n", "motion.stops[0].duration"},
      {"motion: {stops: [[20, 1], [10, 1]]}\n", "motion.stops[1]"},
      {"motion: {stops: [[1, 2]], stop_ramp: -1}\n", "motion.stop_ramp"},
      {"motion: {yaw_phase: .nan}\n", "motion.yaw_phase"},
      {"odometry_error: {time_ofset: 0.1}\n", "odometry_error.time_ofset"},
      {"odometry_error: 0.1\n", "odometry_error"},
      {"odometry_error: {time_offset: 0.9}\n", "odometry_error.time_offset"},
      {"odometry_error: {scale_error: 0.5}\n", "odometry_error.scale_error"},
      {"odometry_error: {rotation_rate_bias: -1}\n", "odometry_error.rotation_rate_bias"},
      {"odometry_error: {velocity_bias: many}\n", "odometry_error.velocity_bias"},
      {"odometry_error: {bias_correlation_time: 0}\n", "odometry_error.bias_correlation_time"},
      {"blind_frames: [[5, 3]]\n", "blind_frames[0].last"},
      {"blind_frames: [[5, 1.5]]\n", "blind_frames[0].last"},
      {"blind_frames: [[10, 20], [15, 30]]\n", "blind_frames[1].first"},
      {"frames: 100\nblind_frames: [[90, 100]]\n", "blind_frames[0].last"},
      {"blind_frames: 7\n", "blind_frames"},
      {"moving_point_fraction: 2\n", "moving_point_fraction"},
      {"moving_point_speed: fast\n", "moving_point_speed"},
      {"moving_point_speed: -1\n", "moving_point_speed"},
      {"rendering: {room_margin: -1}\n", "rendering.room_margin"},
      {"rendering: {room_height: 0}\n", "rendering.room_height"},
      {"rendering: {room_hight: 3}\n", "rendering.room_hight"},
  };
  for (const auto& c : cases) {
    const std::string error = scenarioError(c.first);
    EXPECT_NE(error.find(c.second), std::string::npos) << c.first << " gave: " << error;
  }
}

/// Writes a TUM file of a VehicleTrajectory sampled at 20 Hz for @p seconds.
void writeTum(const std::string& path, double seconds) {
  const VehicleTrajectory trajectory{VehicleMotionProfile()};
  std::ofstream out(path);
  out << "# t x y z qx qy qz qw\n";
  out.precision(17);
  for (int k = 0; k * 0.05 <= seconds + 1e-9; ++k) {
    const Eigen::Isometry3d pose = trajectory.pose(k * 0.05);
    const Eigen::Quaterniond q(pose.rotation());
    out << 500.0 + k * 0.05 << " " << pose.translation().transpose() << " " << q.x() << " " << q.y()
        << " " << q.z() << " " << q.w() << "\n";
  }
}

TEST(ScenarioFileCampaignKeys, TumTrajectoryBecomesTheMeasurementSimulatorsDrive) {
  TempDir dir;
  writeTum(dir.path() + "/drive.tum", 12.0);
  const std::string text =
      "frames: 100\nstep_frame: -1\ntrajectory: {tum_file: drive.tum, start_offset: 1.5}\n";
  const SimulationScenario s = parseScenarioYaml(text, "test.yaml", dir.path());
  ASSERT_TRUE(s.measurement.recorded_trajectory);
  EXPECT_EQ(s.measurement.recorded_start_offset, 1.5);
  const PoseTrajectory file = readTumTrajectory(dir.path() + "/drive.tum");
  MeasurementSimulator sim(s.measurement);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    ASSERT_TRUE(frame.T_world_veh.isApprox(*file.at(501.5 + frame.index * 0.1), 1e-12));
  }
  // Too short for the frames from that offset: the error names the fields.
  const std::string error = scenarioError(
      "frames: 120\ntrajectory: {tum_file: drive.tum, start_offset: 1.5}\n", dir.path());
  EXPECT_NE(error.find("frames"), std::string::npos) << error;
  EXPECT_NE(error.find("start_offset"), std::string::npos) << error;
  // A recording replaces the analytic motion, stops included.
  EXPECT_NE(scenarioError("frames: 50\nmotion: {stops: [[1, 1]]}\n"
                          "trajectory: {tum_file: drive.tum}\n",
                          dir.path())
                .find("motion.stops"),
            std::string::npos);
}

// formatTumTrajectory writes what readTumTrajectory reads back: the stamps to the nanosecond
// at KITTI's ~1.3e9 s, positions to 0.1 mm, rotations to ~1e-9 rad; the comment as '#' lines.
TEST(TumTrajectory, FormattedPosesAreReadBack) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 5; ++k) {
    StampedPose p;
    p.stamp = 1317045935.706851006 + 0.0103 * k;
    p.pose.linear() = expSO3(Eigen::Vector3d(0.01 * k, -0.2, 1.0 + 0.3 * k));
    p.pose.translation() = Eigen::Vector3d(1234.5678 + k, -0.25 * k, 3.0);
    poses.push_back(p);
  }
  const std::string text = formatTumTrajectory(poses, "first line\nsecond line");
  EXPECT_EQ(text.rfind("# first line\n# second line\n", 0), 0u) << text;
  TempDir dir;
  const std::string path = dir.path() + "/poses.tum";
  writeTextFileAtomic(path, text);
  const PoseTrajectory back = readTumTrajectory(path);
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(back.poses()[k].stamp, poses[k].stamp, 1e-6) << k;
    EXPECT_LT((back.poses()[k].pose.translation() - poses[k].pose.translation()).norm(), 1e-4);
    EXPECT_LT(logSO3(back.poses()[k].pose.linear().transpose() * poses[k].pose.linear()).norm(),
              1e-8);
  }
}

TEST(ScenarioFileCampaignKeys, RealRecordedTrajectoryDrivesTheMeasurementSimulator) {
  const std::string path =
      std::string(OSC_SOURCE_DIR) + "/../shared/data/trajectories/udel_gore_rep103.tum";
  if (!std::ifstream(path)) GTEST_SKIP() << "no " << path;
  const SimulationScenario s = parseScenarioYaml(
      "frames: 400\nrate_hz: 20\nstep_frame: -1\nodometry_error: {time_offset: 0.1}\n"
      "motion_rotation_noise: 0\nmotion_translation_noise: 0\n"
      "trajectory: {tum_file: " +
          path + ", start_offset: 30}\n",
      "udel.yaml", ".");
  const PoseTrajectory file = readTumTrajectory(path);
  MeasurementSimulator sim(s.measurement);
  SimulatedFrame f;
  int observed = 0;
  while (sim.nextFrame(&f)) {
    // The stamps are ~1.5e9 s: summed in another order they differ by ~1e-7 s (~1e-7 m).
    const double stamp = file.firstStamp() + 30.0 + f.index / 20.0;
    ASSERT_LT((f.T_world_veh.matrix() - file.at(stamp)->matrix()).norm(), 1e-5) << f.index;
    if (f.index > 0) {
      const Eigen::Isometry3d shifted =
          file.at(stamp - 0.05 + 0.1)->inverse() * *file.at(stamp + 0.1);
      ASSERT_LT((f.measured_motion.T_prev_curr.matrix() - shifted.matrix()).norm(), 1e-5)
          << "frame " << f.index;
    }
    observed += static_cast<int>(f.observations.size());
  }
  EXPECT_GT(observed, 400 * 80);  // the points follow the walk
}

/// A small, fast image-level drive for the odometry and rendering checks.
SimulationScenario smallDrive(const std::string& extra, int frames = 30) {
  return parseScenarioYaml(
      "frames: " + std::to_string(frames) +
          "\nmotion_rotation_noise: 0\nmotion_translation_noise: 0\n"
          "left_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
          "right_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
          "rendering: {supersampling: 1, odom_rate_hz: 100}\n" +
          extra,
      "small.yaml", ".");
}

TEST(DriveSimulation, OdometryCarriesTheTimeOffsetAndScaleError) {
  const DriveSimulator plain(smallDrive(""));
  const DriveSimulator erred(smallDrive("odometry_error: {time_offset: 0.07, scale_error: 0.1}\n"));
  const std::vector<StampedPose> a = plain.odometry(), b = erred.odometry();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 290u);
  for (size_t k = 1; k < b.size(); ++k) {
    // Same stamps; the sample stamped start + t holds the motion up to t + time_offset,
    // with the translation scaled by 1 + scale_error.
    ASSERT_EQ(a[k].stamp, b[k].stamp);
    const double t0 = (k - 1) * 0.01, t1 = k * 0.01;
    const Eigen::Isometry3d truth = erred.truePose(t0 + 0.07).inverse() * erred.truePose(t1 + 0.07);
    const Eigen::Isometry3d reported = b[k - 1].pose.inverse() * b[k].pose;
    ASSERT_LT((reported.translation() - 1.1 * truth.translation()).norm(), 1e-9) << k;
    ASSERT_TRUE(reported.linear().isApprox(truth.linear(), 1e-9)) << k;
    // Without errors (and noise) the odometry is the true motion.
    const Eigen::Isometry3d exact = a[k - 1].pose.inverse() * a[k].pose;
    ASSERT_TRUE(exact.isApprox(plain.truePose(t0).inverse() * plain.truePose(t1), 1e-9)) << k;
  }
}

TEST(DriveSimulation, OdometryBiasesAreTheSameGaussMarkovProcess) {
  // Per axis, the velocity bias seen in the odometry increments has the configured std.
  const DriveSimulator sim(
      smallDrive("odometry_error: {velocity_bias: 0.05, bias_correlation_time: 0.5}\n", 1500));
  const std::vector<StampedPose> odometry = sim.odometry();
  std::vector<double> bias;
  for (size_t k = 1; k < odometry.size(); ++k) {
    const double t0 = (k - 1) * 0.01, t1 = k * 0.01;
    const Eigen::Isometry3d truth = sim.truePose(t0).inverse() * sim.truePose(t1);
    const Eigen::Isometry3d reported = odometry[k - 1].pose.inverse() * odometry[k].pose;
    bias.push_back((reported.translation() - truth.translation()).y() / 0.01);
  }
  double sum = 0.0, sum2 = 0.0;
  for (double b : bias) {
    sum += b;
    sum2 += b * b;
  }
  const double m = sum / bias.size();
  EXPECT_NEAR(std::sqrt(sum2 / bias.size() - m * m), 0.05, 0.01);  // 300 correlation times: ~4 %
}

TEST(DriveSimulation, BlindFramesAreRenderedAlmostBlack) {
  const DriveSimulator sim(smallDrive("blind_frames: [[10, 12]]\n"));
  const SimulatedImagePair seen = sim.renderFrame(9), blind = sim.renderFrame(11);
  const double seen_mean = cv::mean(seen.left)[0], blind_mean = cv::mean(blind.left)[0];
  EXPECT_GT(seen_mean, 40.0);
  EXPECT_LT(blind_mean, 0.05 * seen_mean + 1.0);
  EXPECT_LT(cv::mean(blind.right)[0], 0.05 * cv::mean(seen.right)[0] + 1.0);
  // Its structure is gone: the image's std is about the pixel noise.
  cv::Scalar mean, stddev;
  cv::meanStdDev(blind.left, mean, stddev);
  EXPECT_LT(stddev[0], 3.0);
}

}  // namespace
}  // namespace osc
