/// @file motion_excitation.h
/// @brief How much of a measured vehicle rotation is real excitation rather than sensor noise.
///
/// The camera position enters the point prediction (eq. 8) only through
/// R_lopt^T (R_motion^T - I) t_l: it is learned from the vehicle's rotation, zl from its roll
/// and pitch (seed Sec. II-D). Linearised at the *measured* rotation, the roll/pitch noise of
/// the motion sensor (0.02 deg per step) looks like excitation, and on a flat road the filter
/// would learn zl from noise alone and become overconfident. This class keeps a running mean
/// square of the measured rotation per vehicle axis and shrinks each axis by the empirical
/// Bayes (Wiener / positive-part James-Stein) factor max(0, 1 - sigma^2 / mean square):
/// an axis that rotates no more than the sensor noise gives no lever-arm information; a
/// strongly excited axis is used as measured.
#pragma once

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/config/filter_config.h"

namespace osc {

class MotionExcitation {
 public:
  explicit MotionExcitation(const FilterConfig& config) : config_(config) { reset(); }

  /// Forgets the history: no axis counts as excited until motion is seen.
  void reset();

  /// Adds one measured motion increment (rotation R_prev_curr over dt seconds).
  void update(const Eigen::Matrix3d& R_prev_curr, double dt);

  /// Shrinkage factor in [0, 1] per vehicle axis (roll, pitch, yaw); all 1 when disabled.
  Eigen::Vector3d gains() const;

  /// The part of R_prev_curr that is excitation: Exp(gains .* Log(R_prev_curr)).
  Eigen::Matrix3d excitedRotation(const Eigen::Matrix3d& R_prev_curr) const;

  /// Whether the shrinkage is on (config: motion_excitation_window_s > 0).
  bool enabled() const { return config_.motion_excitation_window > 0.0; }

 private:
  FilterConfig config_;
  /// Running mean square of the rotation per axis, per reference period (rad^2).
  Eigen::Vector3d mean_square_ = Eigen::Vector3d::Zero();
};

/// Which of x_caml's translation axes (vehicle x, y, z) the recent motion does not determine.
/// The camera position enters the prediction only through (R_motion^T - I) t_l (eq. 8), so a
/// rotation about one axis shows the position along the other two: zl needs roll or pitch,
/// yl roll or yaw, xl pitch or yaw. An axis counts as excited with a MotionExcitation gain of
/// at least @p min_gain. @p gains: roll, pitch, yaw.
std::array<bool, 3> unexcitedTranslationAxes(const Eigen::Vector3d& gains, double min_gain = 0.1);

}  // namespace osc
