/// @file convergence.h
/// @brief When a calibration counts as converged (issue 14: an honest and reachable state):
/// every parameter's 3-sigma within its block's bound, except the x_caml translations the
/// recent vehicle motion does not determine, which are reported instead of waited for.
#pragma once

#include <vector>

#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"

namespace osc {

/// 3-sigma bounds, per block of parameters (m, rad). The defaults are reached by the
/// paper-like off-road drive (docs/ros.md).
struct ConvergenceThresholds {
  double caml_translation = 0.05;                       ///< m, xl yl zl
  double caml_rotation = 0.3 * 0.0174532925199432958;   ///< rad, roll_l pitch_l yaw_l
  double camr_translation = 0.003;                      ///< m, xr yr zr
  double camr_rotation = 0.05 * 0.0174532925199432958;  ///< rad, roll_r pitch_r yaw_r
};

/// The 3-sigma bound of parameter @p index (interface order).
double convergenceBound(const ConvergenceThresholds& thresholds, int index);

/// The parameters (interface order) the data do not determine, so that their sigma may stay
/// wide without blocking convergence: x_caml translations along a vehicle axis whose two
/// other axes have not rotated beyond the motion noise lately (unexcitedTranslationAxes of
/// estimate.excitation) and whose 3-sigma is above its bound (a parameter already learned
/// is not excused); and scaleLimitedParameters().
std::vector<int> undeterminedParameters(const CalibrationEstimate& estimate,
                                        const ConvergenceThresholds& thresholds);

/// The translations whose 3-sigma is above its bound only because of the odometry's scale
/// uncertainty (FilterConfig::odometry_scale_sigma), which no drive reduces: within the
/// bound without it (CalibrationEstimate::odometry_scale_covariance).
std::vector<int> scaleLimitedParameters(const CalibrationEstimate& estimate,
                                        const ConvergenceThresholds& thresholds);

/// Every parameter's 3-sigma within its bound, undeterminedParameters() excepted.
bool isConverged(const CalibrationEstimate& estimate, const ConvergenceThresholds& thresholds);

}  // namespace osc
