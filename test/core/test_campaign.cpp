// Tests of the campaign tool's library (issue 13): short campaigns (4 runs of 100 frames at
// measurement level), their files, resuming and replaying them, their stored configuration,
// seeds, failed runs, and honesty told from overconfidence.
#include <gtest/gtest.h>

#include <stdlib.h>
#include "campaign_test_support.h"
#include "temp_dir.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/campaign.h"
#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/output_directory.h"

namespace osc {
namespace {

/// Easy ranges: a paper-like off-road drive with small start errors, no event, no odometry or
/// scene trouble, a forward-looking pinhole rig.
const char* kEasy =
    "rig: {lens: pinhole, mounting: forward, forward_pitch_down_deg: [0, 5],"
    " baseline_m: [0.2, 0.4], focal_px: [500, 700], image_width_px: 640}\n"
    "motion: {kind: offroad, offroad_speed_mps: [3, 4], offroad_roll_pitch_std_deg: [1.5, 2]}\n"
    "start_errors: {caml_translation_m: [0, 0.05], caml_angle_deg: [0, 1],"
    " camr_baseline_percent: [-5, 5], camr_translation_m: [0, 0.005], camr_angle_deg: [0, 0.5]}\n"
    "events: {kind: none}\n"
    "odometry: {time_offset_ms: 0, scale_error_percent: 0, rotation_rate_bias_deg_s: 0,"
    " velocity_bias_mps: 0}\n"
    "scene: {blind_stretches: 0, moving_point_fraction: 0}\n";

CampaignInputs inputsFor(const std::string& ranges_yaml, int frames, unsigned seed) {
  CampaignInputs inputs;
  inputs.ranges_text = ranges_yaml;
  inputs.ranges = parseCampaignRanges(ranges_yaml, "test ranges");
  inputs.frames = frames;
  inputs.seed = seed;
  return inputs;
}

CampaignOptions quietOptions(const std::string& out, int runs, int jobs) {
  CampaignOptions options;
  options.runs = runs;
  options.jobs = jobs;
  options.out = out;
  options.progress = false;
  options.plot = false;
  return options;
}

/// The documented columns, in order (issue 13), then rmse_<p>, the settings, run_s, status.
TEST(Campaign, FourRunsOf100FramesWriteTheDocumentedColumnsAndResume) {
  TempDir dir;
  const CampaignInputs inputs = inputsFor(kNoRecorded, 100, 40);
  const std::vector<CampaignRow> rows = runCampaign(inputs, quietOptions(dir.path(), 4, 2));
  ASSERT_EQ(rows.size(), 4u);
  std::ifstream csv(dir.path() + "/campaign.csv");
  std::string header;
  std::getline(csv, header);
  std::vector<std::string> expected = {"run",
                                       "seed",
                                       "frames",
                                       "share_within_3sigma",
                                       "frames_beyond_5sigma",
                                       "frames_beyond_5sigma_unseen",
                                       "max_z",
                                       "max_z_parameter",
                                       "first_frame_beyond_5sigma",
                                       "nees_mean",
                                       "converged_frame",
                                       "frames_converged",
                                       "frames_converged_beyond_3sigma",
                                       "time_ms_median"};
  for (const char* p : {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l", "xr", "yr", "zr", "roll_r",
                        "pitch_r", "yaw_r"}) {
    expected.push_back(std::string("rmse_") + p);
  }
  for (const char* p : {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l", "xr", "yr", "zr", "roll_r",
                        "pitch_r", "yaw_r"}) {
    expected.push_back(std::string("mean_z_") + p);
  }
  for (const std::string& name : campaignSettingNames(false)) expected.push_back(name);
  expected.push_back("run_s");
  expected.push_back("status");
  std::string joined;
  for (const std::string& c : expected) joined += (joined.empty() ? "" : ",") + c;
  EXPECT_EQ(header, joined);
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 4);
  const std::vector<CampaignRow> read = readCampaignCsv(dir.path() + "/campaign.csv");
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(read[k].run, k);
    EXPECT_EQ(read[k].seed, 40u + k);
    EXPECT_EQ(read[k].frames, 100);
    EXPECT_TRUE(read[k].ok()) << read[k].status;
    EXPECT_GE(read[k].score.share_within_3sigma, 0.0);
    EXPECT_LE(read[k].score.share_within_3sigma, 1.0);
    EXPECT_GT(read[k].score.time_ms_median, 0.0);
  }
  const std::string summary = readTextFile(dir.path() + "/summary.txt");
  EXPECT_NE(summary.find("Campaign of 4 runs"), std::string::npos);
  EXPECT_NE(summary.find("baseline_m"), std::string::npos);

  // Resuming runs nothing again: the rows (with their wall times) stay as they were.
  const std::vector<CampaignRow> again = runCampaign(inputs, quietOptions(dir.path(), 4, 2));
  for (int k = 0; k < 4; ++k) EXPECT_EQ(again[k].run_seconds, rows[k].run_seconds);
  // Other inputs are refused, naming what differs.
  try {
    runCampaign(inputsFor(kNoRecorded, 120, 40), quietOptions(dir.path(), 4, 2));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--frames"), std::string::npos) << e.what();
  }
  try {
    runCampaign(inputsFor(std::string(kNoRecorded) + "events: {kind: none}\n", 100, 40),
                quietOptions(dir.path(), 4, 2));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the ranges"), std::string::npos) << e.what();
  }
}

// --only K gives the campaign's row of run K, with the per-frame files of evaluate.
TEST(Campaign, ReplayOfARunGivesItsRowAndPerFrameFiles) {
  TempDir dir;
  const CampaignInputs inputs = inputsFor(kNoRecorded, 100, 20);
  const std::vector<CampaignRow> rows = runCampaign(inputs, quietOptions(dir.path(), 2, 2));
  const CampaignRow replayed = replayCampaignRun(inputs, dir.path(), 1, false);
  EXPECT_EQ(replayed.seed, 21u);
  EXPECT_EQ(replayed.settings, rows[1].settings);
  // The campaign's rows come from its CSV (10 significant digits).
  EXPECT_NEAR(replayed.score.share_within_3sigma, rows[1].score.share_within_3sigma, 1e-9);
  EXPECT_NEAR(replayed.score.max_z, rows[1].score.max_z, 1e-8 * rows[1].score.max_z);
  EXPECT_EQ(replayed.score.frames_beyond_5sigma, rows[1].score.frames_beyond_5sigma);
  for (int p = 0; p < 12; ++p) {
    EXPECT_NEAR(replayed.score.rmse[p], rows[1].score.rmse[p], 1e-8 * rows[1].score.rmse[p]);
  }
  const std::string run_dir = dir.path() + "/run_1";
  const std::vector<EstimateRow> estimates = readEstimatesCsv(run_dir + "/estimates.csv");
  const std::vector<ReferenceRow> reference = readReferenceCsv(run_dir + "/reference.csv");
  ASSERT_EQ(estimates.size(), 100u);
  ASSERT_EQ(reference.size(), 100u);
  // The RMSE of xl over the last 150 (here all 100) frames, from the files.
  double sum = 0.0;
  for (size_t i = 0; i < estimates.size(); ++i) {
    const double e = estimates[i].parameters(0) - reference[i].parameters(0);
    sum += e * e;
  }
  EXPECT_NEAR(std::sqrt(sum / 100.0), replayed.score.rmse[0], 1e-12);
  EXPECT_EQ(readCampaignCsv(run_dir + "/run.csv").size(), 1u);
  EXPECT_NE(readTextFile(run_dir + "/settings.txt").find("seed 21"), std::string::npos);
  // events.txt: a line per frame in which the estimator acted, in frame order, each naming
  // what it did; a start from a drawn guess is tempered in its first updates.
  std::istringstream events(readTextFile(run_dir + "/events.txt"));
  std::string line;
  int previous = -1, lines = 0, tempered = 0;
  while (std::getline(events, line)) {
    ++lines;
    int frame = -1;
    ASSERT_EQ(std::sscanf(line.c_str(), "frame %d:", &frame), 1) << line;
    EXPECT_GT(frame, previous) << line;
    EXPECT_LT(frame, 100) << line;
    previous = frame;
    tempered += line.find("update tempered x") != std::string::npos;
  }
  EXPECT_GT(lines, 0);
  EXPECT_GT(tempered, 0);
  // A replay with other inputs is refused.
  EXPECT_THROW(replayCampaignRun(inputsFor(kNoRecorded, 100, 21), dir.path(), 1, false),
               std::runtime_error);
}

// DIR/inputs/config.yaml is compared by its keys and values, not its text: a campaign stored
// before config/default.yaml's layout grouped the keys in sections (other order, other
// comments) resumes with the same configuration, and one with another value is refused.
TEST(Campaign, StoredConfigIsComparedByKeysAndValues) {
  TempDir dir;
  const CampaignInputs inputs = inputsFor(kNoRecorded, 100, 3);
  storeOrCheckCampaignInputs(dir.path(), inputs);
  const std::string path = dir.path() + "/inputs/config.yaml";
  // The same lines without comments, the top-level keys sorted, the front end's map last in
  // reverse order.
  std::vector<std::string> top, front_end;
  std::istringstream lines(readTextFile(path));
  for (std::string line; std::getline(lines, line);) {
    const size_t first = line.find_first_not_of(' ');
    if (first == std::string::npos || line[first] == '#' || line == "front_end:") continue;
    (first == 0 ? top : front_end).push_back(line);
  }
  ASSERT_GT(top.size(), 50u);
  ASSERT_GT(front_end.size(), 30u);
  std::sort(top.begin(), top.end());
  std::reverse(front_end.begin(), front_end.end());
  std::string relaid;
  for (const std::string& line : top) relaid += line + "\n";
  relaid += "front_end:\n";
  for (const std::string& line : front_end) relaid += line + "\n";
  writeTextFileAtomic(path, relaid);
  EXPECT_NO_THROW(storeOrCheckCampaignInputs(dir.path(), inputs));

  for (const std::string& changed :
       {std::string("max_points: 150\n"), std::string("  max_features: 2000\n")}) {
    std::string other = relaid;
    const size_t at = other.find(changed);
    ASSERT_NE(at, std::string::npos) << changed;
    other.insert(at + changed.size() - 1, "1");
    writeTextFileAtomic(path, other);
    try {
      storeOrCheckCampaignInputs(dir.path(), inputs);
      ADD_FAILURE() << "a stored configuration with another value was accepted: " << changed;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("the estimator configuration"), std::string::npos)
          << e.what();
    }
  }
}

TEST(Campaign, SameSeedGivesTheSameRows) {
  TempDir one, two;
  const CampaignInputs inputs = inputsFor(kNoRecorded, 100, 7);
  const std::vector<CampaignRow> a = runCampaign(inputs, quietOptions(one.path(), 2, 2));
  const std::vector<CampaignRow> b = runCampaign(inputs, quietOptions(two.path(), 2, 1));
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(a[k].seed, b[k].seed);
    EXPECT_EQ(a[k].settings, b[k].settings);
    EXPECT_EQ(a[k].score.share_within_3sigma, b[k].score.share_within_3sigma);
    EXPECT_EQ(a[k].score.max_z, b[k].score.max_z);
    EXPECT_EQ(a[k].score.nees_mean, b[k].score.nees_mean);
    EXPECT_EQ(a[k].score.rmse, b[k].score.rmse);
    EXPECT_EQ(a[k].score.converged_frame, b[k].score.converged_frame);
  }
  EXPECT_NE(a[0].score.rmse, a[1].score.rmse);
}

// A run that cannot be made (here: the recording is shorter than the drive) is a failed row;
// the campaign goes on and the summary counts it.
TEST(Campaign, FailedRunsAreRecordedNotFatal) {
  TempDir tum_dir, dir;
  {
    std::ofstream tum(tum_dir.path() + "/short.tum");
    for (int i = 0; i <= 50; ++i) tum << 0.1 * i << " " << 0.5 * i << " 0 0 0 0 0 1\n";
  }
  const std::string ranges =
      "trajectories_dir: " + tum_dir.path() + "\nmotion: {kind: {offroad: 1, recorded: 1}}\n";
  const std::vector<CampaignRow> rows =
      runCampaign(inputsFor(ranges, 100, 3), quietOptions(dir.path(), 6, 2));
  ASSERT_EQ(rows.size(), 6u);
  int failed = 0;
  for (const CampaignRow& row : rows) {
    const bool recorded = settingOf(row.settings, "motion") == "recorded";
    EXPECT_EQ(row.ok(), !recorded) << row.status;
    if (row.ok()) continue;
    ++failed;
    EXPECT_NE(row.status.find("shorter than the drive"), std::string::npos) << row.status;
    EXPECT_TRUE(std::isnan(row.score.share_within_3sigma));
    EXPECT_FALSE(row.honest());
  }
  EXPECT_GT(failed, 0);
  EXPECT_LT(failed, 6);
  EXPECT_NE(
      readTextFile(dir.path() + "/summary.txt")
          .find("(" + std::to_string(6 - failed) + " ran, " + std::to_string(failed) + " failed)"),
      std::string::npos);
}

// The shipped configuration against one that declares the pixel noise 10x too small (the
// simulator adds 0.5 px). On the easy ranges the shipped filter is honest in 3 of the 4 runs
// (run 3: yr beyond 3 sigma in 44 % of the frames, max_z 4.8; a campaign is a measurement,
// and this is one of its findings): the test asserts that majority and that no run is grossly
// overconfident, against every overconfident run being far beyond its sigmas.
TEST(Campaign, OverconfidentConfigurationIsNotHonestTheShippedOneIs) {
  TempDir shipped_dir, overconfident_dir;
  const CampaignInputs shipped = inputsFor(kEasy, 100, 1);
  const std::vector<CampaignRow> good =
      runCampaign(shipped, quietOptions(shipped_dir.path(), 4, 2));
  CampaignInputs overconfident = shipped;
  overconfident.config.filter.pixel_noise = shipped.config.filter.pixel_noise / 10.0;
  // Tempered updates alone keep this one honest (measured: all 4 runs, NEES 0.2-0.4): with
  // 100 times the information per pixel every update would shrink the sigmas far below the
  // random walk's step, so each is tempered, which undoes the declared noise. The test is
  // about the score telling an overconfident filter, so the filter here is the untempered one.
  overconfident.config.filter.max_sigma_shrink_per_update = 0.0;
  const std::vector<CampaignRow> bad =
      runCampaign(overconfident, quietOptions(overconfident_dir.path(), 4, 2));
  int honest = 0;
  for (const CampaignRow& row : good) {
    honest += row.honest();
    EXPECT_LT(row.score.max_z, 6.0) << "run " << row.run;
    EXPECT_LT(row.score.nees_mean, 3.0) << "run " << row.run;
  }
  EXPECT_GE(honest, 3);
  for (const CampaignRow& row : bad) {
    EXPECT_FALSE(row.honest()) << "run " << row.run << ": share " << row.score.share_within_3sigma;
    EXPECT_GT(row.score.max_z, 10.0) << "run " << row.run;
    EXPECT_GT(row.score.nees_mean, 10.0) << "run " << row.run;
  }
  const std::string summary = readTextFile(overconfident_dir.path() + "/summary.txt");
  EXPECT_NE(summary.find("frames_beyond_5sigma = 0): 0 of 4 (0 %)"), std::string::npos) << summary;
}

}  // namespace
}  // namespace osc
