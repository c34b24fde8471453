/// @file calibration_diagnostics.cpp
/// @brief Aggregated calibration diagnostics.
#include "online_stereo_calibration/ros/calibration_diagnostics.h"

#include <cmath>
#include <sstream>

#include "online_stereo_calibration/StereoCalibration.h"

namespace online_stereo_calibration {
namespace {

const char* const kParameterNames[12] = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                                         "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};

const char* stateName(uint8_t state) {
  switch (state) {
    case StereoCalibration::STATE_INITIALIZING:
      return "INITIALIZING";
    case StereoCalibration::STATE_CONVERGING:
      return "CONVERGING";
    case StereoCalibration::STATE_CONVERGED:
      return "CONVERGED";
    case StereoCalibration::STATE_DIVERGED:
      return "DIVERGED";
  }
  return "UNKNOWN";
}

}  // namespace

CalibrationDiagnostics::CalibrationDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                                               const RosConfig& config)
    : config_(config),
      min_rate_(config.min_rate),
      max_rate_(config.max_rate),
      updater_(nh, private_nh),
      pair_frequency_(diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.1, 10),
                      "image pairs"),
      processed_frequency_(
          diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.1, 10),
          "processed pairs"),
      odom_frequency_(diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.1, 10),
                      "motion samples") {
  updater_.setHardwareID("stereo camera");
  updater_.add(pair_frequency_);
  updater_.add(processed_frequency_);
  updater_.add(odom_frequency_);
  updater_.add("calibration", this, &CalibrationDiagnostics::produceStatus);
}

void CalibrationDiagnostics::tickPair() { pair_frequency_.tick(); }
void CalibrationDiagnostics::tickProcessed() { processed_frequency_.tick(); }
void CalibrationDiagnostics::tickOdom() { odom_frequency_.tick(); }

void CalibrationDiagnostics::recordProblem(const std::string& kind, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_problem_ = message;
  for (auto& entry : counts_) {
    if (entry.first == kind) {
      ++entry.second;
      return;
    }
  }
  counts_.emplace_back(kind, 1);
}

int CalibrationDiagnostics::count(const std::string& kind) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& entry : counts_) {
    if (entry.first == kind) return entry.second;
  }
  return 0;
}

void CalibrationDiagnostics::recordEstimate(const osc::CalibrationEstimate& estimate,
                                            uint8_t state) {
  std::lock_guard<std::mutex> lock(mutex_);
  estimate_ = estimate;
  state_ = state;
  have_estimate_ = true;
}

void CalibrationDiagnostics::update() { updater_.update(); }

void CalibrationDiagnostics::produceStatus(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  using diagnostic_msgs::DiagnosticStatus;
  status.summary(DiagnosticStatus::OK, "calibrating");
  std::vector<std::string> reasons;
  unsigned char level = DiagnosticStatus::OK;
  if (!have_estimate_) {
    level = DiagnosticStatus::WARN;
    reasons.push_back("no image pair processed yet");
  } else {
    status.add("state", stateName(state_));
    status.add("tracked points", estimate_.tracked_points);
    if (state_ == StereoCalibration::STATE_DIVERGED) {
      level = DiagnosticStatus::ERROR;
      reasons.push_back("calibration jump detected");
    } else if (state_ != StereoCalibration::STATE_CONVERGED) {
      level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
      reasons.push_back("not converged");
    }
    if (static_cast<int>(estimate_.tracked_points) < config_.min_tracked_points) {
      level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
      reasons.push_back("too few points");
    }
    const osc::Vector12d sigma = estimate_.sigmas();
    for (int i = 0; i < 12; ++i) {
      status.add(std::string("3-sigma ") + kParameterNames[i] + ((i % 6) < 3 ? " [m]" : " [rad]"),
                 3.0 * sigma(i));
      status.add(std::string(kParameterNames[i]) + ((i % 6) < 3 ? " [m]" : " [rad]"),
                 estimate_.parameters(i));
    }
    if (!estimate_.parameters.allFinite() || !estimate_.parameter_covariance.allFinite()) {
      level = DiagnosticStatus::ERROR;
      reasons.push_back("non-finite estimate");
    }
  }
  // Problems since the last report make the status WARN; totals are always listed.
  for (const auto& entry : counts_) {
    status.add(entry.first + " (total)", entry.second);
    int before = 0;
    for (const auto& old : counts_at_last_report_) {
      if (old.first == entry.first) before = old.second;
    }
    if (entry.second > before) {
      level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
      reasons.push_back(entry.first);
    }
  }
  counts_at_last_report_ = counts_;
  if (!last_problem_.empty()) status.add("last problem", last_problem_);
  std::ostringstream summary;
  if (reasons.empty()) {
    summary << "converged";
  } else {
    for (size_t i = 0; i < reasons.size(); ++i) summary << (i ? "; " : "") << reasons[i];
  }
  status.summary(level, summary.str());
}

}  // namespace online_stereo_calibration
