/// @file pose_interpolation.cpp
/// @brief Stamped pose sequences and their linear + SLERP interpolation.
#include "online_stereo_calibration/tools/pose_interpolation.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
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

PoseTrajectory readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open TUM trajectory '" + path + "'");
  PoseTrajectory trajectory;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (double& x : v) {
      if (!(fields >> x) || !std::isfinite(x)) {
        throw std::runtime_error(path + ":" + std::to_string(number) +
                                 ": expected 8 numbers 't x y z qx qy qz qw'");
      }
    }
    std::string extra;
    if (fields >> extra) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": more than 8 fields");
    }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": zero quaternion");
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    if (!trajectory.empty() && !(v[0] > trajectory.lastStamp())) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": stamp not increasing");
    }
    trajectory.append(v[0], pose);
  }
  if (trajectory.size() < 2) throw std::runtime_error(path + ": fewer than 2 poses");
  return trajectory;
}

}  // namespace osc
