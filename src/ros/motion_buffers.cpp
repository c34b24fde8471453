/// @file motion_buffers.cpp
/// @brief PoseBuffer and GyroIntegrator.
#include "online_stereo_calibration/ros/motion_buffers.h"

#include <algorithm>
#include <cmath>

namespace online_stereo_calibration {

std::string lookupStatusName(LookupStatus status) {
  switch (status) {
    case LookupStatus::kOk:
      return "ok";
    case LookupStatus::kNotYet:
      return "no motion sample after the image stamp yet";
    case LookupStatus::kTooOld:
      return "image stamp older than the motion history";
    case LookupStatus::kGap:
      return "gap in the motion samples around the image stamp";
    case LookupStatus::kEmpty:
      return "no motion sample received";
  }
  return "unknown";
}

bool PoseBuffer::add(const StampedPose& sample) {
  if (!std::isfinite(sample.stamp) || !sample.pose.matrix().allFinite()) return false;
  if (!samples_.empty() && !(sample.stamp > samples_.back().stamp)) return false;
  samples_.push_back(sample);
  while (samples_.size() > 2 && samples_.front().stamp < sample.stamp - history_) {
    samples_.pop_front();
  }
  return true;
}

PoseBuffer::Offered PoseBuffer::offer(const StampedPose& sample) {
  if (!std::isfinite(sample.stamp) || !sample.pose.matrix().allFinite()) return Offered::kRejected;
  if (samples_.empty() || sample.stamp >= samples_.back().stamp - max_gap_) {
    if (!add(sample)) return Offered::kRejected;
    held_back_.clear();
    return Offered::kAdded;
  }
  const bool continues = !held_back_.empty() && sample.stamp > held_back_.back().stamp &&
                         sample.stamp - held_back_.back().stamp <= max_gap_;
  if (!continues) held_back_.clear();
  held_back_.push_back(sample);
  if (static_cast<int>(held_back_.size()) < kSamplesToRestart) return Offered::kHeldBack;
  restart();
  return Offered::kRestarted;
}

void PoseBuffer::restart() {
  samples_.swap(held_back_);
  held_back_.clear();
}

LookupStatus PoseBuffer::poseAt(double stamp, Eigen::Isometry3d* pose) const {
  if (samples_.empty()) return LookupStatus::kEmpty;
  if (stamp > samples_.back().stamp) return LookupStatus::kNotYet;
  if (stamp < samples_.front().stamp) return LookupStatus::kTooOld;
  auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp,
                                [](const StampedPose& s, double t) { return s.stamp < t; });
  if (after->stamp == stamp) {
    *pose = after->pose;
    return LookupStatus::kOk;
  }
  auto before = after - 1;
  if (after->stamp - before->stamp > max_gap_) return LookupStatus::kGap;
  *pose = interpolatePose(*before, *after, stamp);
  return LookupStatus::kOk;
}

bool PoseBuffer::twistAt(double stamp, osc::Vector6d* twist) const {
  if (samples_.empty() || !(stamp >= samples_.front().stamp && stamp <= samples_.back().stamp))
    return false;
  auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp,
                                [](const StampedPose& s, double t) { return s.stamp < t; });
  if (after->stamp == stamp) {
    if (after->has_twist) *twist = after->twist;
    return after->has_twist;
  }
  auto before = after - 1;
  if (after->stamp - before->stamp > max_gap_ || !before->has_twist || !after->has_twist)
    return false;
  const double s = (stamp - before->stamp) / (after->stamp - before->stamp);
  *twist = (1.0 - s) * before->twist + s * after->twist;
  return true;
}

bool PoseBuffer::incrementCovariance(double from, double to,
                                     Eigen::Matrix<double, 6, 6>* covariance) const {
  if (samples_.size() < 2 || !(to > from) || from < samples_.front().stamp ||
      to > samples_.back().stamp) {
    return false;
  }
  covariance->setZero();
  for (size_t i = 1; i < samples_.size(); ++i) {
    const double overlap = std::min(to, samples_[i].stamp) - std::max(from, samples_[i - 1].stamp);
    if (overlap <= 0.0) continue;
    if (!samples_[i].has_twist_covariance) return false;
    *covariance += samples_[i].twist_covariance * (overlap * overlap);
  }
  return true;
}

bool GyroIntegrator::add(double stamp, const Eigen::Vector3d& angular_rate) {
  if (!std::isfinite(stamp) || !angular_rate.allFinite()) return false;
  if (!samples_.empty() && !(stamp > samples_.back().stamp)) return false;
  samples_.push_back({stamp, angular_rate});
  while (samples_.size() > 2 && samples_.front().stamp < stamp - history_) samples_.pop_front();
  return true;
}

LookupStatus GyroIntegrator::rotationBetween(double from, double to,
                                             Eigen::Matrix3d* rotation) const {
  if (samples_.empty()) return LookupStatus::kEmpty;
  if (to > samples_.back().stamp) return LookupStatus::kNotYet;
  if (from < samples_.front().stamp) return LookupStatus::kTooOld;
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (size_t i = 0; i + 1 < samples_.size(); ++i) {
    const double t0 = std::max(samples_[i].stamp, from);
    const double t1 = std::min(samples_[i + 1].stamp, to);
    if (t1 <= t0) continue;
    if (samples_[i + 1].stamp - samples_[i].stamp > max_gap_) return LookupStatus::kGap;
    const Eigen::Vector3d angle = samples_[i].rate * (t1 - t0);
    const double norm = angle.norm();
    if (norm > 0.0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(norm, angle / norm));
  }
  *rotation = q.normalized().toRotationMatrix();
  return LookupStatus::kOk;
}

}  // namespace online_stereo_calibration
