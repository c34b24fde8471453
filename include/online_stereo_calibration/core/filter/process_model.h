/// @file process_model.h
/// @brief Prediction of the state between two image pairs (seed Sec. II-B).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/types.h"
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

/// The same for a homogeneous point [d; w] (position d / w, point_coordinates.h): the motion
/// is affine in the position, p -> A p + c, so [d; w] -> [A d + c w; w], defined also for a
/// point at infinity (w = 0).
Eigen::Vector4d predictHomogeneousPoint(const Eigen::Vector4d& point_lopt,
                                        const Eigen::Isometry3d& T_veh_lopt,
                                        const Eigen::Isometry3d& T_prev_curr,
                                        const Eigen::Vector3d& position_error,
                                        const Eigen::Matrix3d& R_excited);

/// The vehicle's body twist [v (3), w (3)] (m/s, rad/s, in the vehicle frame at that
/// instant) at the start and at the end of one motion increment.
struct MotionTwists {
  Vector6d start = Vector6d::Zero();
  Vector6d end = Vector6d::Zero();
};

/// How many earlier increments twistsAtEnds fits its trend to.
constexpr int kTwistTrendIncrements = 2;

/// The twists at the ends of @p current: the odometry's own if it gave them
/// (MotionIncrement::has_twists), else from the increments before it (oldest first, the
/// last one ending where @p current starts): a least-squares line through their mean
/// twists log(T) / dt, extrapolated over @p current. The current increment's own mean is
/// not used: its noise would then enter both the measured motion and its correction, and
/// the time offset would be fitted to cancel that noise (measured: +5-10 ms of bias at the
/// paper's motion noise). The lagged trend misses part of the change instead: measured, it
/// shrinks the estimated offset to about 0.8 x (more with a longer window). With fewer than
/// two earlier increments both ends get the current mean twist (no correction).
MotionTwists twistsAtEnds(const std::vector<MotionIncrement>& earlier,
                          const MotionIncrement& current);

/// Our model of the odometry's time offset (issue 15; not in the paper). The odometry's
/// sample stamped t holds the vehicle at camera time t + d (d = `time_offset`: the camera
/// clock minus the odometry's), so the increment read at the image stamps t0 and t1 is
/// M = T(t0 + d)^-1 T(t1 + d). With T(t + d) = T(t) Exp(d xi(t))
/// (xi: body twist), the vehicle's true motion between the two image pairs is
///   T(t0)^-1 T(t1) = Exp(d xi(t0)) M Exp(-d xi(t1)).
/// A constant twist gives M back whatever d: only a change of motion shows the offset.
Eigen::Isometry3d correctedMotion(const Eigen::Isometry3d& measured, double time_offset,
                                  const MotionTwists& twists);

/// Covariance [dt (3), dtheta (3)] of what correctedMotion leaves out. It takes each end's
/// twist as constant over the offset d, so each end errs by about a d^2 / 2 (a: the twist's
/// rate there); the two ends cancel for a steady rate and not for a jerky one. An empirical
/// scale, not a derivation: with a taken as the change of twist over the increment,
/// |xi(t1) - xi(t0)| / dt, each axis gets the 1 sigma factor * |change| E[d^2] / dt, where
/// E[d^2] = offset^2 + its variance (the linear part is the offset state's own Jacobian).
/// Measured on the recorded walking rig (udel_gore, d = 18 ms): the first-order model
/// errs by 0.07 deg median, 0.18 deg p95 per 0.1 s step, 3-9x the default motion noise;
/// its gated-out points were taken for jumps of x_caml (docs/RESULTS.md "Session 16").
Matrix6d timeOffsetModelCovariance(const MotionTwists& twists, double dt,
                                   double offset_second_moment, double factor);

/// Variance scale of a per-step noise for a step of dt seconds (random walk: dt / T_ref).
double noiseScale(const FilterConfig& config, double dt);

/// Seed eq. 10-13: calibration drift covariance over dt, in the filter's error layout.
Matrix12d calibrationDriftCovariance(const FilterConfig& config, double dt);

/// Factors on the variance of the calibration's random walk (eq. 10-13) per block; 1 = as
/// configured. The consistency monitor's (consistency_monitor.h) for the filter's prediction.
struct DriftInflation {
  double caml = 1.0;  ///< x_caml
  double camr = 1.0;  ///< x_camr
  bool operator==(const DriftInflation& o) const { return caml == o.caml && camr == o.camr; }
};

/// Covariance of the error of one measured motion increment [dt (3), dtheta (3)] over dt
/// (shared motion-noise model; eq. 15 for the rotation).
Matrix6d motionNoiseCovariance(const FilterConfig& config, double dt);

/// What the odometry's scale uncertainty (FilterConfig::odometry_scale_sigma) adds to the
/// covariance of the translations of @p extrinsics, in the calibration's error layout (equal
/// to its parameters' for translations); zero when the scale is exact.
Matrix12d odometryScaleCovariance(const FilterConfig& config, const StereoExtrinsics& extrinsics);

/// Seed eq. 14-27: the paper's diagonal process noise of one point, computed in the camera
/// *body* axes (x forward, y left, z up, as the paper's figures) and returned in the left
/// optical frame. sigma_imu: angular motion error (rad); sigma_p: eq. 14 (m).
Eigen::Matrix3d paperPointProcessNoise(const Eigen::Vector3d& point_lopt, double sigma_imu,
                                       double sigma_p);

}  // namespace osc
