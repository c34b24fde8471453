/// @file test_image_pipeline.cpp
/// @brief A short end-to-end run at image level: rendered stereo pairs of the paper's
/// off-road drive through the CalibrationPipeline (front end + filter) from the seed's
/// start errors; the calibration must converge and stay consistent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/tools/campaign_score.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(ImagePipeline, ConvergesOnAShortRenderedDrive) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.frames = 150;
  scenario.step_frame = -1;
  int matches = 0, matches_correct = 0, tracks = 0, tracks_correct = 0;
  double render_ms = 0.0, pipeline_ms = 0.0;
  const std::vector<ImageFrameResult> results = runImageScenario(
      scenario, FilterConfig(), FrontEndConfig(), ImageScenarioOptions(),
      [&](const ImageFrameResult& r, const CalibrationPipeline&) {
        matches += r.matches_checked;
        matches_correct += r.matches_correct;
        tracks += r.tracks_checked;
        tracks_correct += r.tracks_correct;
        render_ms += r.render_ms;
        pipeline_ms += r.filter.time_ms;
        if (r.filter.frame % 25 == 0 || r.filter.frame == scenario.frames - 1) {
          const Vector12d& e = r.filter.tangent_error;
          std::printf(
              "  frame %3d: points %3d, |dt_l| %.3f m, |dth_l| %.3f deg, |dt_r| %.4f m, "
              "|dth_r| %.4f deg, NEES %.1f\n",
              r.filter.frame, r.filter.tracked_points, e.segment<3>(0).norm(),
              e.segment<3>(3).norm() / kDeg, e.segment<3>(6).norm(), e.segment<3>(9).norm() / kDeg,
              r.filter.nees);
        }
      });
  std::printf(
      "  matches %.2f %% correct, tracks %.2f %% correct; render %.0f ms, pipeline "
      "%.1f ms per frame\n",
      100.0 * matches_correct / std::max(1, matches), 100.0 * tracks_correct / std::max(1, tracks),
      render_ms / results.size(), pipeline_ms / results.size());
  ASSERT_EQ(results.size(), 150u);
  const ImageFrameResult& last = results.back();
  const Vector12d& e = last.filter.tangent_error;
  EXPECT_LT(e.segment<3>(6).norm(), 0.005);        // x_camr translation, a few mm
  EXPECT_LT(e.segment<3>(9).norm(), 0.05 * kDeg);  // x_camr rotation
  EXPECT_LT(e.segment<3>(3).norm(), 1.0 * kDeg);   // x_caml rotation
  EXPECT_LT(last.filter.nees, 3.0 * 12.0);         // not overconfident
  EXPECT_GE(last.filter.tracked_points, 50);
  // Front end over the whole run at the 99 % (measured: stereo matches 99.90 %,
  // tracks on their birth point 99.40 %).
  EXPECT_GE(matches_correct, 0.99 * matches);
  EXPECT_GE(tracks_correct, 0.99 * tracks);
}

// A knocked camera at image level: the 10 deg yaw step of x_caml moves every point ~90 px
// from its prediction, far outside the track windows. The lost tracks are searched over the
// whole image (reacquire_below_fraction), reach the filter as outliers, and it detects the
// change at the step frame and pulls yaw_l back.
TEST(ImagePipeline, DetectsAndFollowsASuddenYawStepOfTheCamera) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.frames = 130;
  scenario.step_frame = 100;
  // A camera calibrated before (no start error, small start sigmas): the step meets a
  // converged filter, as at frame 774 of the paper's drive, without 774 frames to render.
  scenario.initial_error.setZero();
  FilterConfig calibrated;
  calibrated.initial_caml_translation_sigma = 0.02;
  calibrated.initial_caml_rotation_sigma = 0.2 * kDeg;
  const std::vector<ImageFrameResult> results =
      runImageScenario(scenario, calibrated, FrontEndConfig(), ImageScenarioOptions(),
                       [&](const ImageFrameResult&, const CalibrationPipeline&) {});
  ASSERT_EQ(results.size(), 130u);
  int jumps = 0, first_jump = -1;
  for (const ImageFrameResult& r : results) {
    if (!r.filter.jump_detected) continue;
    if (first_jump < 0) first_jump = r.filter.frame;
    ++jumps;
  }
  EXPECT_EQ(first_jump, 100);
  EXPECT_EQ(jumps, 1);
  const ImageFrameResult& last = results.back();
  const double yaw_error =
      std::remainder(last.filter.parameters(5) - last.filter.truth(5), 2 * M_PI);
  std::printf("  jump at frame %d; yaw_l error at frame %d: %.3f deg\n", first_jump,
              last.filter.frame, yaw_error / kDeg);
  // Back from 10 deg to within 0.3 deg (measured -0.05 deg 29 frames after the step).
  EXPECT_LT(std::abs(yaw_error), 0.3 * kDeg);
  EXPECT_GE(last.filter.tracked_points, 30);
}

/// The filter's side of a list of image-level results, for scoreCampaignRun.
std::vector<ScenarioFrameResult> filterResults(const std::vector<ImageFrameResult>& results) {
  std::vector<ScenarioFrameResult> filter;
  for (const ImageFrameResult& r : results) filter.push_back(r.filter);
  return filter;
}

/// A calibrated start (no start error, small x_caml sigmas) of the paper drive whose x_camr
/// parameter `param` (6-11) steps by `step` (m or rad) at frame 100; images as the bags'.
std::vector<ImageFrameResult> rightCameraStep(
    int param, double step, int frames,
    const std::function<void(const ImageFrameResult&, const CalibrationPipeline&)>& on_frame) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.frames = frames;
  scenario.step_frame = 100;
  scenario.initial_error.setZero();
  scenario.step.setZero();
  scenario.step(param) = step;
  FilterConfig calibrated;
  calibrated.initial_caml_translation_sigma = 0.02;
  calibrated.initial_caml_rotation_sigma = 0.2 * kDeg;
  ImageScenarioOptions as_bags;
  as_bags.render.noise_sigma = 1.0;
  as_bags.render.blur_sigma = 0.5;
  return runImageScenario(scenario, calibrated, FrontEndConfig(), as_bags, on_frame);
}

/// A knock of `step` rad on x_camr parameter `param` at frame 100 of a 130-frame calibrated
/// drive: at least 50 points tracked from frame 105 on, at frame 129 the parameter within
/// `tolerance` and 3 sigma, and from frame 30 on all 12 within 3 sigma in >= 95 % of the
/// frames, at most `max_frames_beyond_5sigma` beyond 5 sigma (the knock's). Returns frame 100's
/// result.
ImageFrameResult expectReconvergedAfterKnock(int param, double step, double tolerance,
                                             int max_frames_beyond_5sigma = 0) {
  int fewest_from_105 = 1000;
  const std::vector<ImageFrameResult> results =
      rightCameraStep(param, step, 130, [&](const ImageFrameResult& r, const CalibrationPipeline&) {
        if (r.filter.frame >= 105) {
          fewest_from_105 = std::min(fewest_from_105, r.filter.tracked_points);
        }
      });
  EXPECT_EQ(results.size(), 130u);
  if (results.size() != 130u) return ImageFrameResult();
  const ImageFrameResult& last = results.back();
  const double error = last.filter.parameters(param) - last.filter.truth(param);
  std::printf("  fewest points from frame 105 %d; error at frame %d: %.4f deg (sigma %.4f)\n",
              fewest_from_105, last.filter.frame, error / kDeg, last.filter.sigmas(param) / kDeg);
  EXPECT_GE(fewest_from_105, 50);
  EXPECT_LT(std::abs(error), tolerance);
  // Issue 14's bar for all 12 parameters from frame 30 on; a knock the pipeline re-opens in
  // its own pair is honest in every frame, one within the band is seen a pair later.
  const CampaignScore score = scoreCampaignRun(filterResults(results));
  std::printf(
      "  all 12 within 3 sigma in %.3f of the frames from 30, %d beyond 5 sigma (first: "
      "frame %d), max z %.2f (%s)\n",
      score.share_within_3sigma, score.frames_beyond_5sigma, score.first_frame_beyond_5sigma,
      score.max_z, score.max_z_parameter.c_str());
  EXPECT_GE(score.share_within_3sigma, 0.95);
  EXPECT_LE(score.frames_beyond_5sigma, max_frames_beyond_5sigma);
  if (score.frames_beyond_5sigma > 0) {
    EXPECT_EQ(score.first_frame_beyond_5sigma, 100);
  }
  EXPECT_LT(std::abs(error), 3.0 * last.filter.sigmas(param));
  return results[100];
}

// A small knock of the right camera, within the epipolar band (0.1 deg of pitch_r: every
// right pixel ~1 px off its line). The refined pairs, measured against the frame's common
// distance from the lines (EpipolarTrend), still reach the filter, and that distance, ~35 of
// x_camr's sigmas, re-opens its rotation (CalibrationPipeline). Before: all pairs refused
// (76 points -> 1) with the narrow band alone; with the trend but no re-opening, pitch_r
// followed only through x_camr's drift noise, 0.027 deg off 30 frames later, 1 sigma 0.003 deg.
TEST(ImagePipeline, ReconvergesAfterASmallKnockOfTheRightCamera) {
  // Measured: within 0.001 deg three frames after the step (1 sigma 0.003 deg at the end); the
  // knock's own pair 30 sigma off (pitch_r), the only frame beyond 5 sigma; 0.99 within 3.
  expectReconvergedAfterKnock(10, 0.1 * kDeg, 0.01 * kDeg, 1);
}

// A knock beyond the band of a converged x_camr (0.5 deg of pitch_r: ~5 px off the lines): no
// stereo pair is found at all, so the filter's own jump test never sees one. The pair's
// whole-image fit contradicts x_camr, the pipeline re-opens its rotation in that same pair,
// the band widens to its start-up width and the filter re-converges (before: 0 points from
// the step on, pitch_r stuck 0.5 deg off; until session 14 the re-opening waited for a
// second pair, and the knock's own pair was reported 90 sigma off).
TEST(ImagePipeline, ReopensTheRightCameraAfterAKnockBeyondTheBand) {
  // Measured: within 0.02 deg one frame after the step (1 sigma 0.003 deg at the end).
  const ImageFrameResult knock = expectReconvergedAfterKnock(10, 0.5 * kDeg, 0.02 * kDeg);
  ASSERT_EQ(knock.filter.frame, 100);
  // Measured: 0.50 deg off at 1 sigma 1.49 deg (re-opened to 3 times the fit's angle).
  constexpr int kPitchR = 10;
  EXPECT_LT(std::abs(knock.filter.parameters(kPitchR) - knock.filter.truth(kPitchR)),
            3.0 * knock.filter.sigmas(kPitchR));
}

// A knock of 1 deg of roll_r (about the optical axis: pixels near the image centre stay near
// their lines). The band of the converged x_camr still holds ~270 chance matches in the
// knock's pair, but no track is found again: counting the tracked pairs (not the matches) runs
// the whole-image fit in that pair, and its contradiction re-opens x_camr at once. Before
// (session 13), a pair counted as "lost" only without matches as well, and the refined pairs'
// distance from their lines re-opened x_camr one pair later: the knock's pair was reported
// 1 deg off at 1 sigma 0.006 deg. Image run 1 of session 13's campaign was this case with too
// few refined pairs for that distance test: 0.77 deg off at 1 sigma 0.014 deg for 130 pairs.
TEST(ImagePipeline, ReopensTheRightCameraInTheKnocksPairThoughChanceMatchesRemainInTheBand) {
  // Measured: the knock's pair 1.0 deg off at 1 sigma 3.0 deg (3 times the fit's angle); the
  // next pair re-seeded 0.0003 deg off; at frame 129 0.005 deg off (1 sigma 0.007 deg).
  const ImageFrameResult knock = expectReconvergedAfterKnock(9, 1.0 * kDeg, 0.02 * kDeg);
  ASSERT_EQ(knock.filter.frame, 100);
  EXPECT_GT(knock.front_end.stereo_matches, 50);
  EXPECT_LE(knock.front_end.tracked, 5);
  constexpr int kRollR = 9;
  EXPECT_LT(std::abs(knock.filter.parameters(kRollR) - knock.filter.truth(kRollR)),
            3.0 * knock.filter.sigmas(kRollR))
      << "1 sigma " << knock.filter.sigmas(kRollR) / kDeg << " deg";
}

/// Issue 14's texture-poor stretch: the seed's off-road drive from its start errors, 200
/// frames, blind in frames 80-149 (7 s at 10 Hz), their images rendered at
/// `blind_exposure_gain`. Expects no re-opening of x_camr, x_camr within 3 sigma in every
/// frame from 30 on, all 12 within 3 sigma in >= 95 % of those frames and none beyond 5
/// sigma, and tracking back after the stretch. Returns the pairs processed in the stretch and
/// the most stereo pairs the front end found in one of them.
std::pair<int, int> expectHonestThroughABlindStretch(double blind_exposure_gain) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.frames = 200;
  scenario.step_frame = -1;
  constexpr int kFirstBlind = 80, kLastBlind = 149;
  scenario.blind_frames = {{kFirstBlind, kLastBlind}};
  ImageScenarioOptions options;
  options.blind_exposure_gain = blind_exposure_gain;
  int reopened = 0, processed_in_stretch = 0, pairs_in_stretch = 0, right_beyond_3sigma = 0;
  double right_worst_z = 0.0;
  const std::vector<ImageFrameResult> results = runImageScenario(
      scenario, FilterConfig(), FrontEndConfig(), options,
      [&](const ImageFrameResult& r, const CalibrationPipeline&) {
        const int frame = r.filter.frame;
        reopened += r.right_camera_reopened;
        if (scenario.isBlindFrame(frame) && r.processed) {
          ++processed_in_stretch;
          pairs_in_stretch = std::max(pairs_in_stretch, r.front_end.stereo_matches);
        }
        if (frame < kCampaignFirstScoredFrame) return;
        const double z = r.filter.tangent_error.tail<6>()
                             .cwiseQuotient(r.filter.tangent_sigmas.tail<6>())
                             .cwiseAbs()
                             .maxCoeff();
        right_beyond_3sigma += z > 3.0;
        right_worst_z = std::max(right_worst_z, z);
        if (frame % 20 == 0 || frame == kLastBlind + 1) {
          std::printf("  frame %3d: %s, points %3d, x_camr z %.2f, rotation sigma %.4f deg\n",
                      frame, r.processed ? "processed" : "refused", r.filter.tracked_points, z,
                      r.filter.tangent_sigmas.tail<3>().maxCoeff() / kDeg);
        }
      });
  EXPECT_EQ(results.size(), 200u);
  if (results.size() != 200u) return {0, 0};
  const CampaignScore score = scoreCampaignRun(filterResults(results));
  std::printf(
      "  %d pairs of the stretch processed (at most %d stereo matches), re-openings %d; "
      "all 12 within 3 sigma in %.3f of the frames from 30, %d beyond 5 sigma, max z "
      "%.2f (%s); x_camr worst z %.2f\n",
      processed_in_stretch, pairs_in_stretch, reopened, score.share_within_3sigma,
      score.frames_beyond_5sigma, score.max_z, score.max_z_parameter.c_str(), right_worst_z);
  EXPECT_EQ(reopened, 0);
  EXPECT_EQ(right_beyond_3sigma, 0) << "worst " << right_worst_z;
  EXPECT_GE(score.share_within_3sigma, 0.95);
  EXPECT_EQ(score.frames_beyond_5sigma, 0)
      << "max z " << score.max_z << " (" << score.max_z_parameter << ")";
  EXPECT_GE(results.back().filter.tracked_points, 50);
  return {processed_in_stretch, pairs_in_stretch};
}

// Darkness or a uniform wall: the pairs have no contrast and are refused; the next pair
// brings the motion of the whole 7 s.
TEST(ImagePipeline, ADarkStretchMidDriveReopensNothingAndStaysHonest) {
  const std::pair<int, int> stretch = expectHonestThroughABlindStretch(kBlindFrameExposureGain);
  EXPECT_EQ(stretch.first, 0) << "the dark pairs were not refused";
}

// A dim, texture-poor view: the pairs are processed but hold (almost) no stereo pair. The
// filter predicts without updates; the pipeline's whole-image fit finds nothing to contradict
// x_camr, so the mere absence of matches re-opens nothing (issue 14: "never the mere absence
// of matches").
TEST(ImagePipeline, ATexturePoorStretchMidDriveReopensNothingAndStaysHonest) {
  const std::pair<int, int> stretch = expectHonestThroughABlindStretch(0.1);
  EXPECT_GE(stretch.first, 60) << "the dim pairs were refused";
  EXPECT_LE(stretch.second, 5) << "the dim pairs were not texture-poor";
}

/// Diagnostics: rightCameraStep with D_PARAM (6-11, default 10 = pitch_r), D_STEP (deg or m,
/// default 0.1) and DIAG_FRAMES (default 160); prints per frame from 95 on the tracked points,
/// the jump flag and that parameter's error and sigma.
TEST(ImagePipelineDiag, DISABLED_StepOfTheRightCamera) {
  const int param = std::getenv("D_PARAM") ? std::atoi(std::getenv("D_PARAM")) : 10;
  const double unit = param % 6 >= 3 ? kDeg : 1.0;
  const double step = (std::getenv("D_STEP") ? std::atof(std::getenv("D_STEP")) : 0.1) * unit;
  const int frames = std::getenv("DIAG_FRAMES") ? std::atoi(std::getenv("DIAG_FRAMES")) : 160;
  rightCameraStep(param, step, frames, [&](const ImageFrameResult& r, const CalibrationPipeline&) {
    if (r.filter.frame < 95) return;
    std::printf("  frame %d points %d jump %d re-seeded %d error %.4f sigma %.4f\n", r.filter.frame,
                r.filter.tracked_points, r.filter.jump_detected, r.right_rotation_from_stereo_fit,
                (r.filter.parameters(param) - r.filter.truth(param)) / unit,
                r.filter.sigmas(param) / unit);
  });
}

/// Diagnostics, not a check (run with --gtest_also_run_disabled_tests): a whole drive at image
/// level straight from the simulator (its motion, no bag and no odometry file in between),
/// per parameter the RMSE, the last 1 sigma and the frames within 2 sigma over a window; to
/// tell the front end's part in an overconfidence seen with `evaluate` on a bag from the
/// odometry's. Environment: D_SCENARIO (paper_offroad, urban_planar, drift), DIAG_FRAMES
/// (default 1151), D_WINDOW_FIRST (default 1000), D_SCENE_SEED, D_UNDULATION, D_DENSITY,
/// D_NOISE, D_BLUR.
TEST(ImagePipelineDiag, DISABLED_ConsistencyOverAWindow) {
  const std::string name = std::getenv("D_SCENARIO") ? std::getenv("D_SCENARIO") : "";
  MeasurementScenario scenario = name == "urban_planar" ? urbanPlanarScenario()
                                 : name == "drift"      ? driftScenario()
                                                        : paperOffroadScenario();
  scenario.frames = std::getenv("DIAG_FRAMES") ? std::atoi(std::getenv("DIAG_FRAMES")) : 1151;
  const int first = std::getenv("D_WINDOW_FIRST") ? std::atoi(std::getenv("D_WINDOW_FIRST")) : 1000;
  Vector12d squared = Vector12d::Zero(), within = Vector12d::Zero(), sigma = Vector12d::Zero();
  int used = 0;
  ImageScenarioOptions options;  // the scene as a scenario file's `rendering:` may set it
  if (std::getenv("D_SCENE_SEED")) options.scene.seed = std::atoi(std::getenv("D_SCENE_SEED"));
  if (std::getenv("D_UNDULATION"))
    options.scene.ground_undulation = std::atof(std::getenv("D_UNDULATION"));
  if (std::getenv("D_DENSITY"))
    options.scene.structure_density = std::atof(std::getenv("D_DENSITY"));
  // The images as `simulate` renders them by default: 1 grey level of noise, 0.5 px blur.
  if (std::getenv("D_NOISE")) options.render.noise_sigma = std::atof(std::getenv("D_NOISE"));
  if (std::getenv("D_BLUR")) options.render.blur_sigma = std::atof(std::getenv("D_BLUR"));
  runImageScenario(scenario, FilterConfig(), FrontEndConfig(), options,
                   [&](const ImageFrameResult& r, const CalibrationPipeline&) {
                     if (r.filter.frame % 100 == 0) std::printf("  frame %d\n", r.filter.frame);
                     if (r.filter.frame < first) return;
                     ++used;
                     for (int k = 0; k < 12; ++k) {
                       double e = r.filter.parameters(k) - r.filter.truth(k);
                       if (k % 6 >= 3) e = std::remainder(e, 2 * M_PI);
                       squared(k) += e * e;
                       within(k) += std::abs(e) <= 2.0 * r.filter.sigmas(k) ? 1.0 : 0.0;
                       sigma(k) = r.filter.sigmas(k);
                     }
                   });
  const char* names[12] = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                           "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};
  for (int k = 0; k < 12; ++k) {
    const double unit = k % 6 >= 3 ? kDeg : 1.0;
    std::printf("%-8s RMSE %.5f  1sigma %.5f  in 2sig %.1f %%  (%s)\n", names[k],
                std::sqrt(squared(k) / std::max(1, used)) / unit, sigma(k) / unit,
                100.0 * within(k) / std::max(1, used), unit == 1.0 ? "m" : "deg");
  }
}

}  // namespace
}  // namespace osc
