/// @file frame_event.h
/// @brief The per-frame event log: one line for each thing a component did to the
/// calibration in a frame, or found wrong with its input (docs/design.md, "the order per
/// image pair"). The estimator and the pipeline write it (FrameReport::events); the node's
/// diagnostics key each line by frameEventName(), `evaluate` and the campaign print its text.
#pragma once

#include <string>
#include <vector>

namespace osc {

enum class FrameEvent {
  kMotionRejected,        ///< the motion was unusable: points dropped, calibration kept
  kObservationsIgnored,   ///< NaN/Inf pixels or sigmas, or pixels no ray of the lens reaches
  kJump,                  ///< JumpTest re-opened a block before the update (StepReport::jump)
  kRightRotationWidened,  ///< RightCameraScoreTest widened x_camr's rotation
  kRightCameraOffEpipolarLines,  ///< EpipolarKnockTest re-opened x_camr's rotation
  kLeftCameraReopenedAfterGap,   ///< LeftCameraGapCheck re-opened x_caml
  kRelinearized,                 ///< RestartFromEstimate restarted from the estimate
  kMountingRotationFromMotion,   ///< the hand-eye start restarted x_caml's rotation
  kRightRotationFromStereoFit,   ///< the stereo fit re-seeded x_camr (CalibrationPipeline)
  kBaselineFromMotion,           ///< x_camr's translation restarted at the measured length
  kTooFewPoints,                 ///< a stretch of pairs too few to update begins (predicted only)
  kNoPointInitialised,           ///< stereo pairs came, none triangulates: the baseline guess?
  kNoPointMeasurable,            ///< tracked points measured, none predictable, for 10 pairs
  kCovarianceRepaired,           ///< the calibration covariance had to be made positive definite
  kOdometryNoiseLearned,         ///< OdometryNoiseMatcher raised the motion noise (or set it back)
};

/// A short name of the event (the key the node's diagnostics count it under).
const char* frameEventName(FrameEvent kind);

/// One line of the log.
struct FrameEventLine {
  FrameEvent kind;
  std::string text;  ///< what was done and why, with its figures
};

/// A frame's log, in the order things happened.
class FrameEvents {
 public:
  void add(FrameEvent kind, std::string text) { lines_.push_back({kind, std::move(text)}); }
  /// Before every other line (an event that happened before the estimator ran).
  void addFirst(FrameEvent kind, std::string text) {
    lines_.insert(lines_.begin(), {kind, std::move(text)});
  }
  bool has(FrameEvent kind) const {
    for (const FrameEventLine& line : lines_)
      if (line.kind == kind) return true;
    return false;
  }
  bool empty() const { return lines_.empty(); }
  std::vector<FrameEventLine>::const_iterator begin() const { return lines_.begin(); }
  std::vector<FrameEventLine>::const_iterator end() const { return lines_.end(); }
  /// Every line's text, in order.
  std::vector<std::string> texts() const;

 private:
  std::vector<FrameEventLine> lines_;
};

}  // namespace osc
