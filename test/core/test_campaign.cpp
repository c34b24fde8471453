// Tests of the campaign tool's library (issue 13): ranges, drawing, scoring, the CSV, and
// short campaigns (4 runs of 100 frames at measurement level).
#include <gtest/gtest.h>

#include <stdlib.h>
#include "temp_dir.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/campaign.h"
#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_draw.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"
#include "online_stereo_calibration/tools/campaign_score.h"
#include "online_stereo_calibration/tools/campaign_summary.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/perfect_filter.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// The value of the setting column @p name (campaignSettingNames), "" if there is none.
std::string settingOf(const CampaignSettings& settings, const std::string& name) {
  for (const auto& [key, value] : settings)
    if (key == name) return value;
  return "";
}

std::string parseError(const std::string& yaml) {
  try {
    parseCampaignRanges(yaml, "test.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

/// Ranges without the recorded trajectories (which need files).
const char* kNoRecorded = "motion: {kind: {offroad: 1, urban: 1}}\n";

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

TEST(CampaignRanges, ErrorsNameTheKey) {
  EXPECT_NE(parseError(std::string(kNoRecorded) + "rig: {baseline: [0.1, 0.2]}")
                .find("rig.baseline: unknown key"),
            std::string::npos);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "rigs: {}").find("rigs: unknown key"),
            std::string::npos);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "rig: {baseline_m: [0.5, 0.1]}")
                .find("rig.baseline_m: [0.5, 0.1]: min > max"),
            std::string::npos);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "images: {exposure_flicker: [0, 2]}")
                .find("images.exposure_flicker"),
            std::string::npos);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "scene: {blind_stretches: [0, 1.5]}")
                .find("scene.blind_stretches: [0, 1.5] must be integers"),
            std::string::npos);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "rig: {baseline_m: fast}")
                .find("rig.baseline_m: 'fast' is not a number or [min, max]"),
            std::string::npos);
  EXPECT_NE(parseError("motion: {kind: {offroad: 1, flying: 1}}")
                .find("motion.kind: unknown kind 'flying'"),
            std::string::npos);
  EXPECT_NE(parseError("motion: {kind: {offroad: 0}}").find("motion.kind: at least one weight"),
            std::string::npos);
  // The default kinds include `recorded`, which needs trajectories_dir.
  EXPECT_NE(parseError("").find("trajectories_dir: not given"), std::string::npos);
  // ... and a directory that holds them when it is the only kind.
  const std::string only_recorded =
      parseError("trajectories_dir: /nonexistent/dir\nmotion: {kind: recorded}");
  EXPECT_NE(only_recorded.find("trajectories_dir: '/nonexistent/dir' is not a directory"),
            std::string::npos);
  EXPECT_NE(only_recorded.find("the only kind"), std::string::npos);
  // Every problem at once.
  const std::string both =
      parseError(std::string(kNoRecorded) + "rig: {baseline_m: [0.5, 0.1], focal: 3}");
  EXPECT_NE(both.find("rig.baseline_m"), std::string::npos);
  EXPECT_NE(both.find("rig.focal: unknown key"), std::string::npos);
  // A fixed value and a single kind.
  const CampaignRanges fixed = parseCampaignRanges(
      std::string(kNoRecorded) + "rig: {baseline_m: 0.3, lens: equidistant}", "t");
  EXPECT_EQ(fixed.baseline_m.min, 0.3);
  EXPECT_EQ(fixed.baseline_m.max, 0.3);
  EXPECT_EQ(fixed.lens.weight("equidistant"), 1.0);
  EXPECT_EQ(fixed.lens.weight("pinhole"), 0.0);
}

TEST(CampaignRanges, MissingRecordedTrajectoriesDropThatKindAndSaySo) {
  // A clone without ../shared/data: the shipped ranges still draw the other motions.
  TempDir empty;
  for (const std::string& dir : {std::string("/nonexistent/dir"), empty.path()}) {
    const CampaignRanges ranges = parseCampaignRanges("trajectories_dir: " + dir, "t");
    EXPECT_EQ(ranges.motion.weight("recorded"), 0.0) << dir;
    EXPECT_EQ(ranges.motion.weight("offroad"), 1.0) << dir;
    EXPECT_EQ(ranges.motion.weight("urban"), 1.0) << dir;
    EXPECT_NE(ranges.dropped_recorded.find("trajectories_dir: '" + dir), std::string::npos)
        << ranges.dropped_recorded;
    EXPECT_NE(ranges.dropped_recorded.find("'recorded' dropped"), std::string::npos);
    CampaignInputs inputs;
    inputs.ranges = ranges;
    inputs.frames = 100;
    for (int run = 0; run < 12; ++run) {
      const CampaignRunSpec spec = drawCampaignRun(inputs, run);
      ASSERT_TRUE(spec.error.empty()) << spec.error;
      EXPECT_NE(settingOf(spec.settings, "motion"), "recorded") << "run " << run;
    }
  }
  // With the trajectories there, nothing is dropped.
  TempDir with_file;
  std::ofstream(with_file.path() + "/a.tum") << "# empty\n";
  const CampaignRanges kept = parseCampaignRanges("trajectories_dir: " + with_file.path(), "t");
  EXPECT_TRUE(kept.dropped_recorded.empty()) << kept.dropped_recorded;
  EXPECT_EQ(kept.motion.weight("recorded"), 1.0);
}

TEST(CampaignRanges, ShippedFileStatesTheBuiltInDefaults) {
  // Resolve trajectories_dir (../../shared/data/trajectories beside config/) in a scratch tree.
  TempDir dir;
  std::filesystem::create_directories(dir.path() + "/repo/config");
  std::filesystem::create_directories(dir.path() + "/shared/data/trajectories");
  std::ofstream(dir.path() + "/shared/data/trajectories/a.tum") << "# empty\n";
  const std::string text = readTextFile(std::string(OSC_SOURCE_DIR) + "/config/campaign.yaml");
  const CampaignRanges shipped =
      parseCampaignRanges(text, "config/campaign.yaml", dir.path() + "/repo/config");
  const CampaignRanges defaults;
  for (const DrawRangeSpec& spec : drawRangeSpecs()) {
    EXPECT_EQ((shipped.*spec.member).min, (defaults.*spec.member).min) << spec.key;
    EXPECT_EQ((shipped.*spec.member).max, (defaults.*spec.member).max) << spec.key;
  }
  for (const KindChoiceSpec& spec : kindChoiceSpecs()) {
    EXPECT_EQ((shipped.*spec.member).weights, (defaults.*spec.member).weights) << spec.key;
  }
  ASSERT_EQ(shipped.trajectory_files.size(), 1u);
  EXPECT_NE(shipped.trajectory_files[0].find("a.tum"), std::string::npos);
}

TEST(CampaignDraw, ValuesStayInTheirRangesAndRepeatWithTheSeed) {
  const CampaignRanges ranges = parseCampaignRanges(
      std::string(kNoRecorded) + "rig: {mounting: {forward: 1, sideways: 1}}", "t");
  std::set<std::string> lenses, events, motions, mountings;
  for (int run = 0; run < 300; ++run) {
    const CampaignRunSpec spec = drawCampaignRun(ranges, run, 100 + run, 600, true);
    const MeasurementScenario& s = spec.scenario;
    ASSERT_TRUE(s.validate().empty()) << run;
    EXPECT_EQ(s.seed, 100u + run);
    const double baseline = -s.truth(7);
    EXPECT_GE(baseline, 0.08);
    EXPECT_LE(baseline, 0.6);
    EXPECT_GE(s.left.width, 640);
    EXPECT_LE(s.left.width, 1280);
    EXPECT_EQ(s.left.height * 4, s.left.width * 3);
    EXPECT_GE(s.left.fx, 400);
    EXPECT_LE(s.left.fx, 1400);
    if (s.left.model == DistortionModel::kPlumbBob) {
      EXPECT_GE(s.left.distortion[0], -0.3);
      EXPECT_LE(s.left.distortion[0], 0.0);
    }
    for (int i = 0; i < 3; ++i) EXPECT_LE(std::abs(s.initial_error(i)), 0.5);
    for (int i = 3; i < 6; ++i) EXPECT_LE(std::abs(s.initial_error(i)), 10 * kDeg + 1e-12);
    EXPECT_LE(std::abs(s.initial_error(7)), 0.5 * baseline + 1e-12);
    for (int i : {6, 8}) EXPECT_LE(std::abs(s.initial_error(i)), 0.02);
    for (int i = 9; i < 12; ++i) EXPECT_LE(std::abs(s.initial_error(i)), 5 * kDeg + 1e-12);
    if (s.step_frame >= 0) {
      EXPECT_GE(s.step_frame, 240);
      EXPECT_LE(s.step_frame, 360);
      const double size = s.step.norm() / kDeg;
      EXPECT_GE(size, 0.1 - 1e-9);
      EXPECT_LE(size, 10 + 1e-9);
    }
    EXPECT_LE(s.drift_per_second.segment<3>(9).norm(), 0.5 * kDeg / 60 + 1e-15);
    EXPECT_LE(s.drift_per_second.segment<3>(6).norm(), 0.005 / 60 + 1e-15);
    EXPECT_LE(std::abs(s.odometry_error.time_offset), 0.030);
    EXPECT_LE(std::abs(s.odometry_error.scale_error), 0.02);
    EXPECT_LE(s.odometry_error.rotation_rate_bias, 0.01 * kDeg);
    EXPECT_LE(s.odometry_error.velocity_bias, 0.02);
    EXPECT_LE(s.blind_frames.size(), 1u);
    for (const FrameSpan& b : s.blind_frames) {
      EXPECT_GE(b.last - b.first + 1, 20);
      EXPECT_LE(b.last - b.first + 1, 50);
      EXPECT_GE(b.first, 30);
    }
    if (s.motion.planar) {
      EXPECT_GE(s.motion.speed, 8);
      EXPECT_LE(s.motion.speed, 15);
      EXPECT_GE(s.motion.stops.size(), 1u);
      EXPECT_LE(s.motion.stops.size(), 2u);
      for (const TimeSpan& stop : s.motion.stops) {
        EXPECT_GE(stop.duration, 2);
        EXPECT_LE(stop.duration, 10);
        EXPECT_GE(stop.start, 0);
        EXPECT_LE(stop.start + stop.duration + s.motion.stop_ramp, 60.0);
      }
    } else {
      EXPECT_GE(s.motion.speed, 2);
      EXPECT_LE(s.motion.speed, 6);
    }
    EXPECT_LE(s.moving_point_fraction, 0.2);
    EXPECT_LE(spec.image_options.render.noise_sigma, 3);
    EXPECT_LE(spec.image_options.render.blur_sigma, 1);
    EXPECT_LE(spec.image_options.exposure_variation, 0.2);
    // The settings are the documented columns, in order.
    const std::vector<std::string> names = campaignSettingNames(true);
    ASSERT_EQ(spec.settings.size(), names.size());
    for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(spec.settings[i].first, names[i]);
    lenses.insert(settingOf(spec.settings, "lens"));
    mountings.insert(settingOf(spec.settings, "mounting"));
    motions.insert(settingOf(spec.settings, "motion"));
    events.insert(settingOf(spec.settings, "event"));
  }
  EXPECT_EQ(lenses, (std::set<std::string>{"pinhole", "plumb_bob", "equidistant"}));
  EXPECT_EQ(mountings, (std::set<std::string>{"forward", "sideways_left", "sideways_right"}));
  EXPECT_EQ(motions, (std::set<std::string>{"offroad", "urban"}));
  EXPECT_EQ(events, (std::set<std::string>{"none", "caml_yaw_step", "camr_knock", "camr_drift"}));

  // The same seed gives the same run; another seed another one.
  const CampaignRunSpec a = drawCampaignRun(ranges, 3, 7, 600, false);
  const CampaignRunSpec b = drawCampaignRun(ranges, 3, 7, 600, false);
  const CampaignRunSpec c = drawCampaignRun(ranges, 3, 8, 600, false);
  EXPECT_EQ(a.settings, b.settings);
  EXPECT_EQ(a.scenario.truth, b.scenario.truth);
  EXPECT_EQ(a.scenario.initial_error, b.scenario.initial_error);
  EXPECT_NE(a.scenario.initial_error, c.scenario.initial_error);
}

TEST(CampaignDraw, TheSteeringPhaseIsDrawnOnItsOwnStreamAndLeavesTheRestOfTheRun) {
  // Until session 34 every drawn drive started at the height of a left turn. The phase is
  // drawn over 0-360 deg now, from a stream of its own: holding it at 0 gives the run drawn
  // before it existed, every other value unchanged.
  const CampaignRanges drawn = parseCampaignRanges(kNoRecorded, "t");
  ASSERT_EQ(drawn.yaw_phase_deg.min, 0.0);
  ASSERT_EQ(drawn.yaw_phase_deg.max, 360.0);
  const CampaignRanges held =
      parseCampaignRanges("motion: {kind: {offroad: 1, urban: 1}, yaw_phase_deg: 0}", "t");
  int left_turn_starts = 0, right_turn_starts = 0;
  constexpr int kRuns = 200;
  for (int run = 0; run < kRuns; ++run) {
    const CampaignRunSpec a = drawCampaignRun(drawn, run, 100 + run, 600, true);
    const CampaignRunSpec b = drawCampaignRun(held, run, 100 + run, 600, true);
    const double phase = a.scenario.motion.yaw_phase;
    ASSERT_GE(phase, 0.0);
    ASSERT_LT(phase, 2.0 * M_PI);
    EXPECT_EQ(b.scenario.motion.yaw_phase, 0.0);
    EXPECT_NEAR(std::stod(settingOf(a.settings, "yaw_phase_deg")), phase / kDeg, 1e-3);
    // Everything but the phase is the run drawn without it.
    ASSERT_EQ(a.settings.size(), b.settings.size());
    for (size_t i = 0; i < a.settings.size(); ++i) {
      if (a.settings[i].first != "yaw_phase_deg") {
        EXPECT_EQ(a.settings[i], b.settings[i]) << run;
      }
    }
    EXPECT_EQ(a.scenario.initial_error, b.scenario.initial_error);
    EXPECT_EQ(a.scenario.odometry_error.time_offset, b.scenario.odometry_error.time_offset);
    EXPECT_EQ(a.image_options.render.noise_sigma, b.image_options.render.noise_sigma);
    // Which way the drive turns first: the yaw rate at frame 0 is amplitude * cos(phase).
    (std::cos(phase) > 0.0 ? left_turn_starts : right_turn_starts) += 1;
  }
  // Binomial(200, 1/2): 100 +- 7; below 70 of either would be 4 sigma.
  EXPECT_GT(left_turn_starts, 70);
  EXPECT_GT(right_turn_starts, 70);
  // A recorded trajectory has no steering profile: no phase.
  TempDir dir;
  {
    std::ofstream tum(dir.path() + "/line.tum");
    for (int i = 0; i <= 1000; ++i) tum << 100.0 + 0.1 * i << " " << 0.5 * i << " 0 0 0 0 0 1\n";
  }
  const CampaignRunSpec recorded = drawCampaignRun(
      parseCampaignRanges("trajectories_dir: " + dir.path() + "\nmotion: {kind: recorded}", "t"), 0,
      1, 300, false);
  EXPECT_EQ(settingOf(recorded.settings, "yaw_phase_deg"), "-");
  EXPECT_EQ(recorded.scenario.motion.yaw_phase, 0.0);
}

TEST(CampaignDraw, RecordedTrajectoryStretchLiesInTheFile) {
  TempDir dir;
  {
    std::ofstream tum(dir.path() + "/line.tum");
    for (int i = 0; i <= 1000; ++i) tum << 100.0 + 0.1 * i << " " << 0.5 * i << " 0 0 0 0 0 1\n";
  }
  const CampaignRanges ranges =
      parseCampaignRanges("trajectories_dir: " + dir.path() + "\nmotion: {kind: recorded}", "t");
  for (int run = 0; run < 20; ++run) {
    const CampaignRunSpec spec = drawCampaignRun(ranges, run, run, 300, false);
    EXPECT_TRUE(spec.error.empty()) << spec.error;
    ASSERT_TRUE(spec.scenario.recorded_trajectory);
    EXPECT_DOUBLE_EQ(spec.scenario.recorded_trajectory->firstStamp(), 100.0);
    EXPECT_GE(spec.scenario.recorded_start_offset, 0.0);
    EXPECT_LE(spec.scenario.recorded_start_offset + 30.0, 100.0);
    EXPECT_EQ(settingOf(spec.settings, "trajectory"), "line");
  }
  // A drive longer than the recording: the run cannot be made, the error names the file, the
  // settings are all there.
  const CampaignRunSpec too_long = drawCampaignRun(ranges, 0, 0, 2000, false);
  EXPECT_NE(too_long.error.find("line.tum"), std::string::npos) << too_long.error;
  EXPECT_EQ(too_long.settings.size(), campaignSettingNames(false).size());
}

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

/// The directory of the recorded trajectories the shipped ranges draw from (config/campaign.yaml's
/// trajectories_dir): the project's ../shared/data, not part of a clone.
const std::string kSharedTrajectories =
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
CampaignRunSpec shippedRun(int run, const std::string& events = "", int frames = 600,
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
CampaignRow runShipped(const CampaignRunSpec& spec,
                       const std::function<void(FilterConfig*)>& change = {}) {
  EstimatorConfig config;
  if (change) change(&config.filter);
  return runCampaignRun(spec, config, false);
}

/// A run's honesty figures, for an assertion's message.
std::string scoreText(const CampaignRow& row) {
  std::ostringstream text;
  text << row.score.share_within_3sigma << " within 3 sigma, " << row.score.frames_beyond_5sigma
       << " frames beyond 5, max z " << row.score.max_z << " on " << row.score.max_z_parameter;
  return text.str();
}

// Issue 14: "an honest and reachable state": a user who trusts CONVERGED must find the errors
// within the sigmas. An honest Gaussian filter has about 3 % of its frames with some of the
// 12 errors beyond 3 sigma whatever its state says (12 x 0.27 %). The shipped filter over the
// first ten runs of the shipped ranges, against one that declares the odometry's motion noise
// 5x smaller than the simulator's: its sigmas shrink to CONVERGED as fast, its errors do not.
// (A pixel noise declared 3x or 10x too small never reaches CONVERGED on these runs: its
// innovations keep re-opening the blocks. Without the velocity-error states: 590 of 1172
// CONVERGED frames beyond 3 sigma.)
/// The frames of @p spec (measurement level, the shipped configuration unless @p config) whose
/// warnings hold one that starts with @p prefix.
std::vector<int> framesWarning(const CampaignRunSpec& spec, const std::string& prefix,
                               const FilterConfig& config = FilterConfig()) {
  std::vector<int> frames;
  for (const ScenarioFrameResult& f : runMeasurementScenario(spec.scenario, config)) {
    for (const std::string& warning : f.warnings) {
      if (warning.rfind(prefix, 0) == 0) frames.push_back(f.frame);
    }
  }
  return frames;
}

TEST_F(CampaignRun, AStallWithEveryTrackedPointUnmeasurableIsWarnedOnce) {
  // Run 92 of the shipped ranges with its drawn steering phase (6.5 deg; docs/RESULTS.md
  // "Session 34"): at frame 10 x_camr's rotation is re-opened to 8.5 deg, and from then on
  // each of the 40 tracked points is dropped as not measurable until frame 92, which the
  // estimator did not say. Now it warns once, in the tenth such pair in a row; with phase 0
  // the run keeps its points and never warns.
  const std::string prefix = "no tracked point could be predicted";
  const CampaignRunSpec drawn = shippedRun(92, "", 600, /*drawn_phase=*/true);
  ASSERT_TRUE(drawn.error.empty()) << drawn.error;
  ASSERT_NEAR(drawn.scenario.motion.yaw_phase * 180.0 / M_PI, 6.479, 1e-3);
  const std::vector<int> stalled = framesWarning(drawn, prefix);
  ASSERT_EQ(stalled.size(), 1u);
  EXPECT_GE(stalled[0], 19);
  EXPECT_LE(stalled[0], 30);
  const CampaignRunSpec phase0 = shippedRun(92);
  ASSERT_TRUE(phase0.error.empty()) << phase0.error;
  EXPECT_TRUE(framesWarning(phase0, prefix).empty());
}

TEST_F(CampaignRun, TheConvergedStateIsReachedAndNotConfidentlyWrong) {
  int converged = 0, converged_off = 0, overconfident_converged = 0, overconfident_off = 0;
  for (int run = 0; run < 10; ++run) {
    const CampaignRunSpec spec = shippedRun(run);
    ASSERT_TRUE(spec.error.empty()) << spec.error;
    const CampaignRow shipped = runShipped(spec);
    const CampaignRow overconfident = runShipped(spec, [](FilterConfig* c) {
      c->motion_translation_noise /= 5.0;
      c->motion_rotation_noise /= 5.0;
    });
    ASSERT_TRUE(shipped.ok()) << shipped.status;
    ASSERT_TRUE(overconfident.ok()) << overconfident.status;
    converged += shipped.score.frames_converged;
    converged_off += shipped.score.frames_converged_beyond_3sigma;
    overconfident_converged += overconfident.score.frames_converged;
    overconfident_off += overconfident.score.frames_converged_beyond_3sigma;
  }
  // Measured: 1071 frames CONVERGED in 5 of the 10 runs, 2 of them beyond 3 sigma.
  EXPECT_GE(converged, 500);
  EXPECT_LE(converged_off, 0.03 * converged) << converged_off << " of " << converged;
  // Measured: 1582 of 1864 frames CONVERGED beyond 3 sigma.
  EXPECT_GT(overconfident_off, 0.3 * overconfident_converged)
      << overconfident_off << " of " << overconfident_converged;
}

TEST_F(CampaignRun, AYawStepOfTheLeftCameraOnAFlatRoadIsDetectedThoughZlStaysOpen) {
  // Run 121 of the shipped ranges (config/campaign.yaml, seed 122): a sideways-left camera on
  // an urban (planar) drive, x_caml yawed by -4.8 deg at frame 301. zl cannot be determined on
  // a flat road, so its sigma stays far above the re-opened jump_translation_sigma; when that
  // alone kept a block from being re-opened, the step's frame gated out every point, nothing
  // was re-opened and yaw_l stayed ~100 sigma off for the rest of the drive.
  const CampaignRunSpec spec = shippedRun(121);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "event"), "caml_yaw_step");
  ASSERT_EQ(settingOf(spec.settings, "motion"), "urban");
  EstimatorConfig config;
  const CampaignRow shipped = runCampaignRun(spec, config, false);
  config.filter.jump_settle_time = 1e6;  // translations must settle first, as before
  const CampaignRow translations_first = runCampaignRun(spec, config, false);
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(translations_first.ok()) << translations_first.status;
  // The step is followed: yaw_l ends where the truth is, and is not the worst parameter.
  // (The run is not honest since session 12, on yaw_r: 6.0 sigma, 87 % of the frames within
  // 3 sigma, with points in units of the baseline; docs/RESULTS.md "Session 12".)
  constexpr int kYawL = 5;
  EXPECT_LT(shipped.score.rmse[kYawL], 0.2 * kDeg)
      << "yaw_l RMSE over the last frames (deg): " << shipped.score.rmse[kYawL] / kDeg;
  EXPECT_NE(shipped.score.max_z_parameter, "yaw_l")
      << shipped.score.max_z << " sigma, " << shipped.score.frames_beyond_5sigma
      << " frames beyond 5";
  EXPECT_GT(translations_first.score.frames_beyond_5sigma, 100);  // measured: 299
  EXPECT_EQ(translations_first.score.max_z_parameter, "yaw_l");
  EXPECT_GT(translations_first.score.rmse[kYawL], 0.5 * kDeg);  // measured: 0.96 deg
}

TEST_F(CampaignRun, AYawStepOfASidewaysCameraReopensOnlyTheTurnedAxis) {
  // Run 144 of the shipped ranges: a sideways-right camera on a flat urban drive, x_caml
  // yawed by 8.8 deg at frame 304. Re-opened to 10 deg on every axis, pitch_l (about the
  // direction of travel, which only turns tell) locked ~3 sigma off at sigma 1 deg for 100
  // frames. The turn fitted to the tracked points' left bearings moves x_caml
  // and re-opens only its yaw; pitch_l keeps what it knew (docs/RESULTS.md "Session 31").
  const CampaignRunSpec spec = shippedRun(144);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "event"), "caml_yaw_step");
  ASSERT_EQ(settingOf(spec.settings, "mounting"), "sideways_right");
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow every_axis =
      runShipped(spec, [](FilterConfig* c) { c->jump_fit_rotation_sigma = 0.0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(every_axis.ok()) << every_axis.status;
  constexpr int kPitchL = 4;
  // Measured: 99 % within 3 sigma, none beyond 5; pitch_l RMSE 0.14 deg.
  EXPECT_GE(shipped.score.share_within_3sigma, 0.95) << scoreText(shipped);
  EXPECT_EQ(shipped.score.frames_beyond_5sigma, 0) << scoreText(shipped);
  EXPECT_LT(shipped.score.rmse[kPitchL], 0.25 * kDeg) << shipped.score.rmse[kPitchL] / kDeg;
  // Measured: 84 % within 3 sigma; pitch_l RMSE 0.64 deg (3.1 deg at frame 400).
  EXPECT_LT(every_axis.score.share_within_3sigma, 0.9) << scoreText(every_axis);
  EXPECT_GT(every_axis.score.rmse[kPitchL], 0.4 * kDeg) << every_axis.score.rmse[kPitchL] / kDeg;
}

TEST_F(CampaignRun, ADronesForwardVelocityErrorIsEstimatedNotTakenForAYawOfTheRightCamera) {
  // Run 40 of the shipped ranges without its event: a 0.28 m rig on a recorded EuRoC drone
  // stretch (~0.4 m/s) whose odometry has a velocity error of 0.019 m/s per axis, 5 % of the
  // motion along the drone's forward axis. With only the lateral and vertical errors as
  // states yaw_r ended ~39 sigma off: the forward error changes the depths the motion gives
  // the points, which a vergence of the right camera explains too.
  const CampaignRunSpec spec = shippedRun(40, "kind: {none: 1}");
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "motion"), "recorded");
  ASSERT_GT(EstimatorConfig().filter.odometry_forward_velocity_bias_sigma, 0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow lateral_only =
      runShipped(spec, [](FilterConfig* c) { c->odometry_forward_velocity_bias_sigma = 0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(lateral_only.ok()) << lateral_only.status;
  // Honest until the updates were tempered (max_sigma_shrink_per_update): since then no
  // start transient (yr was 9 sigma off in frames 3-10, then re-linearised), but yl and
  // yaw_r wander to 3.0-3.2 sigma in frames 220-340: 87 % of the frames within 3 sigma.
  // Since the odometry is read at the estimated offset (session 16) the motion noise no
  // longer carries the first-order correction's error here (-14 ms), and yaw_r swings within
  // +-3.4 sigma over ~100 frames: 77 % (88 % with read_odometry_at_offset 0). Since its
  // fisheye's pixel noise is stretched through the lens (session 21) 73 %, max z 4.4.
  EXPECT_GE(shipped.score.share_within_3sigma, 0.7) << scoreText(shipped);
  EXPECT_EQ(shipped.score.frames_beyond_5sigma, 0) << scoreText(shipped);
  EXPECT_GT(lateral_only.score.max_z, 20.0);  // measured: 38.5
  EXPECT_EQ(lateral_only.score.max_z_parameter, "yaw_r");
}

TEST_F(CampaignRun, AKnockDuringAStretchWithoutPointsIsDetectedOnceNewPointsDisagree) {
  // Run 94 of the shipped ranges: x_camr is knocked by 0.5 deg at frame 293, while no point
  // is seen (a 3.2 s blind stretch). The new points after it are triangulated with the old
  // x_camr; 30-60 % of their next measurements were gated out per frame, never the 60 % of
  // the one-frame jump test, and roll_r stayed 20-137 sigma off for 300 frames. The sustained
  // test re-opens x_camr 3 frames after the points return; what is left are the blind frames.
  const CampaignRunSpec spec = shippedRun(94);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_GT(EstimatorConfig().filter.jump_sustained_frames, 0);
  // Since session 18 x_camr's score test (jump_score_*) catches it too, without the sustained
  // test, and since session 21 the new pairs' distance from the epipolar lines
  // (epipolar_knock_*); with none of them, only the one-frame test is left. (Since session 22
  // the step repeated at the corrected motion while slow, motion_relinearizations, leaves the
  // one-frame case 16 frames beyond 5 sigma too: it is off there, as before.)
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow score_only = runShipped(spec, [](FilterConfig* c) {
    c->jump_sustained_frames = 0;
    c->epipolar_knock_false_alarm = 0.0;
  });
  const CampaignRow one_frame_test = runShipped(spec, [](FilterConfig* c) {
    c->jump_sustained_frames = 0;
    c->jump_score_false_alarm = 0.0;
    c->epipolar_knock_false_alarm = 0.0;
    c->motion_relinearizations = 0;
  });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(score_only.ok()) << score_only.status;
  ASSERT_TRUE(one_frame_test.ok()) << one_frame_test.status;
  EXPECT_LT(shipped.score.frames_beyond_5sigma, 30);          // measured: 16
  EXPECT_LT(score_only.score.frames_beyond_5sigma, 30);       // measured: 17
  EXPECT_GT(one_frame_test.score.frames_beyond_5sigma, 200);  // measured: 307
  EXPECT_GE(shipped.score.first_frame_beyond_5sigma, 293);    // not before the knock
}

TEST_F(CampaignRun, AKnockInsideABlindStretchIsFoundOnTheEpipolarLinesNotBlamedOnTheLeftCamera) {
  // Run 102 of the shipped ranges: a 0.127 m rig looking sideways, x_camr knocked by 0.69 deg
  // at frame 357 inside a 4.7 s blind stretch (frames 349-395). The points after it are new,
  // triangulated with the old x_camr at wrong depths, so their next left pixels fail too and
  // the jump test blamed x_caml: x_caml re-opened, x_camr kept 190 sigma off to frame 460.
  // The stereo pairs of frames 396-397 lie off x_camr's epipolar lines (statistic ~1000 for a
  // bound of 33), which depend on x_camr alone: x_camr is re-opened at frame 396 (397 with
  // epipolar_knock_pairs 2, sessions 21-23).
  const CampaignRunSpec spec = shippedRun(102);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_GT(EstimatorConfig().filter.epipolar_knock_false_alarm, 0.0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow without =
      runShipped(spec, [](FilterConfig* c) { c->epipolar_knock_false_alarm = 0.0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(without.ok()) << without.status;
  // What is left are the knock's blind frames (39) and yl's 5.0-5.5 sigma after a small rig's
  // start (6; 97 with epipolar_knock_pairs 2).
  EXPECT_LT(shipped.score.frames_beyond_5sigma, 200) << scoreText(shipped);  // measured: 45
  // Without the test, 243 frames since session 26's far-move restart (331 before).
  EXPECT_GT(without.score.frames_beyond_5sigma, 200) << scoreText(without);  // measured: 243
}

TEST_F(CampaignRun, AStandingCarsOdometryNoiseIsNotTakenForParallax) {
  // Run 106 of the shipped ranges: an 8.5 cm rig on an urban drive at 14.9 m/s with one
  // 7.2 s stop. While the car stands, its measured translation per step is the odometry's
  // noise, and a prediction linearised there (depth times translation) fakes a metric
  // parallax: after the stop yaw_r went 8.6 sigma off (9 frames beyond 5 sigma from frame
  // 275). The step repeated at the corrected motion while slower than 2 m/s
  // (FilterConfig::motion_relinearizations) keeps it honest.
  const CampaignRunSpec spec = shippedRun(106);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "motion"), "urban");
  ASSERT_EQ(settingOf(spec.settings, "stops"), "1");
  ASSERT_GT(EstimatorConfig().filter.motion_relinearizations, 0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow without =
      runShipped(spec, [](FilterConfig* c) { c->motion_relinearizations = 0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(without.ok()) << without.status;
  EXPECT_EQ(shipped.score.frames_beyond_5sigma, 0) << scoreText(shipped);    // measured: max z 2.2
  EXPECT_GE(shipped.score.share_within_3sigma, 0.95) << scoreText(shipped);  // measured: 1.000
  EXPECT_GT(without.score.frames_beyond_5sigma, 0) << scoreText(without);    // measured: 9
  EXPECT_GT(without.score.max_z, 6.0) << scoreText(without);                 // measured: 8.6
}

TEST_F(CampaignRun, AKnockTooSmallToGateOutPointsIsCaughtByItsScoreInTwoUpdates) {
  // Run 23 of the shipped ranges: x_camr knocked by 0.15 deg at frame 339 (a walking rig,
  // 15 cm baseline, no blind stretch). roll_r is 43 sigma off at once, but no point is gated
  // out: each point's right pixel moves by less than a pixel. Without the score test the
  // filter followed the knock over 30 frames, every one beyond 5 sigma. x_camr's score
  // statistic of the first update after the knock is 60-100 for 6 dof; widening its rotation
  // after two such updates leaves only the knock's own frame beyond 5 sigma.
  const CampaignRunSpec spec = shippedRun(23);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_GT(EstimatorConfig().filter.jump_score_false_alarm, 0.0);
  // Since session 21 the pairs' distance from the epipolar lines (epipolar_knock_*) finds it
  // at the next pair as well (run 23: re-opened at frame 340); "without" is without both.
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow score_only =
      runShipped(spec, [](FilterConfig* c) { c->epipolar_knock_false_alarm = 0.0; });
  const CampaignRow without = runShipped(spec, [](FilterConfig* c) {
    c->jump_score_false_alarm = 0.0;
    c->epipolar_knock_false_alarm = 0.0;
  });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(score_only.ok()) << score_only.status;
  ASSERT_TRUE(without.ok()) << without.status;
  EXPECT_LE(score_only.score.frames_beyond_5sigma, 2) << scoreText(score_only);
  // Not before the knock (-1: none, since session 24's epipolar_knock_pairs 1).
  EXPECT_TRUE(shipped.score.first_frame_beyond_5sigma == -1 ||
              shipped.score.first_frame_beyond_5sigma >= 339)
      << scoreText(shipped);
  EXPECT_LE(shipped.score.frames_beyond_5sigma, 2);   // measured: 1 (0 since session 24)
  EXPECT_GT(without.score.frames_beyond_5sigma, 20);  // measured: 30
}

TEST_F(CampaignRun, AKnocksFirstPairOffTheEpipolarLinesReopensTheRightCamera) {
  // Run 23 of the shipped ranges again (x_camr knocked by 0.15 deg at frame 339). The pairs
  // leave the epipolar lines at frame 339 already (statistic 48 for a bound of 33). Waiting
  // for a second such pair (epipolar_knock_pairs 2, sessions 21-23) left that frame's
  // estimate roll_r 33 sigma off; re-opened on the first (the default since session 24), no
  // frame is beyond 5 sigma.
  const CampaignRunSpec spec = shippedRun(23);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(EstimatorConfig().filter.epipolar_knock_pairs, 1);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow two_pairs =
      runShipped(spec, [](FilterConfig* c) { c->epipolar_knock_pairs = 2; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(two_pairs.ok()) << two_pairs.status;
  EXPECT_EQ(shipped.score.frames_beyond_5sigma, 0) << scoreText(shipped);  // measured: 0
  EXPECT_TRUE(shipped.honest()) << scoreText(shipped);                     // measured: 1.000
  EXPECT_EQ(two_pairs.score.first_frame_beyond_5sigma, 339) << scoreText(two_pairs);
  EXPECT_GT(two_pairs.score.max_z, 10.0) << scoreText(two_pairs);  // measured: 32.5
}

TEST_F(CampaignRun, ASteadyDriftOfTheRightCameraIsFollowedByItsRateWithoutALagBeyondItsSigma) {
  // Run 28 of the shipped ranges: a 0.46 m rig looking forward on an urban drive while
  // x_camr turns by 0.19 deg/min about a fixed axis and moves 4.9 mm/min (a thermal drift).
  // With the random walk alone (and the consistency monitor raising it) roll_r lagged the
  // drift beyond its sigma: 83 % of the frames within 3 sigma, 5.2 sigma at worst.
  const CampaignRunSpec spec = shippedRun(28);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "motion"), "urban");
  ASSERT_GT(EstimatorConfig().filter.camr_rotation_drift_rate_sigma, 0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow walk_only =
      runShipped(spec, [](FilterConfig* c) { c->camr_rotation_drift_rate_sigma = 0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(walk_only.ok()) << walk_only.status;
  EXPECT_TRUE(shipped.honest()) << scoreText(shipped);
  // Measured: 0.94 and 3.8 (roll_r) with tempered updates; 0.83 and 5.2 before.
  EXPECT_LT(walk_only.score.share_within_3sigma, 0.95);
  EXPECT_GT(walk_only.score.max_z, 3.5);
}

TEST_F(CampaignRun, AStartFarFromTheTruthIsTemperedNotLockedIn) {
  // Run 11 of the shipped ranges: a fisheye camera on an urban drive, the baseline guessed
  // 42 % short. Untempered, the first updates, linearised there, locked yaw_r 25 sigma off
  // (138 frames beyond 5 sigma from frame 30). Tempered to a threefold shrink of a sigma per
  // update, the start converges over a few frames, each linearised where the last left it.
  // (Until session 16 this was run 72, until session 21 run 92 (321 frames, yaw_r 49 sigma):
  // the time-offset changes, then the fisheye's pixel noise through the lens, made them
  // honest untempered.)
  const CampaignRunSpec spec = shippedRun(11);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "motion"), "urban");
  ASSERT_GT(EstimatorConfig().filter.max_sigma_shrink_per_update, 1.0);
  // Untempered, the test of the pairs against x_camr's epipolar lines (epipolar_knock_*,
  // session 21) rescues it too: the collapsed x_camr's lines are off the next pairs and its
  // rotation is re-opened. x_camr's score test (jump_score_*) alone does not here (123 frames
  // beyond 5 sigma; on run 92 it did). "untempered" is without both.
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow epipolar_only = runShipped(spec, [](FilterConfig* c) {
    c->max_sigma_shrink_per_update = 0;
    c->jump_score_false_alarm = 0.0;
  });
  const CampaignRow untempered = runShipped(spec, [](FilterConfig* c) {
    c->max_sigma_shrink_per_update = 0;
    c->jump_score_false_alarm = 0.0;
    c->epipolar_knock_false_alarm = 0.0;
  });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(epipolar_only.ok()) << epipolar_only.status;
  ASSERT_TRUE(untempered.ok()) << untempered.status;
  EXPECT_TRUE(shipped.honest()) << scoreText(shipped);
  EXPECT_LT(epipolar_only.score.frames_beyond_5sigma, 10) << scoreText(epipolar_only);
  EXPECT_GT(untempered.score.frames_beyond_5sigma, 100);  // measured: 138
  EXPECT_GT(untempered.score.max_z, 20.0);                // measured: 25 (yaw_r)
}

TEST_F(CampaignRun, AJerkyRigWithATimeOffsetIsNotTakenForAKnock) {
  // Run 147 of the shipped ranges: a backward camera carried around a building at walking
  // pace (the recorded udel_gore stretch: twists changing at 200-500 deg/s^2), odometry 24 ms
  // ahead. The first-order time-offset correction alone errs there by ~0.1 deg per step, 5x
  // the motion noise: whole frames of points were gated out, taken for jumps of x_caml, and
  // each re-opening re-converged overconfident (243 frames beyond 5 sigma, xl 6 sigma). Read
  // at the estimated offset (read_odometry_at_offset), with the correction's own error in
  // the motion noise (time_offset_model_noise), it is honest.
  const CampaignRunSpec spec = shippedRun(147);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "trajectory"), "udel_gore_rep103");
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow first_order_only = runShipped(spec, [](FilterConfig* c) {
    c->read_odometry_at_offset = 0;
    c->time_offset_model_noise = 0;
  });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(first_order_only.ok()) << first_order_only.status;
  EXPECT_TRUE(shipped.honest()) << scoreText(shipped);
  EXPECT_GT(first_order_only.score.frames_beyond_5sigma, 100);  // measured: 243
}

TEST_F(CampaignRun, TheOdometryReadAtTheEstimatedOffsetKeepsAWalkingRigHonest) {
  // Run 189: the walking rig again, a side camera, odometry 30 ms ahead. Read at the image
  // stamps, even with the correction's error in the motion noise, roll_l ended 7 sigma off
  // (171 frames beyond 5 sigma; since a re-linearisation restart keeps the learned time
  // offset, pitch_l 6.5 sigma, 62 frames, 61 % within 3 sigma); read at the stamps minus the
  // estimated offset (as VINS reads its IMU), only the estimate's error is left to the
  // first-order correction.
  const CampaignRunSpec spec = shippedRun(189);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "trajectory"), "udel_gore_rep103");
  ASSERT_EQ(EstimatorConfig().filter.read_odometry_at_offset, 1);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow at_stamps =
      runShipped(spec, [](FilterConfig* c) { c->read_odometry_at_offset = 0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(at_stamps.ok()) << at_stamps.status;
  EXPECT_TRUE(shipped.honest()) << scoreText(shipped);
  EXPECT_GT(at_stamps.score.frames_beyond_5sigma, 30) << scoreText(at_stamps);  // measured: 62
  EXPECT_LT(at_stamps.score.share_within_3sigma, 0.8) << scoreText(at_stamps);  // measured: 0.61
}

TEST_F(CampaignRun, AStartThatMovedFarIsRestartedThoughItsInnovationsLookAsExpected) {
  // A start's wide sigmas dominate the expected innovations, so a linearisation far off need
  // not show in them. Run 143 of the shipped ranges (a sideways camera on a recorded EuRoC
  // drone path, the baseline guessed 21 % short, x_camr's angles 4.2 deg off) moved 2.1 start
  // sigmas by frame 30 with its innovations at 0.96 of their expected size, under the 1.05
  // gate, and locked yr 11 sigma off (15 frames beyond 5 sigma) until the next check.
  // Run 7 (a backward camera, the baseline guessed 48 % short) moved 2.3 start sigmas at 0.99
  // and sat beyond 3 sigma in 25 % of its frames. A move beyond 2 start sigmas restarts at the
  // lower gate 0.95 until the first restart after a start (relinearization_far_*); a start
  // within its prior moves about 1 sigma (paper_offroad: 1.0-1.3, not restarted).
  ASSERT_GT(EstimatorConfig().filter.relinearization_far_threshold, 0.0);
  const auto no_far_gate = [](FilterConfig* c) { c->relinearization_far_threshold = 0.0; };
  for (const int run : {143, 7}) {
    const CampaignRunSpec spec = shippedRun(run);
    ASSERT_TRUE(spec.error.empty()) << spec.error;
    const CampaignRow shipped = runShipped(spec);
    const CampaignRow without = runShipped(spec, no_far_gate);
    ASSERT_TRUE(shipped.ok()) << shipped.status;
    ASSERT_TRUE(without.ok()) << without.status;
    EXPECT_TRUE(shipped.honest()) << "run " << run << ": " << scoreText(shipped);
    EXPECT_FALSE(without.honest()) << "run " << run << ": " << scoreText(without);
  }
}

TEST_F(CampaignRun, ACollapsedGuessThatTriangulatesAlmostNoPointIsReopenedOnItsEpipolarLines) {
  // Run 24: a backward camera on an urban drive, the baseline guessed 33 % long and x_camr's
  // angles 4.7 deg off. Almost no pair triangulates within the depth range with that guess:
  // one point in 600 frames. Without the epipolar knock test (and without the step repeated
  // at the corrected motion while slow), that one point's updates take yaw_r's sigma from 2
  // to 0.7 deg while it is 5.1 deg off (435 frames beyond 5 sigma). Shipped, the pairs leave
  // the collapsed x_camr's epipolar lines and its rotation is re-opened (frame 166; 1 frame
  // beyond 5 sigma).
  const CampaignRunSpec spec = shippedRun(24);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "mounting"), "backward");
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow without = runShipped(spec, [](FilterConfig* c) {
    c->epipolar_knock_false_alarm = 0.0;
    c->motion_relinearizations = 0;
  });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(without.ok()) << without.status;
  EXPECT_GT(without.score.frames_beyond_5sigma, 100);                       // measured: 435
  EXPECT_LT(shipped.score.frames_beyond_5sigma, 10) << scoreText(shipped);  // measured: 1
}

TEST_F(CampaignRun, AYawStepOfTheLeftCameraInABlindStretchIsReopenedWhenThePointsReturn) {
  // Run 9 of the shipped ranges at 200 frames (as the image campaign draws them): a backward
  // camera on an off-road drive, x_caml yawed by -2.5 deg at frame 88 inside a 3.7 s blind
  // stretch. No tracked point outlives the stretch, so none gates out and the jump test sees
  // nothing; after it the consistency monitor's x_caml statistic was 13-20 for a bound of
  // 3.8, but the monitor holds x_caml for its first 20 s, and yaw_l stayed 13 -> 8 sigma off
  // to the end. The first updates after the stretch now test x_caml and re-open it (frame
  // 116): what is left are the blind frames and the three updates of the test.
  const CampaignRunSpec spec = shippedRun(9, "", 200);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "event"), "caml_yaw_step");
  ASSERT_GT(EstimatorConfig().filter.unobserved_gap, 0.0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow without = runShipped(spec, [](FilterConfig* c) { c->unobserved_gap = 0.0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(without.ok()) << without.status;
  EXPECT_GE(shipped.score.first_frame_beyond_5sigma, 88);                    // not before the step
  EXPECT_LT(shipped.score.frames_beyond_5sigma, 40) << scoreText(shipped);   // measured: 28
  EXPECT_GT(shipped.score.share_within_3sigma, 0.8) << scoreText(shipped);   // measured: 0.84
  EXPECT_GT(without.score.frames_beyond_5sigma, 100) << scoreText(without);  // measured: 112
  EXPECT_LT(without.score.share_within_3sigma, 0.5) << scoreText(without);   // measured: 0.34

  // The same drive without the step: the test after the blind stretch finds nothing, and the
  // run is the same as with the test off.
  const CampaignRunSpec still = shippedRun(9, "kind: {none: 1}", 200);
  ASSERT_TRUE(still.error.empty()) << still.error;
  ASSERT_EQ(settingOf(still.settings, "event"), "none");
  // The blind stretch is still drawn, long enough for the check to follow it.
  ASSERT_GT(std::stod(settingOf(still.settings, "blind_s")),
            EstimatorConfig().filter.unobserved_gap);
  const CampaignRow still_shipped = runShipped(still);
  const CampaignRow still_without =
      runShipped(still, [](FilterConfig* c) { c->unobserved_gap = 0.0; });
  ASSERT_TRUE(still_shipped.ok()) << still_shipped.status;
  ASSERT_TRUE(still_without.ok()) << still_without.status;
  EXPECT_EQ(still_shipped.score.frames_beyond_5sigma, 0) << scoreText(still_shipped);
  EXPECT_EQ(still_shipped.score.share_within_3sigma, still_without.score.share_within_3sigma);
  EXPECT_EQ(still_shipped.score.rmse, still_without.score.rmse);
}

}  // namespace
}  // namespace osc

namespace osc {
namespace {

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

TEST_F(CampaignRun, InverseDepthPointsKeepAnEasyRunHonestThatPositionsMadeConfidentlyWrong) {
  // Run 25 of the easy ranges docs/results/campaign/B_clean.yaml (seed 26): a 0.56 m rig
  // looking forward on the recorded EuRoC MAV trajectory, start errors within the prior.
  // Stored as positions, the first points' depths were +-100 % uncertain and non-Gaussian and
  // yaw_r locked in far off within the first frames (docs/RESULTS.md "Inverse-depth points").
  const std::string dir = std::string(OSC_SOURCE_DIR) + "/docs/results/campaign";
  CampaignInputs inputs;
  inputs.ranges_text = readTextFile(dir + "/B_clean.yaml");
  inputs.ranges = parseCampaignRanges(inputs.ranges_text, "B_clean.yaml", dir);
  inputs.frames = 600;  // as the campaign drew it
  const CampaignRunSpec spec = drawCampaignRun(inputs, 25);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  EstimatorConfig config;
  ASSERT_EQ(config.filter.inverse_depth_points, 1);  // the shipped default
  const CampaignRow inverse_depth = runCampaignRun(spec, config, false);
  config.filter.inverse_depth_points = 0;
  const CampaignRow position = runCampaignRun(spec, config, false);
  ASSERT_TRUE(inverse_depth.ok()) << inverse_depth.status;
  ASSERT_TRUE(position.ok()) << position.status;
  EXPECT_TRUE(inverse_depth.honest()) << scoreText(inverse_depth);
  // The old way fails here, so the test can tell.
  EXPECT_LT(position.score.share_within_3sigma, 0.5);  // measured: 0 %, yaw_r 48 sigma off
  EXPECT_GT(position.score.max_z, 10.0);
}

}  // namespace
}  // namespace osc
