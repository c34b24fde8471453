// Campaign runs of the shipped ranges (config/campaign.yaml) replayed with the shipped
// configuration, in which the calibration changes: the left camera's yaw steps, the right
// camera's knocks (in and out of blind stretches, too small to gate points out) and its
// steady drift. The CampaignRun fixture (campaign_test_support.h) skips them without the
// recorded trajectories of ../shared/data.
#include <gtest/gtest.h>

#include "campaign_test_support.h"

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/campaign.h"

namespace osc {
namespace {

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

TEST_F(CampaignRun, AYawStepOfTheLeftCameraInABlindStretchIsReopenedWhenThePointsReturn) {
  // Run 9 of the shipped ranges at 200 frames (as the image campaign draws them): a backward
  // camera on an off-road drive, x_caml yawed by -2.5 deg at frame 88 inside a 3.7 s blind
  // stretch. No tracked point outlives the stretch, so none gates out and the jump test sees
  // nothing; after it the consistency monitor's x_caml statistic was 13-20 for a bound of
  // 3.8, but the random walk it raises does not follow a step, and yaw_l stayed 13 -> 8 sigma
  // off to the end. The first updates after the stretch now test x_caml and re-open it (frame
  // 116): what is left are the blind frames and the three updates of the test.
  const CampaignRunSpec spec = shippedRun(9, "", 200);
  ASSERT_TRUE(spec.error.empty()) << spec.error;
  ASSERT_EQ(settingOf(spec.settings, "event"), "caml_yaw_step");
  ASSERT_GT(EstimatorConfig().filter.unobserved_gap, 0.0);
  const CampaignRow shipped = runShipped(spec);
  const CampaignRow without = runShipped(spec, [](FilterConfig* c) { c->unobserved_gap = 0.0; });
  ASSERT_TRUE(shipped.ok()) << shipped.status;
  ASSERT_TRUE(without.ok()) << without.status;
  std::cout << "with the gap check: " << scoreText(shipped) << "\nwithout: " << scoreText(without)
            << "\n";
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
