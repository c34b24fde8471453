// Campaign runs of the shipped ranges (config/campaign.yaml) replayed with the shipped
// configuration, about the start and the odometry: the CONVERGED state is reached and honest,
// a stall is warned once, starts far off are tempered, restarted or re-opened, inverse-depth
// points keep an easy run honest, and the odometry's velocity error, noise at a standstill and
// time offset are not taken for the calibration. The CampaignRun fixture
// (campaign_test_support.h) skips them without the recorded trajectories of ../shared/data.
#include <gtest/gtest.h>

#include "campaign_test_support.h"

#include <cmath>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/campaign.h"

namespace osc {
namespace {

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
    // The odometry noise matcher would learn the noise back (53 of 1449 CONVERGED frames
    // beyond 3 sigma with it): off, to see an overconfident filter.
    const CampaignRow overconfident = runShipped(spec, [](FilterConfig* c) {
      c->motion_translation_noise /= 5.0;
      c->motion_rotation_noise /= 5.0;
      c->odometry_noise_window = 0.0;
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
  // beyond 5 sigma; on run 92 it did). "untempered" is without both. Measured without the
  // odometry noise matcher, which is off in the variants (with it, epipolar-only: 17 frames).
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow epipolar_only = runShipped(spec, [](FilterConfig* c) {
    c->max_sigma_shrink_per_update = 0;
    c->jump_score_false_alarm = 0.0;
    c->odometry_noise_window = 0.0;
  });
  const CampaignRow untempered = runShipped(spec, [](FilterConfig* c) {
    c->max_sigma_shrink_per_update = 0;
    c->jump_score_false_alarm = 0.0;
    c->epipolar_knock_false_alarm = 0.0;
    c->odometry_noise_window = 0.0;
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
  // the motion noise (time_offset_model_noise), it is honest. The odometry noise matcher
  // learns the first-order correction's error as odometry noise and keeps the run without
  // both honest too (0 frames beyond 5 sigma): off in that variant, to see the mechanism.
  const CampaignRunSpec spec = shippedRun(147);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "trajectory"), "udel_gore_rep103");
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow first_order_only = runShipped(spec, [](FilterConfig* c) {
    c->read_odometry_at_offset = 0;
    c->time_offset_model_noise = 0;
    c->odometry_noise_window = 0.0;
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
  // first-order correction. (With the odometry noise matcher the run read at the stamps has 0
  // frames beyond 5 sigma but 0.69 within 3 sigma: off in that variant.)
  const CampaignRunSpec spec = shippedRun(189);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "trajectory"), "udel_gore_rep103");
  ASSERT_EQ(EstimatorConfig().filter.read_odometry_at_offset, 1);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow at_stamps = runShipped(spec, [](FilterConfig* c) {
    c->read_odometry_at_offset = 0;
    c->odometry_noise_window = 0.0;
  });
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
