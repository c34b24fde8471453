#include "online_stereo_calibration/core/filter/motion_excitation.h"

#include <algorithm>
#include <cmath>

#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

void MotionExcitation::reset() {
  // Start as if every axis had moved exactly as much as the noise: gain 0 until the motion
  // shows more (a conservative start; the window sets how fast it opens).
  const double sigma = config_.motion_rotation_noise;
  mean_square_.setConstant(sigma * sigma);
}

void MotionExcitation::update(const Eigen::Matrix3d& R_prev_curr, double dt) {
  if (!enabled() || !(dt > 0.0)) return;
  // Normalised to the reference period, where the configured noise sigma applies.
  const Eigen::Vector3d rotation = logSO3(R_prev_curr);
  const Eigen::Vector3d per_period = rotation.cwiseAbs2() / noiseScale(config_, dt);
  const double weight = std::min(1.0, dt / config_.motion_excitation_window);
  mean_square_ += weight * (per_period - mean_square_);
}

Eigen::Vector3d MotionExcitation::gains() const {
  if (!enabled()) return Eigen::Vector3d::Ones();
  const double noise = config_.motion_rotation_noise * config_.motion_rotation_noise;
  Eigen::Vector3d gain;
  for (int axis = 0; axis < 3; ++axis) {
    gain(axis) = mean_square_(axis) > 0.0 ? std::max(0.0, 1.0 - noise / mean_square_(axis)) : 0.0;
  }
  return gain;
}

std::array<bool, 3> unexcitedTranslationAxes(const Eigen::Vector3d& gains, double min_gain) {
  std::array<bool, 3> unexcited{};
  for (int axis = 0; axis < 3; ++axis) {
    const double other = std::max(gains((axis + 1) % 3), gains((axis + 2) % 3));
    unexcited[static_cast<size_t>(axis)] = !(other >= min_gain);
  }
  return unexcited;
}

Eigen::Matrix3d MotionExcitation::excitedRotation(const Eigen::Matrix3d& R_prev_curr) const {
  if (!enabled()) return R_prev_curr;
  return expSO3(gains().cwiseProduct(logSO3(R_prev_curr)));
}

}  // namespace osc
