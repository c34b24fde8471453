/// @file jump_test.h
/// @brief Change detection from the outlier gate: when many tracked points are gated out at
/// once, or a smaller share in several frames in a row, a calibration block jumped; it is
/// re-opened before the update instead of being updated with the wrong points (docs/design.md,
/// "change detection, x_caml" and "what re-opens x_camr").
///
/// The left image does not see x_camr: when at least half the gated-out points fail in the
/// left image alone, x_caml is the suspect (via eq. 8), else x_camr. A jump of x_caml found
/// at once has every tracked point measured across it: the rotation that takes their
/// predicted left bearings onto the measured ones is the camera's turn (the fitted turn), and
/// only the axes that turned are re-opened wide.
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"

namespace osc {

/// The test's options (FilterConfig's jump_* keys).
struct JumpTestOptions {
  double rejected_fraction = 0.6;            ///< jump_rejected_fraction: gated out at once
  int min_points = 8;                        ///< jump_min_points: tested points needed
  double sustained_rejected_fraction = 0.3;  ///< jump_sustained_rejected_fraction
  int sustained_frames = 3;                  ///< jump_sustained_frames; 0 = no sustained test
  double settle_time = 5.0;                  ///< jump_settle_time_s
  double rotation_sigma = 0.0;               ///< jump_rotation_sigma: re-opened 1 sigma (rad)
  double translation_sigma = 0.0;            ///< jump_translation_sigma: re-opened 1 sigma (m)
  /// jump_fit_rotation_sigma: floor of a fitted turn's re-opened axes (rad); 0 = no fit.
  double fit_rotation_sigma = 0.0;

  static JumpTestOptions from(const FilterConfig& config);
};

/// The gate's streak (one per estimator). Its decide() is the filter's ChangeDetector.
class JumpTest {
 public:
  explicit JumpTest(const JumpTestOptions& options) : options_(options) {}

  /// Called by CalibrationFilter::step with its first pass's gate, before the update: the
  /// block to re-open, its sigmas, and x_caml's fitted turn, or kNone. A block is re-opened
  /// only when @p filter allows it (CalibrationFilter::canReopen); the sustained test also
  /// waits jump_settle_time_s after the block's start or widening. A start of the filter
  /// since the last call (CalibrationFilter::starts) begins the streak afresh.
  Reopening decide(const GateOutcome& gate, const CalibrationFilter& filter);

 private:
  /// After an x_caml jump found at once: the rotation that takes the tested points'
  /// predicted left bearings onto the measured ones, and each axis's sigma by what it turned
  /// (at least fit_rotation_sigma, at most rotation_sigma). False when off, when the fit
  /// fails or when the turn explains fewer than rejected_fraction of the points.
  bool fitLeftCameraTurn(const GateOutcome& gate, const StereoIntrinsics& intrinsics,
                         Reopening* reopening) const;

  JumpTestOptions options_;
  /// Frames in a row with at least sustained_rejected_fraction of the points gated out.
  int streak_ = 0;
  int last_start_ = 0;  ///< CalibrationFilter::starts() at the last call
};

}  // namespace osc
