// Tests of what the campaign tool makes of its runs (issue 13): a run's score against its
// sigmas (campaign_score.h), the CSV row (campaign_csv.h), the summary over the runs
// (campaign_summary.h), and the perfect filter the summary's statistics are checked on.
#include <gtest/gtest.h>

#include "campaign_test_support.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_score.h"
#include "online_stereo_calibration/tools/campaign_summary.h"
#include "online_stereo_calibration/tools/perfect_filter.h"

namespace osc {
namespace {

ScenarioFrameResult frameWithErrors(int index, const Vector12d& z) {
  ScenarioFrameResult f;
  f.frame = index;
  f.truth.setZero();
  f.truth(5) = M_PI - 0.001;  // the yaw error must be wrapped
  f.sigmas = Vector12d::Constant(0.01);
  f.parameters = f.truth + z * 0.01;
  f.parameters(5) -= 2 * M_PI;
  f.nees = 24.0;
  f.time_ms = index;
  return f;
}

TEST(CampaignScore, CountsFramesAgainstTheSigmasFromFrame30) {
  std::vector<ScenarioFrameResult> frames;
  for (int k = 0; k < 100; ++k) {
    Vector12d z = Vector12d::Constant(1.0);
    if (k < 30) z(0) = 100.0;   // not scored
    if (k == 40) z(5) = -4.0;   // beyond 3 sigma only
    if (k == 50) z(10) = 6.0;   // beyond 5 sigma
    if (k == 60) z(10) = -7.5;  // the largest
    frames.push_back(frameWithErrors(k, z));
    frames.back().converged = k >= 45;
  }
  const CampaignScore s = scoreCampaignRun(frames);
  EXPECT_DOUBLE_EQ(s.share_within_3sigma, 67.0 / 70.0);
  EXPECT_EQ(s.frames_beyond_5sigma, 2);
  EXPECT_EQ(s.first_frame_beyond_5sigma, 50);
  EXPECT_NEAR(s.max_z, 7.5, 1e-6);
  EXPECT_EQ(s.max_z_parameter, "pitch_r");
  EXPECT_DOUBLE_EQ(s.nees_mean, 2.0);
  EXPECT_EQ(s.converged_frame, 45);
  // Frames 45-99 are CONVERGED; of them 50 and 60 are beyond 3 sigma (40 is not converged).
  EXPECT_EQ(s.frames_converged, 55);
  EXPECT_EQ(s.frames_converged_beyond_3sigma, 2);
  EXPECT_DOUBLE_EQ(s.time_ms_median, 50.0);
  // All 100 frames are within the last 150: xl has error 1 in frames 0-29, 0.01 after.
  EXPECT_NEAR(s.rmse[0], std::sqrt((30 * 1.0 + 70 * 1e-4) / 100), 1e-12);
  // yaw_l's errors, wrapped: 0.01 except -0.04 in frame 40.
  EXPECT_NEAR(s.rmse[5], std::sqrt((99 * 1e-4 + 16e-4) / 100), 1e-9);
  // Signed errors in sigmas over frames 30-99 only (xl's 100 sigmas before are not scored);
  // yaw_l's wrapped across pi.
  EXPECT_NEAR(s.mean_z[0], 1.0, 1e-9);
  EXPECT_NEAR(s.mean_z[5], (69.0 - 4.0) / 70.0, 1e-6);
  EXPECT_NEAR(s.mean_z[10], (68.0 + 6.0 - 7.5) / 70.0, 1e-9);
}

// A knock at frame 50 inside a blind stretch 45-60: frames 50-60 are beyond 5 sigma because
// nothing could be seen yet (unseen), frames 61-62 because the filter had not followed yet
// (its own). Both count as beyond 5 sigma; only the first as unseen.
TEST(CampaignScore, FramesBeyondInAnUnseenChangeAreToldApart) {
  MeasurementScenario scenario;
  scenario.frames = 100;
  scenario.step.setZero();
  scenario.step(9) = 0.01;
  scenario.step_frame = 50;
  scenario.blind_frames = {FrameSpan{10, 20}, FrameSpan{45, 60}};
  const std::vector<FrameSpan> unseen = unseenChangeSpans(scenario);
  ASSERT_EQ(unseen.size(), 1u);
  EXPECT_EQ(unseen[0].first, 50);
  EXPECT_EQ(unseen[0].last, 60);

  std::vector<ScenarioFrameResult> frames;
  for (int k = 0; k < 100; ++k) {
    Vector12d z = Vector12d::Constant(1.0);
    if (k >= 50 && k <= 62) z(9) = 40.0;
    frames.push_back(frameWithErrors(k, z));
  }
  const CampaignScore s = scoreCampaignRun(frames, unseen);
  EXPECT_EQ(s.frames_beyond_5sigma, 13);
  EXPECT_EQ(s.frames_beyond_5sigma_unseen, 11);
  EXPECT_EQ(scoreCampaignRun(frames).frames_beyond_5sigma_unseen, 0);

  // A step where frames are tracked, none, or one before its blind stretch: nothing unseen.
  scenario.step_frame = 30;
  EXPECT_TRUE(unseenChangeSpans(scenario).empty());
  scenario.step_frame = 44;
  EXPECT_TRUE(unseenChangeSpans(scenario).empty());
  scenario.step_frame = 50;
  scenario.step.setZero();
  EXPECT_TRUE(unseenChangeSpans(scenario).empty());
}

TEST(CampaignScore, NanEstimateIsBeyondEveryBound) {
  std::vector<ScenarioFrameResult> frames;
  for (int k = 0; k < 40; ++k) frames.push_back(frameWithErrors(k, Vector12d::Zero()));
  frames[35].parameters(2) = NAN;
  const CampaignScore s = scoreCampaignRun(frames);
  EXPECT_EQ(s.frames_beyond_5sigma, 1);
  EXPECT_EQ(s.first_frame_beyond_5sigma, 35);
  EXPECT_TRUE(std::isinf(s.max_z));
  EXPECT_EQ(s.max_z_parameter, "zl");
  // The NaN frame is left out of zl's mean signed error, not spread over it.
  EXPECT_EQ(s.mean_z[2], 0.0);
  EXPECT_THROW(
      scoreCampaignRun(std::vector<ScenarioFrameResult>(frames.begin(), frames.begin() + 30)),
      std::invalid_argument);
}

TEST(CampaignCsv, RowsRoundTripAndFailedRowsKeepTheirColumns) {
  const CampaignRanges ranges = parseCampaignRanges(kNoRecorded, "t");
  const std::vector<std::string> names = campaignSettingNames(false);
  CampaignRow row;
  row.run = 4;
  row.seed = 11;
  row.frames = 100;
  row.score.share_within_3sigma = 0.875;
  row.score.frames_beyond_5sigma = 3;
  row.score.frames_beyond_5sigma_unseen = 2;
  row.score.max_z = 6.25;
  row.score.max_z_parameter = "yaw_r";
  row.score.first_frame_beyond_5sigma = 44;
  row.score.nees_mean = 1.5;
  row.score.converged_frame = -1;
  row.score.frames_converged = 9;
  row.score.frames_converged_beyond_3sigma = 7;
  row.score.time_ms_median = 0.75;
  for (int p = 0; p < 12; ++p) row.score.rmse[p] = 0.001 * (p + 1);
  for (int p = 0; p < 12; ++p) row.score.mean_z[p] = 0.25 * (p - 6);
  row.settings = drawCampaignRun(ranges, 4, 11, 100, false).settings;
  row.run_seconds = 1.25;
  const CampaignRow failed = failedCampaignRow(5, 12, 100, {}, "boom, twice\nagain");
  const std::string text = campaignCsvHeader(names) + "\n" + formatCampaignCsvLine(row, names) +
                           "\n" + formatCampaignCsvLine(failed, names) + "\n";
  const std::vector<CampaignRow> back = parseCampaignCsv(text, "t.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].run, 4);
  EXPECT_EQ(back[0].seed, 11u);
  EXPECT_EQ(back[0].score.share_within_3sigma, 0.875);
  EXPECT_EQ(back[0].score.frames_beyond_5sigma, 3);
  EXPECT_EQ(back[0].score.frames_beyond_5sigma_unseen, 2);
  EXPECT_EQ(back[0].score.max_z_parameter, "yaw_r");
  EXPECT_EQ(back[0].score.first_frame_beyond_5sigma, 44);
  EXPECT_EQ(back[0].score.frames_converged, 9);
  EXPECT_EQ(back[0].score.frames_converged_beyond_3sigma, 7);
  EXPECT_EQ(back[0].score.rmse[11], 0.012);
  EXPECT_EQ(back[0].score.mean_z, row.score.mean_z);
  EXPECT_EQ(back[0].settings, row.settings);
  EXPECT_TRUE(back[0].ok());
  EXPECT_FALSE(back[0].honest());
  EXPECT_FALSE(back[1].ok());
  EXPECT_EQ(back[1].status, "failed: boom; twice again");
  EXPECT_TRUE(std::isnan(back[1].score.share_within_3sigma));
  EXPECT_TRUE(std::isnan(back[1].score.mean_z[7]));
  EXPECT_EQ(back[1].settings.size(), names.size());
  EXPECT_THROW(parseCampaignCsv("run,seed\n1,2\n", "bad.csv"), std::runtime_error);

  // A file written before the mean_z_<p> columns (a campaign resumed after an update) reads
  // back with NaN there and everything else in its place.
  const auto withoutMeanZ = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream in(line);
    for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
    const size_t first = 14 + 12;  // score columns, then rmse_<p>
    fields.erase(fields.begin() + first, fields.begin() + first + 12);
    std::string joined;
    for (const std::string& f : fields) joined += (joined.empty() ? "" : ",") + f;
    return joined;
  };
  const std::vector<CampaignRow> old =
      parseCampaignCsv(withoutMeanZ(campaignCsvHeader(names)) + "\n" +
                           withoutMeanZ(formatCampaignCsvLine(row, names)) + "\n",
                       "old.csv");
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].score.rmse[11], 0.012);
  EXPECT_TRUE(std::isnan(old[0].score.mean_z[0]));
  EXPECT_EQ(old[0].settings, row.settings);
  EXPECT_EQ(old[0].run_seconds, 1.25);
}

// The mean signed error of a parameter over the runs, with its standard error from the runs'
// spread: yr a sigma low in every run is biased, zr's means scattered about 0 are not; a
// failed run does not count.
TEST(CampaignSummary, ParameterBiasIsTheRunsMeanSignedErrorWithItsStandardError) {
  std::vector<CampaignRow> rows;
  const std::vector<double> yr = {-1.0, -1.2, -0.8, -1.0}, zr = {0.1, -0.1, 0.2, -0.2};
  for (size_t i = 0; i < yr.size(); ++i) {
    CampaignRow row;
    row.run = static_cast<int>(i);
    row.score.mean_z.fill(0.0);
    row.score.mean_z[7] = yr[i];
    row.score.mean_z[8] = zr[i];
    rows.push_back(row);
  }
  rows.push_back(failedCampaignRow(9, 9, 100, {}, "crashed"));
  const std::array<ParameterBias, 12> bias = campaignParameterBias(rows);
  EXPECT_EQ(bias[7].runs, 4);
  EXPECT_NEAR(bias[7].mean, -1.0, 1e-12);
  EXPECT_NEAR(bias[7].standard_error, std::sqrt(0.08 / 3.0 / 4.0), 1e-12);
  EXPECT_TRUE(bias[7].significant());
  EXPECT_NEAR(bias[8].mean, 0.0, 1e-12);
  EXPECT_FALSE(bias[8].significant());
  EXPECT_FALSE(bias[0].significant());  // all 0: no spread, no bias
  const std::string summary = formatCampaignSummary(rows, 1);
  EXPECT_NE(summary.find("yr -1.00 +- 0.08*"), std::string::npos) << summary;
  EXPECT_NE(summary.find("zr +0.00 +- 0.09 "), std::string::npos) << summary;
}

TEST(PerfectFilter, IsHonestInTheRunsItsStatisticsPredict) {
  // scripts/honest_by_chance.py over 4000 runs of 600 frames: honest 0.767 (correlation time
  // 100 frames) to 0.853 (a constant's running mean), beyond 5 sigma at most 0.001, mean share
  // within 3 sigma 0.968 (12 x 0.27 % beyond 3 sigma per frame). 1000 runs: +-0.014.
  const PerfectFilterScore long_runs = perfectFilterScore(600, 1000);
  EXPECT_GT(long_runs.honest_low, 0.72);
  EXPECT_LT(long_runs.honest_low, 0.81);
  EXPECT_GT(long_runs.honest_high, 0.81);
  EXPECT_LT(long_runs.honest_high, 0.90);
  EXPECT_LT(long_runs.beyond_5sigma, 0.01);
  EXPECT_NEAR(long_runs.mean_share, 0.968, 0.004);
  // The same seed, the same figures (drawn once per process); another seed, figures within
  // the draw's own spread.
  const PerfectFilterScore again = perfectFilterScore(600, 1000);
  EXPECT_EQ(again.honest_low, long_runs.honest_low);
  EXPECT_EQ(again.honest_high, long_runs.honest_high);
  const PerfectFilterScore other = perfectFilterScore(600, 1000, 2);
  EXPECT_NE(other.mean_share, long_runs.mean_share);  // drawn anew, not the cached figures
  EXPECT_NEAR(other.honest_low, long_runs.honest_low, 0.06);
  EXPECT_NEAR(other.honest_high, long_runs.honest_high, 0.06);
  EXPECT_THROW(perfectFilterScore(30), std::invalid_argument);
  // The summary puts it beside the campaign.
  std::vector<CampaignRow> rows(2);
  for (CampaignRow& row : rows) row.frames = 200;
  const std::string summary = formatCampaignSummary(rows, 1);
  EXPECT_NE(summary.find("A perfect filter"), std::string::npos) << summary;
  EXPECT_NE(summary.find("on runs of 200 frames: honest in "), std::string::npos) << summary;
}

TEST(CampaignSummary, BucketsSplitNumbersInThirdsAndKindsByValue) {
  std::vector<CampaignRow> rows;
  const std::vector<std::pair<std::string, std::string>> values = {
      {"0", "a"}, {"1", "b"}, {"2", "a"}, {"3", "-"}, {"6", "a"}};
  for (size_t i = 0; i < values.size(); ++i) {
    CampaignRow row;
    row.run = static_cast<int>(i);
    row.settings = {{"x", values[i].first}, {"kind", values[i].second}};
    row.score.share_within_3sigma = i == 1 ? 0.5 : 1.0;  // run 1 is not honest
    row.score.max_z = static_cast<double>(i);
    if (i == 2 || i == 3) row.score.frames_beyond_5sigma = 10;  // run 3: 4 of them unseen
    if (i == 3) row.score.frames_beyond_5sigma_unseen = 4;
    row.score.frames_converged = 50;                            // 250 in all
    row.score.frames_converged_beyond_3sigma = i == 1 ? 5 : 0;  // 5 of 250 in run 1
    rows.push_back(row);
  }
  const std::vector<CampaignBucket> x = campaignBuckets(rows, "x");
  ASSERT_EQ(x.size(), 3u);
  EXPECT_EQ(x[0].label, "[0, 2)");
  EXPECT_EQ(x[0].rows, (std::vector<int>{0, 1}));
  EXPECT_EQ(x[1].rows, (std::vector<int>{2, 3}));
  EXPECT_EQ(x[2].label, "[4, 6]");
  EXPECT_EQ(x[2].rows, (std::vector<int>{4}));
  const std::vector<CampaignBucket> kind = campaignBuckets(rows, "kind");
  ASSERT_EQ(kind.size(), 3u);
  EXPECT_EQ(kind[0].label, "-");
  EXPECT_EQ(kind[1].label, "a");
  EXPECT_EQ(kind[1].rows, (std::vector<int>{0, 2, 4}));
  const std::string summary = formatCampaignSummary(rows, 1);
  EXPECT_NE(
      summary.find("Honest (share_within_3sigma >= 0.95 and frames_beyond_5sigma = 0): 2 of 5"),
      std::string::npos)
      << summary;
  EXPECT_NE(summary.find("Frames beyond 5 sigma: 20 in 2 runs; of them 4 in 1 runs in an unseen "
                         "change"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("250 frames CONVERGED, of them 5 (2.0 %) in 1 runs with some error "
                         "beyond 3 sigma"),
            std::string::npos)
      << summary;
  // The worst run listed first is the one that is not honest with the largest max_z, though
  // run 4 has a larger one; its frames beyond 5 sigma with those in an unseen change.
  EXPECT_NE(summary.find("run 3  seed 0  NOT honest"), std::string::npos) << summary;
  EXPECT_NE(summary.find("frames_beyond_5sigma 10 (unseen 4)"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("run 4  seed"), std::string::npos) << summary;
}

}  // namespace
}  // namespace osc
