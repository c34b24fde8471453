/// @file left_camera_gap_check.h
/// @brief Change detection, x_caml: a change of the left camera's mounting while nothing was
/// seen (docs/design.md, "change detection, x_caml").
///
/// After a stretch of `gap` s without a measured point (dark, texture-poor, a gap in the data)
/// no tracked point outlives the stretch, so none gates out and the jump test is blind to a
/// step of x_caml made in it. When tracked points come back, the consistency monitor's window
/// is emptied (what it saw before says nothing of what follows) and for the next `window` s
/// of updates x_caml is tested with its statistic: beyond its bound after at least three
/// updates, x_caml is re-opened with the jump sigmas (image campaign: 257 -> 173 frames beyond
/// 5 sigma; docs/history, session 28).
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/consistency_monitor.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"

namespace osc {

/// The check's options (FilterConfig keys).
struct LeftCameraGapCheckOptions {
  double gap = 2.0;                 ///< unobserved_gap_s: a stretch this long arms it; 0 = off
  double window = 4.0;              ///< consistency_window_s: s of updates it stays armed
  double translation_sigma = 0.02;  ///< jump_translation_sigma_m: the re-opening's (m)
  double rotation_sigma = 10.0 * 0.0174532925199432958;  ///< jump_rotation_sigma_deg (rad)

  static LeftCameraGapCheckOptions from(const FilterConfig& config);
};

/// What one check did.
struct GapDecision {
  bool reopened = false;              ///< x_caml was re-opened
  Vector6d sigma = Vector6d::Zero();  ///< to these sigmas [dt (3), dtheta (3)]
  std::vector<PointId> dropped;       ///< every point of the filter
  std::string warning;                ///< the event's line (empty when nothing was done)
};

/// The time without a measured point and the armed check (one per estimator).
class LeftCameraGapCheck {
 public:
  explicit LeftCameraGapCheck(const LeftCameraGapCheckOptions& options) : options_(options) {}

  /// Before a step with @p has_tracked tracked points: if they end an unobserved stretch, the
  /// consistency monitor's evidence is forgotten and the check armed.
  void beforeStep(ConsistencyMonitor* monitor, bool has_tracked);
  /// After the step (accepted or not): a step that used a measurement ends the unobserved
  /// stretch, any other adds its dt.
  void countAfterStep(const MotionIncrement& motion, const StepReport& step);
  /// x_caml was re-opened on its own evidence (a jump): the check has its answer.
  void disarm() { check_left_ = 0.0; }
  /// After an accepted step without a jump, while armed: re-opens x_caml if the monitor's
  /// x_caml statistic (@p consistency, after the step's update) is beyond its bound after at
  /// least three updates in its window.
  GapDecision checkAfterStep(CalibrationFilter* filter, const MotionIncrement& motion,
                             const StepReport& step, const ConsistencyStatus& consistency);
  /// Forgets the stretch and disarms (a reset).
  void reset() {
    unobserved_time_ = 0.0;
    check_left_ = 0.0;
  }

 private:
  LeftCameraGapCheckOptions options_;
  double unobserved_time_ = 0.0;  ///< s without a point measured so far
  double check_left_ = 0.0;       ///< s of updates left in which x_caml is tested
};

}  // namespace osc
