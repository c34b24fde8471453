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
/// - yaw(t) = yaw_rate_amplitude * yaw_period / (2 pi) * sin(2 pi t / yaw_period), so the yaw
///   rate is yaw_rate_amplitude * cos(2 pi t / yaw_period) and the heading swings about +x;
/// - the ground track (x, y) is the integral of speed * (cos yaw, sin yaw): constant speed;
/// - roll, pitch and heave (z) are sinusoids of their own periods (zero when planar);
/// - rotation R = Rz(yaw) * Ry(pitch) * Rx(roll).
class VehicleTrajectory {
 public:
  /// @throws std::invalid_argument if a period is not positive or a value not finite.
  explicit VehicleTrajectory(const VehicleMotionProfile& profile);

  /// T_world_veh at time t (s).
  Eigen::Isometry3d pose(double t) const;

  /// Heading (rad) at time t.
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
  /// Integral of speed * (cos yaw, sin yaw) over [0, tau], by Gauss-Legendre quadrature.
  Eigen::Vector2d integrateGroundTrack(double tau) const;

  VehicleMotionProfile profile_;
  /// Ground-track displacement over one full steering period (yaw is periodic, so the track
  /// repeats itself shifted by this vector).
  Eigen::Vector2d period_displacement_;
};

}  // namespace osc
