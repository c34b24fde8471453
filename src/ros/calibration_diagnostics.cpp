/// @file calibration_diagnostics.cpp
/// @brief Aggregated calibration diagnostics.
#include "online_stereo_calibration/ros/calibration_diagnostics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "online_stereo_calibration/StereoCalibration.h"
#include "online_stereo_calibration/ros/output_publisher.h"

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

/// The consistency monitor (core/estimator/consistency_monitor.h): each block's window
/// statistic per degree of freedom against its bound, the drift-noise factors, and a WARN
/// while it raises a block's process noise.
void addConsistency(const osc::ConsistencyStatus& consistency,
                    diagnostic_updater::DiagnosticStatusWrapper* status, unsigned char* level,
                    std::vector<std::string>* reasons) {
  if (!consistency.enabled) return;
  for (int k = 0; k < osc::kConsistencyBlocks; ++k) {
    std::ostringstream value;
    value << consistency.statistic[k] << " (bound " << consistency.bound[k] << ")";
    status->add(std::string("consistency ") +
                    osc::consistencyBlockName(static_cast<osc::ConsistencyBlock>(k)),
                value.str());
  }
  std::ostringstream factors;
  factors << consistency.inflation.caml << ", " << consistency.inflation.camr;
  status->add("drift noise factor (x_caml, x_camr)", factors.str());
  const std::string message = consistency.message();
  status->add("consistency", message.empty() ? "measurements agree with the model" : message);
  if (consistency.acting()) {
    *level = std::max<unsigned char>(*level, diagnostic_msgs::DiagnosticStatus::WARN);
    reasons->push_back(message);
  }
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

void CalibrationDiagnostics::tickPair() {
  pair_frequency_.tick();
  std::lock_guard<std::mutex> lock(mutex_);
  ++inputs_.pairs;
}

void CalibrationDiagnostics::tickProcessed() { processed_frequency_.tick(); }

void CalibrationDiagnostics::tickOdom() {
  odom_frequency_.tick();
  std::lock_guard<std::mutex> lock(mutex_);
  ++inputs_.odom;
  last_odom_wall_ = ros::WallTime::now();
}

void CalibrationDiagnostics::tickInput(bool left, bool camera_info) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++inputs_.value[(camera_info ? 2 : 0) + (left ? 0 : 1)];
}

void CalibrationDiagnostics::setInitialGuess(const std::string& description) {
  std::lock_guard<std::mutex> lock(mutex_);
  initial_guess_ = description;
}

void CalibrationDiagnostics::recordProblem(const std::string& kind, const std::string& message) {
  constexpr size_t kMaxUnreported = 3;
  std::lock_guard<std::mutex> lock(mutex_);
  last_problem_ = message;
  for (Problem& problem : problems_) {
    if (problem.kind == kind) {
      ++problem.count;
      problem.last_message = message;
      if (problem.unreported.size() < kMaxUnreported &&
          std::find(problem.unreported.begin(), problem.unreported.end(), message) ==
              problem.unreported.end()) {
        problem.unreported.push_back(message);
      }
      return;
    }
  }
  problems_.push_back({kind, 1, message, {message}});
}

int CalibrationDiagnostics::count(const std::string& kind) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Problem& problem : problems_) {
    if (problem.kind == kind) return problem.count;
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

void CalibrationDiagnostics::recordTempering(double factor) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++updates_since_report_;
  if (factor > 1.0) {
    ++tempered_since_report_;
    largest_tempering_ = std::max(largest_tempering_, factor);
  }
}

void CalibrationDiagnostics::recordQuality(const osc::CalibrationQuality& quality) {
  std::lock_guard<std::mutex> lock(mutex_);
  quality_ = quality;
}

void CalibrationDiagnostics::recordReset() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++resets_;
  have_estimate_ = false;
  quality_.reset();
}

void CalibrationDiagnostics::update() {
  // diagnostic_updater::Updater::update() stays silent until the report time it computed
  // before the clock went back (issue 17: 200 s without a status in a looped bag);
  // force_update() reports now and schedules the next report from the new time.
  const ros::Time now = ros::Time::now();
  if (now < last_update_) {
    updater_.force_update();
  } else {
    updater_.update();
  }
  last_update_ = now;
}

/// Tempered updates (core/filter/update_tempering.h): while a start or a re-opening has
/// little evidence, an update may not shrink any calibration sigma by more than
/// max_sigma_shrink_per_update; the filter then weighs the update down by a factor. Said,
/// because the estimate then moves more slowly than the measurements alone would move it.
void CalibrationDiagnostics::addTempering(diagnostic_updater::DiagnosticStatusWrapper* status,
                                          std::vector<std::string>* reasons) {
  std::ostringstream value;
  value << tempered_since_report_ << " of " << updates_since_report_ << " pairs";
  if (tempered_since_report_ > 0) {
    value << " (largest factor " << std::setprecision(3) << largest_tempering_
          << "): no calibration sigma may shrink more than max_sigma_shrink_per_update in one "
             "update";
    reasons->push_back("updates held back (evidence still thin)");
  }
  status->add("updates held back since last report", value.str());
  updates_since_report_ = 0;
  tempered_since_report_ = 0;
  largest_tempering_ = 1.0;
}

void CalibrationDiagnostics::produceStatus(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  using diagnostic_msgs::DiagnosticStatus;
  status.summary(DiagnosticStatus::OK, "calibrating");
  std::vector<std::string> reasons;
  unsigned char level = DiagnosticStatus::OK;
  if (!initial_guess_.empty()) status.add("initial guess", initial_guess_);

  // Inputs since the last report: images without camera_info never pair (ERROR, nothing can
  // be processed), nor do images whose camera_info stamps differ; pairs without odometry
  // cannot be processed either.
  const auto since = [this](int index) {
    return inputs_.value[index] - inputs_at_last_report_.value[index];
  };
  const int images = std::min(since(0), since(1));
  const int pairs = inputs_.pairs - inputs_at_last_report_.pairs;
  const int odom = inputs_.odom - inputs_at_last_report_.odom;
  status.add("images since last report (left, right)",
             std::to_string(since(0)) + ", " + std::to_string(since(1)));
  status.add("camera_info since last report (left, right)",
             std::to_string(since(2)) + ", " + std::to_string(since(3)));
  status.add("pairs since last report", pairs);
  status.add("odometry since last report", odom);
  if (images > 0 && (since(2) == 0 || since(3) == 0)) {
    level = DiagnosticStatus::ERROR;
    const std::string which = since(2) == 0 && since(3) == 0 ? "left/camera_info, right/camera_info"
                              : since(2) == 0                ? "left/camera_info"
                                                             : "right/camera_info";
    reasons.push_back("no camera_info on " + which + " (images arrive)");
  } else if (images > 0 && pairs == 0) {
    level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
    reasons.push_back("images and camera_info do not pair (stamps differ?)");
  }
  // Pairs arrive but the latest odometry is over a second old (or there never was any).
  constexpr double kOdomSilence = 1.0;  // s, wall clock
  const bool odom_silent =
      last_odom_wall_.isZero() || (ros::WallTime::now() - last_odom_wall_).toSec() > kOdomSilence;
  if (pairs > 0 && odom_silent && config_.motion_source == MotionSourceType::kOdom) {
    level = DiagnosticStatus::ERROR;
    reasons.push_back("no odometry (image pairs arrive)");
  }
  inputs_at_last_report_ = inputs_;

  if (resets_ > 0) status.add("resets (total)", resets_);
  if (!have_estimate_) {
    level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
    reasons.push_back(resets_ > 0 ? "no image pair processed since ~reset"
                                  : "no image pair processed yet");
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
    // What the motion does not determine is said, not hidden (it does not block CONVERGED).
    static const char* const kNeeds[3] = {"no pitch/yaw excitation", "no roll/yaw excitation",
                                          "no roll/pitch excitation"};
    std::string undetermined;
    const std::vector<int> scale_limited =
        osc::scaleLimitedParameters(estimate_, config_.converged);
    for (int i : osc::undeterminedParameters(estimate_, config_.converged)) {
      const bool by_scale =
          std::find(scale_limited.begin(), scale_limited.end(), i) != scale_limited.end();
      undetermined +=
          (undetermined.empty() ? "" : ", ") + std::string(kParameterNames[i]) + ": " +
          (by_scale || i >= 3 ? "limited by the odometry's scale uncertainty" : kNeeds[i]);
    }
    status.add("not determined by the motion", undetermined.empty() ? "-" : undetermined);
    if (!undetermined.empty()) reasons.push_back(undetermined);
    addConsistency(estimate_.consistency, &status, &level, &reasons);
    addTempering(&status, &reasons);
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
  // The camera-odometry time offset (issue 15), when it is estimated.
  if (have_estimate_ && estimate_.time_offset_sigma > 0.0) {
    status.add(
        "odometry time offset [ms]",
        std::to_string(estimate_.time_offset * 1e3) + " +- " +
            std::to_string(estimate_.time_offset_sigma * 1e3) +
            " (camera clock minus odometry clock: the odometry stamped t holds the vehicle at "
            "camera time t + offset; 1 sigma)");
  }
  // The odometry's noise as learned (odometry_noise_matcher.h), when it is learned.
  if (have_estimate_ && estimate_.odometry_noise.enabled) {
    const std::string learned = estimate_.odometry_noise.message();
    status.add("odometry noise", learned.empty() ? "as configured" : learned);
  }
  // x_camr's drift rate (issue 15), when it is estimated.
  if (have_estimate_ && estimate_.camr_drift_rate_sigma.maxCoeff() > 0.0) {
    constexpr double kDegPerMin = 60.0 * 180.0 / M_PI;
    std::ostringstream rate;
    rate << std::fixed << std::setprecision(4);
    for (int k = 0; k < 3; ++k) {
      rate << (k ? ", " : "") << estimate_.camr_drift_rate(k) * kDegPerMin << " +- "
           << estimate_.camr_drift_rate_sigma(k) * kDegPerMin;
    }
    status.add("x_camr rotation drift rate [deg/min]", rate.str() + " (about x, y, z; 1 sigma)");
  }
  // Quality figures of the last processed pair (issue 16): values only, no level.
  if (have_estimate_ && quality_) {
    const auto& error = quality_->rectification_error;
    status.add("rectification error [px]", error
                                               ? std::to_string(error->median_px) + " (median of " +
                                                     std::to_string(error->pairs) + " pairs)"
                                               : std::string("no stereo pair"));
    status.add("depth sigma at 10 m [m]", quality_->depth_sigma_10m);
    status.add("depth sigma at 50 m [m]", quality_->depth_sigma_50m);
  }
  // Problems since the last report make the status WARN; totals are always listed.
  counts_at_last_report_.resize(problems_.size());
  for (size_t i = 0; i < problems_.size(); ++i) {
    Problem& problem = problems_[i];
    status.add(problem.kind + " (total)", problem.count);
    // Every distinct message since the previous report (the latest alone if none is new).
    std::string recent;
    for (const std::string& message : problem.unreported)
      recent += (recent.empty() ? "" : " | ") + message;
    status.add(problem.kind + " (last)", recent.empty() ? problem.last_message : recent);
    problem.unreported.clear();
    std::pair<std::string, int>& old = counts_at_last_report_[i];
    if (old.first != problem.kind) old = {problem.kind, 0};  // problems_ only grows
    if (problem.count > old.second) {
      level = std::max<unsigned char>(level, DiagnosticStatus::WARN);
      reasons.push_back(problem.kind);
    }
    old.second = problem.count;
  }
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
