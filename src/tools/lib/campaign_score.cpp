#include "online_stereo_calibration/tools/campaign_score.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "online_stereo_calibration/tools/evaluation.h"

namespace osc {

namespace {

/// (estimate - truth) / sigma per parameter: 0 for no error, +-inf for an error with a zero
/// sigma, NaN for a NaN estimate or a NaN or negative sigma.
std::array<double, 12> signedErrorsInSigmas(const ScenarioFrameResult& f) {
  std::array<double, 12> z{};
  for (int p = 0; p < 12; ++p) {
    const double e = parameterError(f.parameters, f.truth, p);
    z[p] = e / f.sigmas(p);
    if (e == 0.0) z[p] = 0.0;
    if (!std::isfinite(e) || !(f.sigmas(p) >= 0.0)) z[p] = std::numeric_limits<double>::quiet_NaN();
  }
  return z;
}

/// |signed z|; what has none (NaN) is beyond every bound (+inf).
std::array<double, 12> absoluteErrorsInSigmas(const std::array<double, 12>& signed_z) {
  std::array<double, 12> z{};
  for (int p = 0; p < 12; ++p) {
    z[p] =
        std::isnan(signed_z[p]) ? std::numeric_limits<double>::infinity() : std::abs(signed_z[p]);
  }
  return z;
}

}  // namespace

const std::array<std::string, 12>& campaignParameterNames() {
  static const std::array<std::string, 12> names = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                                                    "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};
  return names;
}

std::vector<FrameSpan> unseenChangeSpans(const MeasurementScenario& scenario) {
  if (scenario.step.isZero() || scenario.step_frame < 0) return {};
  for (const FrameSpan& blind : scenario.blind_frames) {
    if (blind.contains(scenario.step_frame)) return {FrameSpan{scenario.step_frame, blind.last}};
  }
  return {};
}

CampaignScore scoreCampaignRun(const std::vector<ScenarioFrameResult>& frames,
                               const std::vector<FrameSpan>& unseen) {
  CampaignScore score;
  int scored = 0, within = 0;
  double nees_sum = 0.0;
  int max_index = 0;
  std::array<double, 12> signed_z_sum{};
  std::array<int, 12> signed_z_count{};
  for (const ScenarioFrameResult& f : frames) {
    const std::array<double, 12> signed_z = signedErrorsInSigmas(f);
    const std::array<double, 12> z = absoluteErrorsInSigmas(signed_z);
    const auto someBeyond = [&z](double bound) {
      return std::any_of(z.begin(), z.end(), [bound](double v) { return !(v <= bound); });
    };
    const bool some_beyond_3 = someBeyond(3.0);
    if (f.converged) {
      if (score.converged_frame < 0) score.converged_frame = f.frame;
      ++score.frames_converged;
      score.frames_converged_beyond_3sigma += some_beyond_3;
    }
    if (f.frame < kCampaignFirstScoredFrame) continue;
    ++scored;
    for (int p = 0; p < 12; ++p) {
      if (z[p] > score.max_z) {
        score.max_z = z[p];
        max_index = p;
      }
    }
    within += !some_beyond_3;
    for (int p = 0; p < 12; ++p) {
      if (!std::isfinite(signed_z[p])) continue;
      signed_z_sum[p] += signed_z[p];
      ++signed_z_count[p];
    }
    if (someBeyond(5.0)) {
      ++score.frames_beyond_5sigma;
      score.frames_beyond_5sigma_unseen += inFrameSpans(unseen, f.frame);
      if (score.first_frame_beyond_5sigma < 0) score.first_frame_beyond_5sigma = f.frame;
    }
    nees_sum += f.nees / 12.0;
  }
  if (scored == 0) {
    throw std::invalid_argument("scoreCampaignRun: no frame from frame " +
                                std::to_string(kCampaignFirstScoredFrame) + " on");
  }
  score.share_within_3sigma = static_cast<double>(within) / scored;
  score.max_z_parameter = campaignParameterNames()[max_index];
  score.nees_mean = nees_sum / scored;
  for (int p = 0; p < 12; ++p) {
    score.mean_z[p] = signed_z_count[p] > 0 ? signed_z_sum[p] / signed_z_count[p]
                                            : std::numeric_limits<double>::quiet_NaN();
  }

  std::vector<double> times;
  for (const ScenarioFrameResult& f : frames) times.push_back(f.time_ms);
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  score.time_ms_median = times[times.size() / 2];

  const size_t first =
      frames.size() > kCampaignRmseFrames ? frames.size() - kCampaignRmseFrames : 0;
  for (int p = 0; p < 12; ++p) {
    double sum = 0.0;
    for (size_t i = first; i < frames.size(); ++i) {
      const double e = parameterError(frames[i].parameters, frames[i].truth, p);
      sum += e * e;
    }
    score.rmse[p] = std::sqrt(sum / (frames.size() - first));
  }
  return score;
}

}  // namespace osc
