/// @file campaign.h
/// @brief Running a campaign (issue 13): N runs drawn from ranges, each simulated and scored
/// in its own process, J at once, resumable; then DIR/campaign.csv, summary.txt and
/// campaign.png. docs/campaign.md describes the files.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_draw.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"

namespace osc {

/// What defines a campaign's rows: a DIR holds the runs of one set of inputs only.
struct CampaignInputs {
  std::string ranges_text;  ///< the ranges YAML as given (stored as DIR/inputs/ranges.yaml)
  CampaignRanges ranges;    ///< parsed from ranges_text
  EstimatorConfig config;   ///< stored as DIR/inputs/config.yaml (every key)
  int frames = 600;         ///< frames per run, at 10 Hz
  unsigned seed = 1;        ///< run k uses seed + k
  bool images = false;      ///< rendered images through the whole pipeline
};

/// How to run it.
struct CampaignOptions {
  int runs = 0;          ///< N: runs 0 .. N-1
  int jobs = 1;          ///< J: runs at once, each in its own process
  std::string out;       ///< DIR
  bool progress = true;  ///< progress bar on stderr
  bool plot = true;      ///< DIR/campaign.png via scripts/plot_campaign.py
};

/// The per-frame results of one run: the measurement-level runner, or with @p images the
/// whole pipeline on rendered images (the frames it processed).
std::vector<ScenarioFrameResult> simulateCampaignRun(
    const CampaignRunSpec& spec, const EstimatorConfig& config, bool images,
    const std::function<void(const ScenarioFrameResult&)>& on_frame = {});

/// Simulates and scores one run; any exception gives a failed row naming it.
CampaignRow runCampaignRun(const CampaignRunSpec& spec, const EstimatorConfig& config, bool images);

/// Draws run @p run of a campaign (seed = inputs.seed + run); a failed draw throws.
CampaignRunSpec drawCampaignRun(const CampaignInputs& inputs, int run);

/// Stores the inputs in @p dir/inputs, or, when a campaign is already there, checks that they
/// are the same. @throws std::runtime_error naming what differs (frames, seed, images, the
/// ranges, the estimator configuration).
void storeOrCheckCampaignInputs(const std::string& dir, const CampaignInputs& inputs);

/// Runs the runs of 0 .. N-1 without a row in DIR/runs (run_NNNN.csv, written atomically by
/// the run's process; a crashed process gets a failed row), then writes DIR/campaign.csv
/// (sorted by run), DIR/summary.txt and (options.plot) DIR/campaign.png. Returns the rows.
/// @throws std::runtime_error for bad inputs or a DIR of another campaign.
std::vector<CampaignRow> runCampaign(const CampaignInputs& inputs, const CampaignOptions& options);

/// --only K: runs run @p run alone (in this process) into DIR/run_K/: estimates.csv and
/// reference.csv (the per-frame estimate and truth, estimates_csv.h), events.txt (a line per
/// frame in which the estimator tempered, restarted, re-opened or warned), run.csv (its campaign
/// row), settings.txt (scores and drawn settings, also written to @p report if given) and,
/// with @p plot, the plots of scripts/plot_convergence.py as `evaluate` makes them. The inputs
/// are stored in or checked against DIR (storeOrCheckCampaignInputs). Returns the row.
CampaignRow replayCampaignRun(const CampaignInputs& inputs, const std::string& out, int run,
                              bool plot, std::ostream* report = nullptr);

}  // namespace osc
