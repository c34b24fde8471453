#include "online_stereo_calibration/core/estimator/mounting_from_motion.h"

namespace osc {
namespace {

/// Least vehicle translation (m) for a direction pair: below it the odometry's direction is
/// noise (and the camera's parallax is small anyway).
constexpr double kMinTranslation = 0.05;

}  // namespace

MountingFromMotion::MountingFromMotion(const CameraModel& left,
                                       const HandEyeRotationConfig& config)
    : left_(left), solver_(config) {
  motion_config_.focal = 0.5 * (left_.K()(0, 0) + left_.K()(1, 1));
}

CameraMotion MountingFromMotion::addFrame(const MotionIncrement& motion, bool motion_usable,
                                          const std::vector<StereoObservation>& observations) {
  std::unordered_map<PointId, Eigen::Vector2d> current;
  current.reserve(observations.size());
  std::vector<Eigen::Vector2d> before, now;
  for (const StereoObservation& o : observations) {
    Eigen::Vector2d normalized;
    if (!o.left_pixel.allFinite() || !left_.pixelToNormalized(o.left_pixel, &normalized)) {
      continue;
    }
    current[o.id] = normalized;
    const auto it = previous_.find(o.id);
    if (it == previous_.end()) continue;
    before.push_back(it->second);
    now.push_back(normalized);
  }
  CameraMotion fit;
  if (motion_usable && motion.T_prev_curr.matrix().allFinite()) {
    fit = estimateCameraMotion(before, now, motion_config_);
    if (fit.valid) {
      solver_.addRotationPair(motion.T_prev_curr.linear(), fit.R_prev_curr);
      if (motion.T_prev_curr.translation().norm() > kMinTranslation) {
        solver_.addDirectionPair(motion.T_prev_curr.translation(), fit.translation_direction);
      }
    }
  }
  previous_.swap(current);
  return fit;
}

void MountingFromMotion::clear() {
  previous_.clear();
  solver_.clear();
}

}  // namespace osc
