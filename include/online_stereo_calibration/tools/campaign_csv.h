/// @file campaign_csv.h
/// @brief The rows of DIR/campaign.csv (and of DIR/runs/run_NNNN.csv, one row each):
/// `run,seed,frames,share_within_3sigma,frames_beyond_5sigma,max_z,max_z_parameter,
/// first_frame_beyond_5sigma,nees_mean,converged_frame,frames_converged,
/// frames_converged_beyond_3sigma,time_ms_median`, then `rmse_<p>` for
/// the 12 parameters (m, rad), then the drawn settings (campaignSettingNames()), then
/// `run_s` (wall time of the run, s) and `status` ("ok" or "failed: why"; a failed run has
/// nan scores).
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/tools/campaign_draw.h"
#include "online_stereo_calibration/tools/campaign_score.h"

namespace osc {

/// A run counts as honest with share_within_3sigma >= this and no frame beyond 5 sigma.
constexpr double kHonestShare = 0.95;

/// One row: a run, its scores and its drawn settings.
struct CampaignRow {
  int run = 0;
  unsigned seed = 0;
  int frames = 0;
  CampaignScore score;
  CampaignSettings settings;
  double run_seconds = 0.0;   ///< wall time of the run (simulation, estimator, scoring), s
  std::string status = "ok";  ///< "ok" or "failed: <reason>"

  bool ok() const { return status == "ok"; }
  /// ok, share_within_3sigma >= kHonestShare and frames_beyond_5sigma == 0.
  bool honest() const;
};

/// A row for a run that failed (scores nan / -1) with @p reason; settings as drawn, if known.
CampaignRow failedCampaignRow(int run, unsigned seed, int frames, const CampaignSettings& settings,
                              const std::string& reason);

/// All column names, in order, for the given setting names.
std::vector<std::string> campaignCsvColumns(const std::vector<std::string>& setting_names);

/// The header line (no newline) for @p setting_names.
std::string campaignCsvHeader(const std::vector<std::string>& setting_names);

/// One line (no newline). Settings must be in @p setting_names order; a row without
/// settings (a failed draw) gets empty fields. Commas and newlines in values become ';' / ' '.
std::string formatCampaignCsvLine(const CampaignRow& row,
                                  const std::vector<std::string>& setting_names);

/// Parses a campaign CSV (header first). @throws std::runtime_error naming @p source_name and
/// the line for a wrong header, a missing field or a bad number.
std::vector<CampaignRow> parseCampaignCsv(const std::string& text, const std::string& source_name);

/// Reads a campaign CSV file (see parseCampaignCsv).
std::vector<CampaignRow> readCampaignCsv(const std::string& path);

}  // namespace osc
