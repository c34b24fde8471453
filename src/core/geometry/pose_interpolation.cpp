/// @file pose_interpolation.cpp
/// @brief Stamped pose sequences and their linear + SLERP interpolation.
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

namespace {

/// Inverse of the right Jacobian of SO(3): d phi = J_r(phi)^-1 w dt for R Exp(phi).
Eigen::Matrix3d inverseRightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 12.0;
  const double c =
      1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * K + c * K * K;
}

/// Cubic Hermite basis on [0, 1]: value at s from the end values and end slopes (per unit s).
template <typename V>
V hermite(const V& p0, const V& p1, const V& m0, const V& m1, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 +
         (s3 - s2) * m1;
}

}  // namespace

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

std::optional<Eigen::Isometry3d> PoseTrajectory::smoothAt(double stamp, double tolerance) const {
  if (poses_.size() < 3 || !std::isfinite(stamp) || stamp <= poses_.front().stamp ||
      stamp >= poses_.back().stamp) {
    return at(stamp, tolerance);  // the ends, outside, or a single interval: as at()
  }
  const auto upper = std::upper_bound(poses_.begin(), poses_.end(), stamp,
                                      [](double s, const StampedPose& p) { return s < p.stamp; });
  const std::size_t i = static_cast<std::size_t>(upper - poses_.begin()) - 1;  // [i, i + 1]
  const StampedPose& a = poses_[i];
  const StampedPose& b = poses_[i + 1];
  const double h = b.stamp - a.stamp;
  // Catmull-Rom: the tangent at sample k from its neighbours (one-sided at the ends).
  const auto neighbours = [this](std::size_t k) {
    return std::make_pair(k == 0 ? k : k - 1, k + 1 == poses_.size() ? k : k + 1);
  };
  const auto velocity = [this, &neighbours](std::size_t k) -> Eigen::Vector3d {
    const auto [lo, hi] = neighbours(k);
    return (poses_[hi].pose.translation() - poses_[lo].pose.translation()) /
           (poses_[hi].stamp - poses_[lo].stamp);
  };
  // Body angular rate at k: the rotation vectors of the two intervals around it have the same
  // axis in both of their end frames, so they add in k's frame.
  const auto rate = [this, &neighbours](std::size_t k) -> Eigen::Vector3d {
    const auto [lo, hi] = neighbours(k);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (lo < k) sum += logSO3(poses_[lo].pose.linear().transpose() * poses_[k].pose.linear());
    if (hi > k) sum += logSO3(poses_[k].pose.linear().transpose() * poses_[hi].pose.linear());
    return sum / (poses_[hi].stamp - poses_[lo].stamp);
  };
  const double s = (stamp - a.stamp) / h;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() = hermite<Eigen::Vector3d>(a.pose.translation(), b.pose.translation(),
                                               velocity(i) * h, velocity(i + 1) * h, s);
  // R(s) = R_a Exp(phi(s)): phi(0) = 0, phi(1) = log(R_a^T R_b), body rate J_r(phi) phi' / h.
  const Eigen::Vector3d phi1 = logSO3(a.pose.linear().transpose() * b.pose.linear());
  const Eigen::Vector3d phi =
      hermite<Eigen::Vector3d>(Eigen::Vector3d::Zero(), phi1, rate(i) * h,
                               inverseRightJacobianSO3(phi1) * rate(i + 1) * h, s);
  out.linear() = a.pose.linear() * expSO3(phi);
  return out;
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
