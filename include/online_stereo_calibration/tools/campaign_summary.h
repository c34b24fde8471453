/// @file campaign_summary.h
/// @brief DIR/summary.txt of a campaign: how many runs are honest, the worst runs with their
/// seeds and drawn settings, and the same broken down by each setting's bucket.
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/tools/campaign_csv.h"

namespace osc {

/// One bucket of a setting: a kind, or an interval [low, high) of a numeric setting.
struct CampaignBucket {
  std::string label;      ///< the kind, or "[low, high)" (the last interval closed)
  std::vector<int> rows;  ///< indices into the rows
};

/// The buckets of setting @p name over @p rows: numeric settings with more than 3 distinct
/// values in 3 equal-width intervals between their smallest and largest value, else one
/// bucket per value (non-numeric values such as "-" always by value).
std::vector<CampaignBucket> campaignBuckets(const std::vector<CampaignRow>& rows,
                                            const std::string& name);

/// The summary text. @p worst: how many of the worst runs to list (not honest first, then by
/// descending max_z; failed runs first of all).
std::string formatCampaignSummary(const std::vector<CampaignRow>& rows, int worst = 10);

}  // namespace osc
