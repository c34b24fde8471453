#include "online_stereo_calibration/core/estimator/right_camera_score_test.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "online_stereo_calibration/core/estimator/consistency_monitor.h"
#include "online_stereo_calibration/core/filter/state_layout.h"

namespace osc {

RightCameraScoreOptions RightCameraScoreOptions::from(const FilterConfig& config) {
  RightCameraScoreOptions o;
  o.false_alarm = config.jump_score_false_alarm;
  o.updates = config.jump_score_updates;
  o.widening = config.jump_score_widening;
  return o;
}

ScoreWidening RightCameraScoreTest::afterStep(CalibrationFilter* filter) {
  ScoreWidening result;
  if (filter->starts() != last_start_) {
    last_start_ = filter->starts();
    streak_ = 0;
  }
  const UpdateScores* scores = filter->lastUpdateScores();
  if (!(options_.false_alarm > 0.0) || scores == nullptr) {
    streak_ = 0;
    return result;
  }
  std::array<double, 2> statistic;
  std::array<int, 2> dof;
  calibrationStatistics(scores->score, scores->information, &statistic, &dof);
  const int right = static_cast<int>(ConsistencyBlock::kLeftToRight);
  // A common excess of every measurement (noise under-estimated) is not x_camr's (the
  // monitor's F test).
  const double common = std::max(1.0, scores->rest / std::max(1, scores->rest_dof));
  const bool contradicted =
      dof[right] > 0 &&
      statistic[right] / common > chiSquareUpperQuantile(dof[right], options_.false_alarm);
  streak_ = contradicted ? streak_ + 1 : 0;
  if (streak_ < options_.updates || !filter->canReopen(JumpBlock::kLeftToRight)) return result;
  streak_ = 0;
  // The rotation the updates indicate; its translation is left: one update determines x_camr's
  // translation poorly (its estimate was centimetres off in a 0.15 deg roll knock).
  const Vector6d shift =
      partialShiftEstimate(scores->score, scores->information, ConsistencyBlock::kLeftToRight);
  const Eigen::Vector3d rotation = shift.segment<3>(layout::kRotation);
  filter->widenRotationVariance(JumpBlock::kLeftToRight,
                                (options_.widening * rotation).array().square().matrix());
  result.widened = true;
  std::ostringstream message;
  message << "x_camr's rotation contradicted by " << options_.updates
          << " updates in a row (score statistic " << statistic[right] / common << " for "
          << dof[right] << " dof): its sigma widened to cover a shift of "
          << rotation.transpose() * (180.0 / M_PI) << " deg; points kept";
  result.warning = message.str();
  return result;
}

}  // namespace osc
