/// @file measurement_simulator_test_support.h
/// @brief Helpers of the measurement simulator's tests (test_measurement_simulator*,
/// test_measurement_scenario, test_vehicle_trajectory): a noise-free paper drive, all frames of
/// a run, the true pixels of a world point, mean and standard deviation, and a recording of a
/// VehicleTrajectory.
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {

inline constexpr double kDeg = M_PI / 180.0;

/// Runs a simulator to its end and keeps all frames.
inline std::vector<SimulatedFrame> runAll(MeasurementSimulator* sim) {
  std::vector<SimulatedFrame> frames;
  SimulatedFrame frame;
  while (sim->nextFrame(&frame)) frames.push_back(frame);
  return frames;
}

inline MeasurementScenario noiseFree() {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 300;
  s.pixel_noise = 0.0;
  s.motion_rotation_noise = 0.0;
  s.motion_translation_noise = 0.0;
  return s;
}

struct TruePixels {
  Eigen::Vector2d left, right;
};

/// Projects a world point with the frame's true pose and calibration, independently of the
/// simulator's internals (the task statement's formula).
inline TruePixels projectTruth(const MeasurementSimulator& sim, const SimulatedFrame& frame,
                               const Eigen::Vector3d& point_world) {
  const Eigen::Isometry3d T_lopt_world =
      (frame.T_world_veh * frame.truth.vehicleToLeftOptical()).inverse();
  const Eigen::Vector3d in_left = T_lopt_world * point_world;
  const Eigen::Vector3d in_right = frame.truth.leftToRightOptical().inverse() * in_left;
  TruePixels pixels;
  EXPECT_TRUE(sim.leftCamera().project(in_left, &pixels.left));
  EXPECT_TRUE(sim.rightCamera().project(in_right, &pixels.right));
  return pixels;
}

inline double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / v.size();
}

inline double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double sum = 0.0;
  for (double x : v) sum += (x - m) * (x - m);
  return std::sqrt(sum / (v.size() - 1));
}

/// Samples a VehicleTrajectory at 20 Hz from stamp 1000 into a PoseTrajectory (a recording).
inline std::shared_ptr<const PoseTrajectory> recordingOf(const VehicleMotionProfile& profile,
                                                         double seconds) {
  const VehicleTrajectory trajectory(profile);
  std::vector<StampedPose> poses;
  for (int k = 0; k * 0.05 <= seconds; ++k) {
    poses.push_back({1000.0 + k * 0.05, trajectory.pose(k * 0.05)});
  }
  return std::make_shared<const PoseTrajectory>(poses);
}

}  // namespace osc
