#include "online_stereo_calibration/core/estimator/left_camera_gap_check.h"

#include <cmath>
#include <sstream>

#include "online_stereo_calibration/core/estimator/consistency_monitor.h"

namespace osc {

LeftCameraGapCheckOptions LeftCameraGapCheckOptions::from(const FilterConfig& config) {
  LeftCameraGapCheckOptions o;
  o.gap = config.unobserved_gap;
  o.window = config.consistency_window;
  o.translation_sigma = config.jump_translation_sigma;
  o.rotation_sigma = config.jump_rotation_sigma;
  return o;
}

void LeftCameraGapCheck::beforeStep(ConsistencyMonitor* monitor, bool has_tracked) {
  const bool resumes_after_gap =
      options_.gap > 0.0 && unobserved_time_ >= options_.gap && has_tracked;
  if (!resumes_after_gap) return;
  // What the monitor saw before the stretch says nothing of what follows it.
  monitor->forgetEvidence();
  check_left_ = options_.window;
}

void LeftCameraGapCheck::countAfterStep(const MotionIncrement& motion, const StepReport& step) {
  if (step.accepted && step.measurements_used > 0) {
    unobserved_time_ = 0.0;
  } else if (std::isfinite(motion.dt) && motion.dt > 0.0) {
    unobserved_time_ += motion.dt;
  }
}

GapDecision LeftCameraGapCheck::checkAfterStep(CalibrationFilter* filter,
                                               const MotionIncrement& motion,
                                               const StepReport& step,
                                               const ConsistencyStatus& consistency) {
  GapDecision decision;
  if (!(check_left_ > 0.0) || step.measurements_used == 0) return decision;
  check_left_ -= motion.dt;
  // A few updates at least: one update's score is dominated by its own noise.
  constexpr int kLeastUpdates = 3;
  const int caml = static_cast<int>(ConsistencyBlock::kVehicleToLeft);
  if (!consistency.exceeded[caml] || consistency.window_updates < kLeastUpdates) return decision;
  check_left_ = 0.0;
  decision.reopened = true;
  decision.sigma = uniformBlockSigmas(options_.translation_sigma, options_.rotation_sigma);
  decision.dropped = filter->reopen(JumpBlock::kVehicleToLeft, decision.sigma);
  std::ostringstream message;
  message << "x_caml re-opened: the updates after a stretch without points disagree with it "
          << "(consistency statistic " << consistency.statistic[caml] << " > "
          << consistency.bound[caml] << " over " << consistency.window_updates
          << " updates; the mounting changed while nothing was seen?); points re-initialised";
  decision.warning = message.str();
  return decision;
}

}  // namespace osc
