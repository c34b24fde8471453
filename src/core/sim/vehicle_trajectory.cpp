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

void checkProfile(const VehicleMotionProfile& p) {
  const double periods[] = {p.roll_period, p.pitch_period, p.yaw_period, p.heave_period};
  for (double period : periods) {
    if (!(period > 0.0) || !std::isfinite(period)) {
      throw std::invalid_argument("VehicleMotionProfile: periods must be positive and finite");
    }
  }
  const double values[] = {p.speed, p.roll_amplitude, p.pitch_amplitude, p.yaw_rate_amplitude,
                           p.heave_amplitude};
  for (double value : values) {
    if (!std::isfinite(value)) {
      throw std::invalid_argument("VehicleMotionProfile: speed and amplitudes must be finite");
    }
  }
}

}  // namespace

VehicleTrajectory::VehicleTrajectory(const VehicleMotionProfile& profile) : profile_(profile) {
  checkProfile(profile_);
  period_displacement_ = integrateGroundTrack(profile_.yaw_period);
}

double VehicleTrajectory::yaw(double t) const {
  const double heading_amplitude = profile_.yaw_rate_amplitude * profile_.yaw_period / (2.0 * M_PI);
  return sinusoid(heading_amplitude, profile_.yaw_period, t);
}

double VehicleTrajectory::roll(double t) const {
  return profile_.planar ? 0.0 : sinusoid(profile_.roll_amplitude, profile_.roll_period, t);
}

double VehicleTrajectory::pitch(double t) const {
  return profile_.planar ? 0.0 : sinusoid(profile_.pitch_amplitude, profile_.pitch_period, t);
}

double VehicleTrajectory::heave(double t) const {
  return profile_.planar ? 0.0 : sinusoid(profile_.heave_amplitude, profile_.heave_period, t);
}

Eigen::Vector2d VehicleTrajectory::integrateGroundTrack(double tau) const {
  const double panel = profile_.yaw_period / kPanelsPerPeriod;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (double a = 0.0; a < tau; a += panel) {
    const double b = std::min(a + panel, tau);
    const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
    for (size_t i = 0; i < kNodes.size(); ++i) {
      const double heading = yaw(mid + half * kNodes[i]);
      sum += (kWeights[i] * half) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    }
  }
  return profile_.speed * sum;
}

Eigen::Vector2d VehicleTrajectory::groundPosition(double t) const {
  // yaw is periodic, so whole periods contribute a fixed displacement each and only the
  // remainder needs quadrature: the cost per pose stays bounded for arbitrarily long drives.
  const double periods = std::floor(t / profile_.yaw_period);
  const double remainder = t - periods * profile_.yaw_period;
  return periods * period_displacement_ + integrateGroundTrack(remainder);
}

Eigen::Isometry3d VehicleTrajectory::pose(double t) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotationFromRpy(Eigen::Vector3d(roll(t), pitch(t), yaw(t)));
  pose.translation() << groundPosition(t), heave(t);
  return pose;
}

}  // namespace osc
