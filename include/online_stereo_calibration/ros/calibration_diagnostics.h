/// @file calibration_diagnostics.h
/// @brief /diagnostics through diagnostic_updater: a frequency monitor per input and one
/// aggregated calibration status with its reasons (not converged, too few points, missing
/// camera_info or odometry, every recorded input problem, 3-sigma of every parameter).
/// Thread-safe.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>

#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/pipeline/live_rectification.h"
#include "online_stereo_calibration/ros/ros_config.h"

namespace online_stereo_calibration {

/// Counts events and summarises them once per diagnostics period.
class CalibrationDiagnostics {
 public:
  CalibrationDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const RosConfig& config);

  void tickPair();       ///< a synchronised image pair arrived
  void tickProcessed();  ///< a pair went through the estimator
  void tickOdom();       ///< a motion sample arrived
  /// A single input message arrived (before pairing): counts images and camera_info per
  /// side, so that images without camera_info can be told apart from no input at all.
  void tickInput(bool left, bool camera_info);
  /// Where the initial guess and its covariance came from (shown in every report).
  void setInitialGuess(const std::string& description);
  /// A problem with the input; counted under @p kind and kept as the latest message.
  void recordProblem(const std::string& kind, const std::string& message);
  /// The estimate after a processed pair and its StereoCalibration state.
  void recordEstimate(const osc::CalibrationEstimate& estimate, uint8_t state);
  /// The factor the pair's filter update was tempered by (osc::StepReport::tempering; 1: not
  /// held back). Reported per period as "updates held back since last report": how many
  /// of the period's updates, and the largest factor.
  void recordTempering(double factor);
  /// The quality figures of the estimate after a processed pair (issue 16), reported as
  /// "rectification error [px]", "depth sigma at 10 m [m]", "depth sigma at 50 m [m]".
  void recordQuality(const osc::CalibrationQuality& quality);
  /// ~reset was called: the estimate is forgotten until the next processed pair, and the
  /// number of resets is reported.
  void recordReset();
  /// Publishes now if the period elapsed (call from a timer); at once if the clock went
  /// back since the last call (a looped bag), whatever the period.
  void update();
  /// Latest value of a counter (tests, logging).
  int count(const std::string& kind) const;

 private:
  void produceStatus(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// "updates held back since last report" and its reason; starts the next period's count.
  void addTempering(diagnostic_updater::DiagnosticStatusWrapper* status,
                    std::vector<std::string>* reasons);

  /// One kind of problem: how often, the latest message, and the distinct messages since
  /// the last report (so that two problems between two 1 Hz reports are both shown).
  struct Problem {
    std::string kind;
    int count = 0;
    std::string last_message;
    std::vector<std::string> unreported;
  };
  /// Counts of single inputs (index: left image, right image, left info, right info).
  struct InputCounts {
    int value[4] = {0, 0, 0, 0};
    int pairs = 0;
    int odom = 0;
  };

  RosConfig config_;
  double min_rate_;
  double max_rate_;
  diagnostic_updater::Updater updater_;
  diagnostic_updater::FrequencyStatus pair_frequency_;
  diagnostic_updater::FrequencyStatus processed_frequency_;
  diagnostic_updater::FrequencyStatus odom_frequency_;
  mutable std::mutex mutex_;
  std::vector<Problem> problems_;
  std::vector<std::pair<std::string, int>> counts_at_last_report_;
  std::string last_problem_;
  InputCounts inputs_;
  InputCounts inputs_at_last_report_;
  /// Wall time of the latest motion sample (zero: none yet): "no odometry" is judged by how
  /// long ago it was, not by whole report periods without one (reports are not punctual).
  ros::WallTime last_odom_wall_;
  std::string initial_guess_;
  /// ROS time of the last update() call, to see the clock go back.
  ros::Time last_update_;
  int resets_ = 0;
  /// Filter updates since the last report, how many of them were tempered, the largest factor.
  int updates_since_report_ = 0;
  int tempered_since_report_ = 0;
  double largest_tempering_ = 1.0;
  bool have_estimate_ = false;
  osc::CalibrationEstimate estimate_;
  uint8_t state_ = 0;
  std::optional<osc::CalibrationQuality> quality_;  ///< of the last processed pair
};

}  // namespace online_stereo_calibration
