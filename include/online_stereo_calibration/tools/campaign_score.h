/// @file campaign_score.h
/// @brief Scoring one campaign run against its truth: is the filter honest about its errors
/// (the errors within the sigmas it reports), how large are they, when did it converge.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"

namespace osc {

/// Frames before this one are not scored for honesty (the filter's first seconds).
constexpr int kCampaignFirstScoredFrame = 30;
/// The RMSE is taken over the last this many frames (fewer if the drive is shorter).
constexpr int kCampaignRmseFrames = 150;

/// The scores of one run (the first CSV columns after run, seed, frames). Errors are
/// estimate - truth per parameter (interface order, m and rad, angles wrapped to
/// (-pi, pi]); z = |error| / sigma with the filter's reported 1 sigma of that parameter.
/// A NaN estimate or sigma counts as beyond every bound (z = +inf).
struct CampaignScore {
  /// Share of frames >= kCampaignFirstScoredFrame with all 12 |errors| <= 3 sigma.
  double share_within_3sigma = 0.0;
  /// Frames >= kCampaignFirstScoredFrame with some |error| > 5 sigma.
  int frames_beyond_5sigma = 0;
  /// Of those, the frames in an unseen change (unseenChangeSpans): the calibration changed
  /// while nothing could be tracked and nothing has been tracked since, so no estimator
  /// could know of it yet. They still count above (a run with them is not honest); this
  /// tells them apart from the filter's own.
  int frames_beyond_5sigma_unseen = 0;
  /// Largest z over those frames and parameters ...
  double max_z = 0.0;
  /// ... and its parameter's name (xl .. yaw_r).
  std::string max_z_parameter;
  /// First frame >= kCampaignFirstScoredFrame with some |error| > 5 sigma; -1 if none.
  int first_frame_beyond_5sigma = -1;
  /// Mean over frames >= kCampaignFirstScoredFrame of the 12-dof NEES (tangent error with the
  /// full covariance, ScenarioFrameResult::nees) / 12: about 1 when honest.
  double nees_mean = 0.0;
  /// First frame at which the state is CONVERGED (isConverged); -1 if never.
  int converged_frame = -1;
  /// Frames (from frame 0) in the CONVERGED state: what a user who trusts the state sees.
  int frames_converged = 0;
  /// Of those, the frames with some |error| > 3 sigma: the state says "trust me" while the
  /// estimate is off. An honest 12-parameter Gaussian filter shows about 3 % of its frames
  /// so (1 - 0.9973^12); far more means CONVERGED is confidently wrong.
  int frames_converged_beyond_3sigma = 0;
  /// Median estimator time per frame (ms).
  double time_ms_median = 0.0;
  /// RMSE of each parameter over the last kCampaignRmseFrames frames (m, rad).
  std::array<double, 12> rmse{};
  /// Mean over frames >= kCampaignFirstScoredFrame of each parameter's signed error / sigma
  /// (frames where it is not finite left out; NaN if none is). Within a run the errors are
  /// correlated in time, so one run's mean says little; across many runs of a consistent
  /// filter these means average to about 0, and a parameter whose average is not is biased
  /// (the filter errs to one side more than its sigma allows; campaign_summary.h).
  std::array<double, 12> mean_z{};
};

/// Scores a run's per-frame results (in frame order; at least one frame from
/// kCampaignFirstScoredFrame on); frames within @p unseen are also counted in
/// frames_beyond_5sigma_unseen. @throws std::invalid_argument otherwise.
CampaignScore scoreCampaignRun(const std::vector<ScenarioFrameResult>& frames,
                               const std::vector<FrameSpan>& unseen = {});

/// The frames in which the scenario's calibration change (its step) is unseen: from the
/// step's frame to the end of the blind stretch (MeasurementScenario::blind_frames) it falls
/// in. Empty when there is no step or it falls where frames are tracked.
std::vector<FrameSpan> unseenChangeSpans(const MeasurementScenario& scenario);

/// The parameter names in interface order (xl, yl, zl, roll_l, ..., yaw_r).
const std::array<std::string, 12>& campaignParameterNames();

}  // namespace osc
