/// @file right_camera_score_test.h
/// @brief Change detection, x_camr: a knock of the right camera too small to gate out any
/// point is caught by x_camr's part of the updates' score (docs/design.md, "change
/// detection, x_camr").
///
/// Each update's score of a calibration shift, with the other block free (the consistency
/// monitor's partial score statistic), is chi-square with the informed degrees of freedom
/// while x_camr holds. Beyond its bound at the false-alarm probability in `updates` updates in
/// a row, x_camr's rotation variance is widened by (`widening` x the rotation the updates
/// indicate)^2 per axis; its mean and the points are kept, so the next updates move it. A
/// common excess of every measurement (noise under-estimated) is not x_camr's: the statistic
/// is divided by the rest's mean (the monitor's F test). Measured: 0.15 deg knocks 10-30
/// frames beyond 5 sigma without it, 1 with it (docs/history, session 18).
#pragma once

#include <string>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"

namespace osc {

/// The test's options (FilterConfig's jump_score_* keys).
struct RightCameraScoreOptions {
  double false_alarm = 1e-6;  ///< jump_score_false_alarm per update; 0 = off
  int updates = 2;            ///< jump_score_updates: updates in a row beyond the bound
  double widening = 3.0;      ///< jump_score_widening: times the indicated rotation

  static RightCameraScoreOptions from(const FilterConfig& config);
};

/// What one test did.
struct ScoreWidening {
  bool widened = false;  ///< x_camr's rotation variance was widened
  std::string warning;   ///< the event's line (empty when nothing was done)
};

/// The streak of contradicting updates (one per estimator).
class RightCameraScoreTest {
 public:
  explicit RightCameraScoreTest(const RightCameraScoreOptions& options) : options_(options) {}

  /// After an accepted step of @p filter that detected no jump: tests its update's scores
  /// (CalibrationFilter::lastUpdateScores; none: the streak ends) and widens x_camr's
  /// rotation variance when they contradicted x_camr `updates` times in a row and x_camr may
  /// be re-opened (CalibrationFilter::canReopen). A start of the filter since the last test
  /// (CalibrationFilter::starts) begins the streak afresh.
  ScoreWidening afterStep(CalibrationFilter* filter);

 private:
  RightCameraScoreOptions options_;
  int streak_ = 0;      ///< updates in a row whose x_camr statistic was beyond its bound
  int last_start_ = 0;  ///< CalibrationFilter::starts() at the last test
};

}  // namespace osc
