/// @file pose_interpolation.h
/// @brief Stamped pose sequences (odometry, recorded trajectories) and their interpolation to
/// arbitrary stamps: linear in translation, SLERP in rotation. Eigen only, no ROS and no file
/// I/O (tools/tum_trajectory.h reads TUM files), so the core simulator, the offline tools and
/// the nodelet share it.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"

namespace osc {

/// A pose T_fixed_body at a time (s).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// Linear (translation) + SLERP (rotation) interpolation between two poses, @p fraction in
/// [0, 1] (0 gives @p a, 1 gives @p b; values outside extrapolate).
Eigen::Isometry3d interpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                  double fraction);

/// A time-ordered sequence of poses that can be queried at any stamp within its span.
class PoseTrajectory {
 public:
  PoseTrajectory() = default;
  /// @throws std::invalid_argument if the stamps are not strictly increasing or not finite.
  explicit PoseTrajectory(std::vector<StampedPose> poses);

  /// Appends a pose. A stamp equal to the last one replaces it; an older stamp throws
  /// std::invalid_argument (callers buffering live data should drop such messages first).
  void append(double stamp, const Eigen::Isometry3d& pose);
  /// Forgets the poses older than the one just before @p stamp (keeps what at(stamp) needs).
  void pruneBefore(double stamp);

  /// The pose at @p stamp, interpolated between the two samples around it; nothing if the
  /// stamp lies outside [firstStamp(), lastStamp()] by more than @p tolerance (s) (within the
  /// tolerance the end pose is returned) or the sequence is empty.
  std::optional<Eigen::Isometry3d> at(double stamp, double tolerance = 0.0) const;

  /// As at(), but a C1 curve through the samples: cubic Hermite per interval, in the world
  /// translation and in the rotation's tangent space at the interval's start (R_a Exp(phi(s))),
  /// with Catmull-Rom tangents (central differences over the neighbouring samples; one-sided
  /// at both ends). Velocity and angular rate are continuous at the samples, as a vehicle's
  /// are, where at()'s linear pieces jump: the simulators use it for recorded drives, whose
  /// twists must be the derivative of the pose over a time offset (issue 15).
  std::optional<Eigen::Isometry3d> smoothAt(double stamp, double tolerance = 0.0) const;

  /// Motion of the body from stamp @p from to stamp @p to: T_prev_curr = T(from)^-1 * T(to),
  /// dt = to - from. Nothing if either pose is unavailable (see at()) or to <= from.
  std::optional<MotionIncrement> motionBetween(double from, double to,
                                               double tolerance = 0.0) const;

  bool empty() const { return poses_.empty(); }
  std::size_t size() const { return poses_.size(); }
  double firstStamp() const { return poses_.front().stamp; }
  double lastStamp() const { return poses_.back().stamp; }
  const std::vector<StampedPose>& poses() const { return poses_; }

 private:
  std::vector<StampedPose> poses_;
};

}  // namespace osc
