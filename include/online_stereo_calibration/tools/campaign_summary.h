/// @file campaign_summary.h
/// @brief DIR/summary.txt of a campaign: how many runs are honest, the worst runs with their
/// seeds and drawn settings, and the same broken down by each setting's bucket.
#pragma once

#include <array>
#include <cmath>
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

/// One parameter's signed error in sigmas over a campaign: the mean over the runs that ran
/// of their CampaignScore::mean_z, and its standard error (the runs' spread / sqrt(runs)).
/// A consistent filter's mean is 0 within about 2 standard errors; beyond 3 the parameter is
/// biased to one side (a mean of -1 says the estimate sits a sigma low on average).
struct ParameterBias {
  double mean = 0.0;
  double standard_error = 0.0;  ///< NaN with fewer than two runs
  int runs = 0;
  bool significant() const { return runs >= 2 && std::abs(mean) > 3.0 * standard_error; }
};

/// ParameterBias of the 12 parameters (interface order) over the rows that ran and have a
/// finite mean_z.
std::array<ParameterBias, 12> campaignParameterBias(const std::vector<CampaignRow>& rows);

/// The summary text. @p worst: how many of the worst runs to list (not honest first, then by
/// descending max_z; failed runs first of all).
std::string formatCampaignSummary(const std::vector<CampaignRow>& rows, int worst = 10);

}  // namespace osc
