/// @file campaign_test_support.h
/// @brief Helpers of the campaign tests (test_campaign*, test_campaign_run_*): a run's setting,
/// ranges without recorded trajectories, and the CampaignRun fixture with the runs of the
/// shipped ranges (config/campaign.yaml) it replays.
#pragma once

#include <cmath>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/tools/campaign.h"
#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_draw.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"

namespace osc {

inline constexpr double kDeg = M_PI / 180.0;

/// The value of the setting column @p name (campaignSettingNames), "" if there is none.
inline std::string settingOf(const CampaignSettings& settings, const std::string& name) {
  for (const auto& [key, value] : settings)
    if (key == name) return value;
  return "";
}

/// Ranges without the recorded trajectories (which need files).
inline const char* kNoRecorded = "motion: {kind: {offroad: 1, urban: 1}}\n";

/// The directory of the recorded trajectories the shipped ranges draw from (config/campaign.yaml's
/// trajectories_dir): the project's ../shared/data, not part of a clone.
inline const std::string kSharedTrajectories =
    std::string(OSC_SOURCE_DIR) + "/../shared/data/trajectories";

/// Tests that replay a run drawn from the shipped ranges (or docs/results/campaign's) trace runs
/// drawn with the recorded trajectories: without them every run's draw changes, so they skip.
class CampaignRun : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::is_directory(kSharedTrajectories)) {
      GTEST_SKIP() << "needs the recorded trajectories of ../shared/data: " << kSharedTrajectories
                   << " not found";
    }
  }
};

/// Run @p run (of @p frames frames) of the shipped ranges (config/campaign.yaml), with the
/// events' kinds replaced by @p events when given. An error in the spec if the file's events
/// changed. The steering phase is held at 0 (a left turn at frame 0) unless @p drawn_phase, as
/// it was when the runs these tests trace were drawn and written up in docs/RESULTS.md: the
/// phase has a random stream of its own, so every other value of the run is the one drawn then.
inline CampaignRunSpec shippedRun(int run, const std::string& events = "", int frames = 600,
                                  bool drawn_phase = false) {
  const std::string dir = std::string(OSC_SOURCE_DIR) + "/config";
  CampaignInputs inputs;
  inputs.ranges_text = readTextFile(dir + "/campaign.yaml");
  if (!events.empty()) {
    const std::string shipped = "kind: {none: 1, caml_yaw_step: 1, camr_knock: 1, camr_drift: 1}";
    const size_t at = inputs.ranges_text.find(shipped);
    if (at == std::string::npos) {
      CampaignRunSpec failed;
      failed.error = "config/campaign.yaml's events changed";
      return failed;
    }
    inputs.ranges_text.replace(at, shipped.size(), events);
  }
  inputs.ranges = parseCampaignRanges(inputs.ranges_text, "campaign.yaml", dir);
  if (!drawn_phase) inputs.ranges.yaw_phase_deg = {0.0, 0.0};
  inputs.frames = frames;
  return drawCampaignRun(inputs, run);
}

/// @p spec run with the shipped configuration, changed by @p change when given.
inline CampaignRow runShipped(const CampaignRunSpec& spec,
                              const std::function<void(FilterConfig*)>& change = {}) {
  EstimatorConfig config;
  if (change) change(&config.filter);
  return runCampaignRun(spec, config, false);
}

/// A run's honesty figures, for an assertion's message.
inline std::string scoreText(const CampaignRow& row) {
  std::ostringstream text;
  text << row.score.share_within_3sigma << " within 3 sigma, " << row.score.frames_beyond_5sigma
       << " frames beyond 5, max z " << row.score.max_z << " on " << row.score.max_z_parameter;
  return text.str();
}

}  // namespace osc
