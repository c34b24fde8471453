/// @file pose_interpolation.cpp
/// @brief Stamped pose sequences and their linear + SLERP interpolation.
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace osc {

Eigen::Isometry3d interpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                  double fraction) {
  const Eigen::Quaterniond qa(a.rotation()), qb(b.rotation());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(fraction, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - fraction) * a.translation() + fraction * b.translation();
  return out;
}

PoseTrajectory::PoseTrajectory(std::vector<StampedPose> poses) {
  for (const StampedPose& p : poses) {
    if (!poses_.empty() && !(p.stamp > poses_.back().stamp)) {
      throw std::invalid_argument("PoseTrajectory: stamps must be strictly increasing");
    }
    append(p.stamp, p.pose);
  }
}

void PoseTrajectory::append(double stamp, const Eigen::Isometry3d& pose) {
  if (!std::isfinite(stamp)) throw std::invalid_argument("PoseTrajectory: stamp not finite");
  if (!poses_.empty() && stamp < poses_.back().stamp) {
    throw std::invalid_argument("PoseTrajectory: stamp older than the last one");
  }
  if (!poses_.empty() && stamp == poses_.back().stamp) {
    poses_.back().pose = pose;
    return;
  }
  poses_.push_back({stamp, pose});
}

void PoseTrajectory::pruneBefore(double stamp) {
  const auto upper = std::upper_bound(poses_.begin(), poses_.end(), stamp,
                                      [](double s, const StampedPose& p) { return s < p.stamp; });
  if (upper - poses_.begin() >= 2) poses_.erase(poses_.begin(), upper - 1);
}

std::optional<Eigen::Isometry3d> PoseTrajectory::at(double stamp, double tolerance) const {
  if (poses_.empty() || !std::isfinite(stamp)) return std::nullopt;
  if (stamp <= poses_.front().stamp) {
    if (poses_.front().stamp - stamp > tolerance) return std::nullopt;
    return poses_.front().pose;
  }
  if (stamp >= poses_.back().stamp) {
    if (stamp - poses_.back().stamp > tolerance) return std::nullopt;
    return poses_.back().pose;
  }
  const auto upper = std::upper_bound(poses_.begin(), poses_.end(), stamp,
                                      [](double s, const StampedPose& p) { return s < p.stamp; });
  const StampedPose& b = *upper;
  const StampedPose& a = *(upper - 1);
  const double fraction = (stamp - a.stamp) / (b.stamp - a.stamp);
  return interpolatePose(a.pose, b.pose, fraction);
}

std::optional<MotionIncrement> PoseTrajectory::motionBetween(double from, double to,
                                                             double tolerance) const {
  if (!(to > from)) return std::nullopt;
  const auto a = at(from, tolerance);
  const auto b = at(to, tolerance);
  if (!a || !b) return std::nullopt;
  MotionIncrement motion;
  motion.T_prev_curr = a->inverse() * (*b);
  motion.dt = to - from;
  return motion;
}

}  // namespace osc
