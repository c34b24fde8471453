/// @file odometry_error.h
/// @brief The systematic and slowly varying odometry errors of an OdometryErrorModel (scale
/// error, Gauss-Markov angular-rate and velocity biases), applied to motion increments. The
/// one place of this arithmetic: the measurement-level simulator (per frame) and the
/// image-level drive's odometry (per odometry sample) both use it.
#pragma once

#include <random>

#include <Eigen/Core>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"

namespace osc {

/// State of the odometry errors along one drive. The time offset is not applied here (it
/// selects which true interval an increment covers; the caller takes the true increment
/// between t0 + time_offset and t1 + time_offset and hands it to apply()).
///
/// Each bias b (3 axes, independent) is a first-order Gauss-Markov process of steady-state
/// std sigma and correlation time tau: E[b(t) b(t + h)] = sigma^2 exp(-|h| / tau). It starts
/// in its steady state (b(0) ~ N(0, sigma^2)) and is propagated exactly over each step dt:
/// b <- phi b + sigma sqrt(1 - phi^2) w, phi = exp(-dt / tau), w ~ N(0, 1).
class OdometryErrorProcess {
 public:
  /// Stream number of the random stream (seeded with (seed, kRandomStream)) of the biases;
  /// the measurement-level simulator's other streams are 1-3 (tracks, pixels, white motion
  /// noise), so enabling a bias changes none of them.
  static constexpr unsigned kRandomStream = 4;

  /// @p model must be valid (MeasurementScenario::validate()).
  OdometryErrorProcess(const OdometryErrorModel& model, unsigned seed);

  /// True if scale_error and both biases are zero: apply() then returns its input unchanged.
  bool isZero() const { return zero_; }

  /// The reported increment for the true increment @p truth over truth.dt (s): translation
  /// (1 + scale_error) * t + b_v * dt (in the previous vehicle frame, as t), rotation
  /// R * Exp(b_w * dt) (rotation-rate bias about the vehicle's axes; boxPlus convention),
  /// with the biases' values at the start of the increment; then advances the biases by dt.
  /// dt unchanged.
  MotionIncrement apply(const MotionIncrement& truth);

  /// Current angular-rate bias b_w (rad/s, vehicle frame).
  const Eigen::Vector3d& rotationRateBias() const { return rotation_rate_bias_; }
  /// Current velocity bias b_v (m/s, vehicle frame).
  const Eigen::Vector3d& velocityBias() const { return velocity_bias_; }

 private:
  void advance(double dt);

  OdometryErrorModel model_;
  bool zero_ = true;
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Vector3d rotation_rate_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_bias_ = Eigen::Vector3d::Zero();
};

}  // namespace osc
