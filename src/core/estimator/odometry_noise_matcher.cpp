#include "online_stereo_calibration/core/estimator/odometry_noise_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace osc {

OdometryNoiseMatcherOptions OdometryNoiseMatcherOptions::from(const FilterConfig& config) {
  OdometryNoiseMatcherOptions options;
  options.window = config.odometry_noise_window;
  options.translation_noise = config.motion_translation_noise;
  options.rotation_noise = config.motion_rotation_noise;
  return options;
}

std::string OdometryNoiseStatus::message() const {
  std::string text;
  char part[96];
  if (factor[0] > 1.0) {
    std::snprintf(part, sizeof(part), "translation %.1f -> %.1f mm",
                  1e3 * sigma[0] / std::sqrt(factor[0]), 1e3 * sigma[0]);
    text += part;
  }
  if (factor[1] > 1.0) {
    std::snprintf(part, sizeof(part), "%srotation %.3f -> %.3f deg", text.empty() ? "" : ", ",
                  sigma[1] / std::sqrt(factor[1]) * 180.0 / M_PI, sigma[1] * 180.0 / M_PI);
    text += part;
  }
  return text.empty() ? text : "odometry noisier than configured: " + text + " per step learned";
}

OdometryNoiseMatcher::OdometryNoiseMatcher(const OdometryNoiseMatcherOptions& options)
    : options_(options) {
  reset();
}

void OdometryNoiseMatcher::reset() {
  time_ = 0.0;
  window_entries_.clear();
  status_ = OdometryNoiseStatus();
  status_.enabled = options_.window > 0.0;
  learn();
}

void OdometryNoiseMatcher::addUpdate(double dt, const MotionNoiseEvidence* evidence,
                                     double caml_rotation_sigma) {
  if (!status_.enabled) return;
  time_ += dt;
  if (evidence && caml_rotation_sigma <= kSettledRotationSigma) {
    // One update's statistic counts at most up to its chi-square bound: a few updates
    // linearised far off (a start 20 deg off) do not make a noisy odometry on their own.
    Entry entry{time_, *evidence};
    for (int p = 0; p < 2; ++p) {
      entry.evidence.statistic[p] = std::min(
          entry.evidence.statistic[p], chiSquareUpperQuantile(entry.evidence.dof[p], kFalseAlarm));
    }
    window_entries_.push_back(entry);
  }
  while (!window_entries_.empty() && window_entries_.front().time <= time_ - options_.window) {
    window_entries_.pop_front();
  }
  learn();
}

void OdometryNoiseMatcher::learn() {
  static const double z = normalUpperQuantile(kFalseAlarm);
  const std::array<double, 2> configured = {options_.translation_noise, options_.rotation_noise};
  status_.window_updates = static_cast<int>(window_entries_.size());
  for (int p = 0; p < 2; ++p) {
    double excess = 0.0, dof = 0.0, growth = 0.0;
    for (const Entry& entry : window_entries_) {
      const MotionNoiseEvidence& e = entry.evidence;
      excess += e.statistic[p] - e.dof[p] + e.applied_factor[p] * e.growth[p];
      dof += e.dof[p];
      growth += e.growth[p];
    }
    const bool informed = growth > 1e-9 && dof > 0.0;
    status_.estimate[p] = informed ? excess / growth : 0.0;
    status_.standard_error[p] = informed ? std::sqrt(2.0 * dof) / growth : 0.0;
    // A window that hardly informs the motion keeps what was learned before it.
    if (informed) {
      status_.factor[p] =
          std::min(std::max(status_.estimate[p] - z * status_.standard_error[p], 1.0), kMaxFactor);
    }
    status_.sigma[p] = configured[p] * std::sqrt(status_.factor[p]);
  }
}

}  // namespace osc
