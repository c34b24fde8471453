// Tests of the campaign tool's ranges (issue 13): the ranges file's errors, the recorded
// trajectories it needs, the shipped file's defaults (campaign_ranges.h), and the draw of each
// run's values from them (campaign_draw.h).
#include <gtest/gtest.h>

#include <stdlib.h>
#include "campaign_test_support.h"
#include "temp_dir.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/campaign_draw.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {
namespace {

std::string parseError(const std::string& yaml) {
  try {
    parseCampaignRanges(yaml, "test.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
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

TEST(CampaignDraw, TheWhiteNoiseFactorScalesTheOdometryNoiseAndIsDrawnLast) {
  // A GPS/INS noisier than the filter assumes (issue "Real drives in"): the simulated white
  // motion noise times a drawn factor. Drawn after everything else, so that the shipped [1, 1]
  // leaves every run as it was drawn before the key existed.
  const CampaignRanges shipped = parseCampaignRanges(kNoRecorded, "t");
  ASSERT_EQ(shipped.white_noise_factor.min, 1.0);
  ASSERT_EQ(shipped.white_noise_factor.max, 1.0);
  const CampaignRanges noisier = parseCampaignRanges(
      "motion: {kind: {offroad: 1, urban: 1}}\nodometry: {white_noise_factor: [1, 4]}", "t");
  const MeasurementScenario defaults;
  double largest = 1.0;
  for (int run = 0; run < 50; ++run) {
    const CampaignRunSpec a = drawCampaignRun(shipped, run, 7 + run, 600, true);
    const CampaignRunSpec b = drawCampaignRun(noisier, run, 7 + run, 600, true);
    EXPECT_EQ(a.scenario.motion_translation_noise, defaults.motion_translation_noise);
    EXPECT_EQ(settingOf(a.settings, "odo_white_noise_factor"), "1");
    const double factor = std::stod(settingOf(b.settings, "odo_white_noise_factor"));
    ASSERT_GE(factor, 1.0);
    ASSERT_LE(factor, 4.0);
    largest = std::max(largest, factor);
    EXPECT_NEAR(b.scenario.motion_translation_noise, factor * defaults.motion_translation_noise,
                1e-5 * b.scenario.motion_translation_noise);  // the setting has 6 digits
    EXPECT_NEAR(b.scenario.motion_rotation_noise, factor * defaults.motion_rotation_noise,
                1e-5 * b.scenario.motion_rotation_noise);
    for (size_t i = 0; i < a.settings.size(); ++i) {
      if (a.settings[i].first != "odo_white_noise_factor") {
        EXPECT_EQ(a.settings[i], b.settings[i]) << run;
      }
    }
    EXPECT_EQ(a.scenario.initial_error, b.scenario.initial_error);
    EXPECT_EQ(a.image_options.render.noise_sigma, b.image_options.render.noise_sigma);
  }
  EXPECT_GT(largest, 3.0);
  EXPECT_NE(parseError(std::string(kNoRecorded) + "odometry: {white_noise_factor: 0.5}")
                .find("odometry.white_noise_factor"),
            std::string::npos);
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

}  // namespace
}  // namespace osc
