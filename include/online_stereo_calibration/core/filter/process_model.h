/// @file process_model.h
/// @brief Prediction of the state between two image pairs (seed Sec. II-B).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// Seed eq. 7-8: a static point known in the left optical frame at k-1, expressed in the
/// left optical frame at k: p_k = T_veh_lopt^-1 * T_prev_curr^-1 * T_veh_lopt * p_{k-1}.
Eigen::Vector3d predictPoint(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_veh_lopt,
                             const Eigen::Isometry3d& T_prev_curr);

/// Eq. 7-8 at a sigma point whose camera position T_veh_lopt carries the error
/// `position_error` (vehicle frame): the error acts through the excited part R_excited of the
/// motion rotation (motion_excitation.h) instead of the measured one, i.e.
/// predictPoint(...) + R_lopt^T (R_excited^T - R_motion^T) position_error. With
/// R_excited == R_motion this is predictPoint.
Eigen::Vector3d predictPoint(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_veh_lopt,
                             const Eigen::Isometry3d& T_prev_curr,
                             const Eigen::Vector3d& position_error,
                             const Eigen::Matrix3d& R_excited);

/// Variance scale of a per-step noise for a step of dt seconds (random walk: dt / T_ref).
double noiseScale(const FilterConfig& config, double dt);

/// Seed eq. 10-13: calibration drift covariance over dt, in the filter's error layout.
Matrix12d calibrationDriftCovariance(const FilterConfig& config, double dt);

/// Covariance of the error of one measured motion increment [dt (3), dtheta (3)] over dt
/// (shared motion-noise model; eq. 15 for the rotation).
Matrix6d motionNoiseCovariance(const FilterConfig& config, double dt);

/// Seed eq. 14-27: the paper's diagonal process noise of one point, computed in the camera
/// *body* axes (x forward, y left, z up, as the paper's figures) and returned in the left
/// optical frame. sigma_imu: angular motion error (rad); sigma_p: eq. 14 (m).
Eigen::Matrix3d paperPointProcessNoise(const Eigen::Vector3d& point_lopt, double sigma_imu,
                                       double sigma_p);

}  // namespace osc
