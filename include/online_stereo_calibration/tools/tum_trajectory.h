/// @file tum_trajectory.h
/// @brief Reading TUM trajectory files (`t x y z qx qy qz qw`) into a PoseTrajectory, and
/// writing poses as one (file I/O, so in tools; the interpolation itself is
/// core/geometry/pose_interpolation.h).
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

namespace osc {

/// Reads a TUM trajectory file: lines `t x y z qx qy qz qw` (pose of the body in the world),
/// '#' comments and blank lines skipped. @throws std::runtime_error naming the file and line
/// (unreadable, wrong field count, non-number, zero quaternion, stamps not increasing).
PoseTrajectory readTumTrajectory(const std::string& path);

/// @p poses as a TUM trajectory file's text: @p comment as '#' lines (one per line of it),
/// then `t x y z qx qy qz qw` per pose (stamps to the nanosecond, positions to 0.1 mm,
/// quaternions to 1e-9), which readTumTrajectory reads back.
std::string formatTumTrajectory(const std::vector<StampedPose>& poses, const std::string& comment);

}  // namespace osc
