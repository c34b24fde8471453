/// @file right_rotation_seed.h
/// @brief x_camr as a whole-image stereo fit gives it (global_stereo_fit.h), in the filter's
/// terms, with an honest covariance, and how far the filter's estimate is from it (issue 14:
/// the global stereo fit at start).
#pragma once

#include <Eigen/Core>

#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// The fit's x_camr. Frames: body (x forward, y left, z up); tangent as the filter's
/// (pose.h boxPlus: [dt, dtheta], dtheta right-multiplied in the right camera's body frame).
struct RightRotationSeed {
  bool valid = false;  ///< the fit was valid
  /// x_camr from the fit: its rotation, and the estimate's baseline length along the fit's
  /// baseline direction (which is the estimate's, refined with it as the prior).
  Eigen::Isometry3d T_caml_camr = Eigen::Isometry3d::Identity();
  /// Tangent covariance of T_caml_camr (m, rad): the fit's joint covariance of rotation and
  /// direction (the direction's scaled by the length), the estimate's length variance along
  /// the direction, and the least sigmas added in quadrature (rightRotationSeed).
  Matrix6d covariance = Matrix6d::Zero();
  /// Mahalanobis distance (3 dof) between the estimate's x_camr rotation and the fit's, with
  /// both rotation covariances.
  double distance = 0.0;
  double angle = 0.0;  ///< rad: the angle between the two rotations
};

/// The prior to give the fit (GlobalStereoFitConfig::baseline_direction_covariance): x_camr's
/// translation covariance in @p covariance (filter tangent) as a change of the baseline
/// direction in the left optical frame (perpendicular part, divided by the length).
Eigen::Matrix3d baselineDirectionCovariance(const StereoExtrinsics& estimate,
                                            const Matrix12d& covariance);

/// The seed from @p fit, fitted at @p estimate's baseline direction with the prior
/// baselineDirectionCovariance(estimate, covariance) (or held there), and its distance from
/// @p estimate whose filter tangent covariance is @p covariance. @p min_sigma (rad) is added
/// in quadrature per rotation axis (FilterConfig::stereo_fit_min_sigma), and
/// @p min_sigma_along_lines (rad) about the axis across the baseline and the optical axis,
/// whose rotation slides points along their epipolar lines
/// (FilterConfig::stereo_fit_min_sigma_along_lines). Not valid if the fit is not.
RightRotationSeed rightRotationSeed(const GlobalStereoFit& fit, const StereoExtrinsics& estimate,
                                    const Matrix12d& covariance, double min_sigma,
                                    double min_sigma_along_lines = 0.0);

}  // namespace osc
