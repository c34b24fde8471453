/// @file tum_trajectory.h
/// @brief Reading TUM trajectory files (`t x y z qx qy qz qw`) into a PoseTrajectory (file
/// I/O, so in tools; the interpolation itself is core/geometry/pose_interpolation.h).
#pragma once

#include <string>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

namespace osc {

/// Reads a TUM trajectory file: lines `t x y z qx qy qz qw` (pose of the body in the world),
/// '#' comments and blank lines skipped. @throws std::runtime_error naming the file and line
/// (unreadable, wrong field count, non-number, zero quaternion, stamps not increasing).
PoseTrajectory readTumTrajectory(const std::string& path);

}  // namespace osc
