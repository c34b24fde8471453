#include "online_stereo_calibration/core/estimator/frame_event.h"

namespace osc {

const char* frameEventName(FrameEvent kind) {
  switch (kind) {
    case FrameEvent::kMotionRejected:
      return "motion rejected";
    case FrameEvent::kObservationsIgnored:
      return "observations ignored";
    case FrameEvent::kJump:
      return "sudden calibration change";
    case FrameEvent::kRightRotationWidened:
      return "right camera rotation contradicted";
    case FrameEvent::kRightCameraOffEpipolarLines:
      return "right camera off its epipolar lines";
    case FrameEvent::kLeftCameraReopenedAfterGap:
      return "left camera re-opened after a stretch without points";
    case FrameEvent::kRelinearized:
      return "start re-linearised";
    case FrameEvent::kMountingRotationFromMotion:
      return "mounting rotation from motion";
    case FrameEvent::kRightRotationFromStereoFit:
      return "right camera rotation from stereo fit";
    case FrameEvent::kBaselineFromMotion:
      return "baseline length from motion";
    case FrameEvent::kTooFewPoints:
      return "too few points to update";
    case FrameEvent::kNoPointInitialised:
      return "no point initialised";
    case FrameEvent::kNoPointMeasurable:
      return "no point measurable";
    case FrameEvent::kCovarianceRepaired:
      return "covariance repaired";
    case FrameEvent::kOdometryNoiseLearned:
      return "odometry noise learned";
  }
  return "unknown event";
}

std::vector<std::string> FrameEvents::texts() const {
  std::vector<std::string> texts;
  texts.reserve(lines_.size());
  for (const FrameEventLine& line : lines_) texts.push_back(line.text);
  return texts;
}

}  // namespace osc
