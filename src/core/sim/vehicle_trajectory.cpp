#include "online_stereo_calibration/core/sim/vehicle_trajectory.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

namespace {

/// Panels per steering period of the composite quadrature. The integrand changes on the
/// time scale of the heading (seconds), so 5-point Gauss-Legendre on 1/64 of the period is
/// exact to rounding for any sensible steering, at a few hundred sin/cos per pose.
constexpr int kPanelsPerPeriod = 64;

/// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> kNodes = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                          0.5384693101056831, 0.9061798459386640};
constexpr std::array<double, 5> kWeights = {0.2369268850561891, 0.4786286704993665,
                                            0.5688888888888889, 0.4786286704993665,
                                            0.2369268850561891};

double sinusoid(double amplitude, double period, double t) {
  return amplitude * std::sin(2.0 * M_PI * t / period);
}

/// Profile time lost (s) up to fraction u in [0, 1] of a slow-down ramp of unit length: the
/// integral of the smoothstep 3v^2 - 2v^3 over [0, u] (the rate drops as 1 - smoothstep).
double slowDownLoss(double u) { return u * u * u - 0.5 * u * u * u * u; }

/// Smoothstep 3u^2 - 2u^3 on [0, 1]: 0 -> 1 with zero slope at both ends.
double smoothstep(double u) { return u * u * (3.0 - 2.0 * u); }

/// Profile time lost to one stop up to drive time t (see VehicleTrajectory).
double stopLoss(const TimeSpan& stop, double ramp, double t) {
  const double slow_start = stop.start - ramp, stop_end = stop.start + stop.duration;
  if (t <= slow_start) return 0.0;
  if (t < stop.start) return ramp * slowDownLoss((t - slow_start) / ramp);
  if (t <= stop_end) return 0.5 * ramp + (t - stop.start);
  if (t < stop_end + ramp) {
    // Speed-up: the rate rises as smoothstep(u), so the loss grows by u - slowDownLoss(u).
    const double u = (t - stop_end) / ramp;
    return 0.5 * ramp + stop.duration + ramp * (u - slowDownLoss(u));
  }
  return stop.duration + ramp;
}

/// ds/dt of one stop at drive time t: 1 - its share of the lost rate.
double stopLostRate(const TimeSpan& stop, double ramp, double t) {
  const double slow_start = stop.start - ramp, stop_end = stop.start + stop.duration;
  if (t <= slow_start || t >= stop_end + ramp) return 0.0;
  if (t < stop.start) return smoothstep((t - slow_start) / ramp);
  if (t <= stop_end) return 1.0;
  return 1.0 - smoothstep((t - stop_end) / ramp);
}

void checkProfile(const VehicleMotionProfile& p) {
  const double periods[] = {p.roll_period, p.pitch_period, p.yaw_period, p.heave_period};
  for (double period : periods) {
    if (!(period > 0.0) || !std::isfinite(period)) {
      throw std::invalid_argument("VehicleMotionProfile: periods must be positive and finite");
    }
  }
  const double values[] = {p.speed,           p.roll_amplitude,
                           p.pitch_amplitude, p.yaw_rate_amplitude,
                           p.heave_amplitude, p.yaw_phase};
  for (double value : values) {
    if (!std::isfinite(value)) {
      throw std::invalid_argument(
          "VehicleMotionProfile: speed, amplitudes and yaw_phase must be finite");
    }
  }
  if (!(p.stop_ramp >= 0.0) || !std::isfinite(p.stop_ramp)) {
    throw std::invalid_argument("VehicleMotionProfile: stop_ramp must be >= 0 and finite");
  }
  for (const TimeSpan& stop : p.stops) {
    if (!std::isfinite(stop.start) || !(stop.duration > 0.0) || !std::isfinite(stop.duration)) {
      throw std::invalid_argument(
          "VehicleMotionProfile: stops need a finite start and a positive finite duration");
    }
  }
}

}  // namespace

VehicleTrajectory::VehicleTrajectory(const VehicleMotionProfile& profile) : profile_(profile) {
  checkProfile(profile_);
  sin_yaw_phase_ = std::sin(profile_.yaw_phase);
  period_displacement_ = integrateGroundTrack(profile_.yaw_period);
}

double VehicleTrajectory::profileTime(double t) const {
  if (profile_.stops.empty()) return t;
  // Inside a stop, s is its constant start - ramp / 2 (minus the complete earlier stops),
  // computed without t so that it is bit-identical over the whole stop.
  double clock = t, lost = 0.0;
  for (const TimeSpan& stop : profile_.stops) {
    if (t >= stop.start && t <= stop.start + stop.duration) {
      clock = stop.start - 0.5 * profile_.stop_ramp;
    } else {
      lost += stopLoss(stop, profile_.stop_ramp, t);
    }
  }
  return clock - lost;
}

double VehicleTrajectory::profileRate(double t) const {
  double lost = 0.0;
  for (const TimeSpan& stop : profile_.stops) lost += stopLostRate(stop, profile_.stop_ramp, t);
  return std::clamp(1.0 - lost, 0.0, 1.0);
}

double VehicleTrajectory::yaw(double t) const { return analyticYaw(profileTime(t)); }

double VehicleTrajectory::analyticYaw(double t) const {
  const double heading_amplitude = profile_.yaw_rate_amplitude * profile_.yaw_period / (2.0 * M_PI);
  // Shifted so that the heading is 0 at t = 0 whatever the phase (the world's +x); with
  // phase 0 this is bit for bit the unshifted sinusoid (x + 0 and sin(0) = 0 are exact).
  return heading_amplitude *
         (std::sin(2.0 * M_PI * t / profile_.yaw_period + profile_.yaw_phase) - sin_yaw_phase_);
}

double VehicleTrajectory::roll(double t) const {
  return profile_.planar ? 0.0
                         : sinusoid(profile_.roll_amplitude, profile_.roll_period, profileTime(t));
}

double VehicleTrajectory::pitch(double t) const {
  return profile_.planar
             ? 0.0
             : sinusoid(profile_.pitch_amplitude, profile_.pitch_period, profileTime(t));
}

double VehicleTrajectory::heave(double t) const {
  return profile_.planar
             ? 0.0
             : sinusoid(profile_.heave_amplitude, profile_.heave_period, profileTime(t));
}

Eigen::Vector2d VehicleTrajectory::integrateGroundTrack(double tau) const {
  const double panel = profile_.yaw_period / kPanelsPerPeriod;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (double a = 0.0; a < tau; a += panel) {
    const double b = std::min(a + panel, tau);
    const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
    for (size_t i = 0; i < kNodes.size(); ++i) {
      const double heading = analyticYaw(mid + half * kNodes[i]);
      sum += (kWeights[i] * half) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    }
  }
  return profile_.speed * sum;
}

Eigen::Vector2d VehicleTrajectory::groundPosition(double t) const {
  return analyticGroundPosition(profileTime(t));
}

Eigen::Vector2d VehicleTrajectory::analyticGroundPosition(double t) const {
  // yaw is periodic, so whole periods contribute a fixed displacement each and only the
  // remainder needs quadrature: the cost per pose stays bounded for arbitrarily long drives.
  const double periods = std::floor(t / profile_.yaw_period);
  const double remainder = t - periods * profile_.yaw_period;
  return periods * period_displacement_ + integrateGroundTrack(remainder);
}

Eigen::Isometry3d VehicleTrajectory::pose(double t) const {
  const double s = profileTime(t);
  double roll = 0.0, pitch = 0.0, heave = 0.0;
  if (!profile_.planar) {
    roll = sinusoid(profile_.roll_amplitude, profile_.roll_period, s);
    pitch = sinusoid(profile_.pitch_amplitude, profile_.pitch_period, s);
    heave = sinusoid(profile_.heave_amplitude, profile_.heave_period, s);
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotationFromRpy(Eigen::Vector3d(roll, pitch, analyticYaw(s)));
  pose.translation() << analyticGroundPosition(s), heave;
  return pose;
}

Eigen::Isometry3d VehicleTrajectory::motionBetween(double t0, double t1) const {
  // Standing still: the same profile time gives the same pose, but pose^-1 * pose rounds.
  if (profileTime(t0) == profileTime(t1)) return Eigen::Isometry3d::Identity();
  return pose(t0).inverse() * pose(t1);
}

}  // namespace osc
