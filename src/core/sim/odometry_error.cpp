/// @file odometry_error.cpp
/// @brief Scale error and Gauss-Markov biases of simulated odometry (see odometry_error.h).
#include "online_stereo_calibration/core/sim/odometry_error.h"

#include <algorithm>
#include <cmath>

#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

OdometryErrorProcess::OdometryErrorProcess(const OdometryErrorModel& model, unsigned seed)
    : model_(model),
      zero_(model.scale_error == 0.0 && model.rotation_rate_bias == 0.0 &&
            model.velocity_bias == 0.0) {
  std::seed_seq sequence{seed, kRandomStream};
  engine_.seed(sequence);
  // Start in the steady state, so the statistics hold from the first increment on.
  if (model_.rotation_rate_bias > 0.0 || model_.velocity_bias > 0.0) {
    for (int i = 0; i < 3; ++i)
      rotation_rate_bias_(i) = model_.rotation_rate_bias * normal_(engine_);
    for (int i = 0; i < 3; ++i) velocity_bias_(i) = model_.velocity_bias * normal_(engine_);
  }
}

void OdometryErrorProcess::advance(double dt) {
  if (!(model_.rotation_rate_bias > 0.0 || model_.velocity_bias > 0.0)) return;
  // Exact discretisation of db/dt = -b / tau + white noise with steady-state std sigma.
  // Both biases draw every step, so enabling one does not change the other's realisation.
  const double phi = std::exp(-dt / model_.bias_correlation_time);
  const double innovation = std::sqrt(std::max(0.0, 1.0 - phi * phi));
  for (int i = 0; i < 3; ++i) {
    rotation_rate_bias_(i) =
        phi * rotation_rate_bias_(i) + model_.rotation_rate_bias * innovation * normal_(engine_);
  }
  for (int i = 0; i < 3; ++i) {
    velocity_bias_(i) =
        phi * velocity_bias_(i) + model_.velocity_bias * innovation * normal_(engine_);
  }
}

MotionIncrement OdometryErrorProcess::apply(const MotionIncrement& truth) {
  if (zero_) return truth;
  MotionIncrement reported = truth;
  Vector6d bias;
  bias << truth.dt * velocity_bias_, truth.dt * rotation_rate_bias_;
  reported.T_prev_curr.translation() *= 1.0 + model_.scale_error;
  reported.T_prev_curr = boxPlus(reported.T_prev_curr, bias);
  advance(truth.dt);
  return reported;
}

}  // namespace osc
