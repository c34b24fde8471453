#include "online_stereo_calibration/core/estimator/mounting_from_motion.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Least vehicle translation (m) for a direction pair: below it the odometry's direction is
/// noise (and the camera's parallax is small anyway).
constexpr double kMinTranslation = 0.05;

}  // namespace

MountingFromMotion::MountingFromMotion(const CameraModel& left, const HandEyeRotationConfig& config)
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
  last_motion_usable_ = motion_usable && motion.T_prev_curr.matrix().allFinite();
  if (last_motion_usable_) fit = addMatches(motion, before, now);
  last_frame_paired_ = fit.valid;
  previous_.swap(current);
  return fit;
}

CameraMotion MountingFromMotion::addMatches(const MotionIncrement& motion,
                                            const std::vector<Eigen::Vector2d>& previous,
                                            const std::vector<Eigen::Vector2d>& current) {
  if (done_ || !motion.T_prev_curr.matrix().allFinite()) return CameraMotion();
  const CameraMotion fit = estimateCameraMotion(previous, current, motion_config_);
  if (fit.valid) {
    solver_.addRotationPair(motion.T_prev_curr.linear(), fit.R_prev_curr);
    if (motion.T_prev_curr.translation().norm() > kMinTranslation) {
      solver_.addDirectionPair(motion.T_prev_curr.translation(), fit.translation_direction);
    }
  }
  return fit;
}

void MountingFromMotion::clear() {
  previous_.clear();
  solver_.clear();
  done_ = false;
  last_motion_usable_ = last_frame_paired_ = false;
  pairs_at_last_solve_ = -1;
}

bool MountingFromMotion::checkFilter(const Eigen::Matrix3d& R_filter,
                                     const Eigen::Matrix3d& P_filter, double restart_distance,
                                     double min_restart_sigma, MountingRestart* restart) {
  const int pairs = solver_.rotationPairs() + solver_.directionPairs();
  if (done_ || pairs == pairs_at_last_solve_) return false;  // nothing new to solve with
  pairs_at_last_solve_ = pairs;
  const HandEyeRotationResult hand_eye = solver_.solve();
  if (!hand_eye.determined) return false;
  done_ = true;
  // The filter's error dtheta_f (R_true = R_filter Exp(dtheta_f)) and the hand-eye's error
  // (R_true = R_he Exp(dtheta_h)): their difference log(R_filter^T R_he) has covariance
  // P_filter + Ad P_he Ad^T, Ad = R_filter^T R_he (first order).
  // The hand-eye's covariance with every axis widened to min_restart_sigma, for the
  // comparison as for the restart: its own ignores the lever arm and correlated errors (a
  // forward camera guessed exactly was restarted in 1 of 10 drives with the raw one).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(hand_eye.covariance);
  const Eigen::Vector3d widened =
      eigen.eigenvalues().cwiseMax(min_restart_sigma * min_restart_sigma);
  const Eigen::Matrix3d hand_eye_covariance =
      eigen.eigenvectors() * widened.asDiagonal() * eigen.eigenvectors().transpose();
  const Eigen::Matrix3d relative = R_filter.transpose() * hand_eye.R_veh_cam;
  const Eigen::Vector3d difference = logSO3(relative);
  const Eigen::Matrix3d covariance =
      P_filter + relative * hand_eye_covariance * relative.transpose();
  const double distance = std::sqrt(difference.dot(covariance.ldlt().solve(difference)));
  if (!(distance > restart_distance)) return false;
  restart->R_veh_caml = hand_eye.R_veh_cam;
  restart->covariance = hand_eye_covariance;
  restart->distance = distance;
  restart->hand_eye = hand_eye;
  return true;
}

}  // namespace osc
