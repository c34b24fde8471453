/// @file test_image_pipeline.cpp
/// @brief A short end-to-end run at image level: rendered stereo pairs of the paper's
/// off-road drive through the CalibrationPipeline (front end + filter) from the seed's
/// start errors; the calibration must converge and stay consistent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "online_stereo_calibration/core/sim/image_scenario_runner.h"

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
  // Front end over the whole run: stereo matches at the 99 % (measured 99.26 %);
  // tracks still on their birth point NOT YET AT TARGET (measured 95.85 %; outlines against
  // the sky, see docs/RESULTS.md).
  EXPECT_GE(matches_correct, 0.99 * matches);
  EXPECT_GE(tracks_correct, 0.93 * tracks);
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
  // Back from 10 deg to the pre-step level (the image-level x_caml bias of ~0.6 deg, see
  // docs/RESULTS.md; NOT YET the 0.3 deg).
  EXPECT_LT(std::abs(yaw_error), 1.0 * kDeg);
  EXPECT_GE(last.filter.tracked_points, 30);
}

}  // namespace
}  // namespace osc
