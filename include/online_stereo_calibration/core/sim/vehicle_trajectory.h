/// @file vehicle_trajectory.h
/// @brief Smooth analytic vehicle trajectory of the simulator, so that the true motion
/// increments between any two times are exact.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/sim/measurement_scenario.h"

namespace osc {

/// T_world_veh(t) for a VehicleMotionProfile. The world frame is z up with the vehicle at
/// the origin, heading along +x, at t = 0.
///
/// - yaw(t) = yaw_rate_amplitude * yaw_period / (2 pi) * (sin(2 pi t / yaw_period + phase)
///   - sin(phase)) with phase = yaw_phase, so the yaw rate is
///   yaw_rate_amplitude * cos(2 pi t / yaw_period + phase), the heading is 0 at t = 0 and
///   swings about +x (about +x + sin(phase) times the amplitude);
/// - the ground track (x, y) is the integral of speed * (cos yaw, sin yaw): constant speed;
/// - roll, pitch and heave (z) are sinusoids of their own periods (zero when planar);
/// - rotation R = Rz(yaw) * Ry(pitch) * Rx(roll).
///
/// Stops (profile.stops) are a time warp: every quantity at drive time t is the analytic
/// profile's at the profile time s(t) (profileTime()), whose rate s'(t) (profileRate()) is 1
/// while driving, 0 inside a stop, and moves between them along a smoothstep
/// 3u^2 - 2u^3 (u = fraction of the ramp) over stop_ramp seconds before the stop
/// (slow-down) and after it (speed-up). So the speed is speed * s'(t), continuous (C1
/// poses) for stop_ramp > 0; each ramp costs stop_ramp / 2 of profile time and each stop
/// its duration: after a stop, s(t) = t - sum(duration + stop_ramp). Without stops s(t) = t
/// exactly (the poses are bit-identical to a profile without the feature).
class VehicleTrajectory {
 public:
  /// @throws std::invalid_argument if a period is not positive or a value not finite.
  explicit VehicleTrajectory(const VehicleMotionProfile& profile);

  /// T_world_veh at time t (s).
  Eigen::Isometry3d pose(double t) const;
  /// Motion of the vehicle from t0 to t1, T_veh(t0)_veh(t1) = pose(t0)^-1 * pose(t1); exactly
  /// the identity when the profile clock stands still in between (both inside one stop).
  Eigen::Isometry3d motionBetween(double t0, double t1) const;

  /// Profile time s(t) (s) of drive time t: t minus the time lost to the stops up to t.
  double profileTime(double t) const;
  /// Rate ds/dt in [0, 1] at drive time t: the speed is profile().speed times this.
  double profileRate(double t) const;

  /// Heading (rad) at (drive) time t; likewise roll, pitch, heave and groundPosition.
  double yaw(double t) const;
  /// Body roll (rad) at time t.
  double roll(double t) const;
  /// Body pitch (rad) at time t.
  double pitch(double t) const;
  /// Vertical offset (m) at time t.
  double heave(double t) const;
  /// Ground-track position (x, y) in the world at time t.
  Eigen::Vector2d groundPosition(double t) const;

  const VehicleMotionProfile& profile() const { return profile_; }

 private:
  /// The analytic profile at profile time s (no stops).
  double analyticYaw(double s) const;
  Eigen::Vector2d analyticGroundPosition(double s) const;
  /// Integral of speed * (cos yaw, sin yaw) over profile times [0, tau], by Gauss-Legendre
  /// quadrature.
  Eigen::Vector2d integrateGroundTrack(double tau) const;

  VehicleMotionProfile profile_;
  /// sin(yaw_phase): analyticYaw subtracts it so that the heading is 0 at t = 0.
  double sin_yaw_phase_ = 0.0;
  /// Ground-track displacement over one full steering period (yaw is periodic, so the track
  /// repeats itself shifted by this vector).
  Eigen::Vector2d period_displacement_;
};

}  // namespace osc
