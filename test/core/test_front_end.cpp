/// @file test_front_end.cpp
/// @brief The image front end against the renderer's exact ground truth: its configuration,
/// stereo-match and tracking precision on rendered drives (noise, blur, flicker, blind frames,
/// a recorded trajectory, distorted lenses, a wrong calibration), and bad images refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "front_end_test_support.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {
namespace {

DriveFigures drive(const MeasurementScenario& scenario, const FilterConfig& filter,
                   const FrontEndConfig& front_end, const ImageScenarioOptions& options = {}) {
  DriveFigures f;
  const std::vector<ImageFrameResult> results =
      runImageScenario(scenario, filter, front_end, options);
  for (const ImageFrameResult& r : results) {
    f.matches += r.matches_checked;
    f.matches_correct += r.matches_correct;
    f.tracks += r.tracks_checked;
    f.tracks_correct += r.tracks_correct;
    f.tracks_reported += r.tracks_reported;
    f.tracks_stereo_correct += r.tracks_stereo_correct;
    f.new_points += r.new_checked;
    f.new_correct += r.new_correct;
    f.matches_at_pixel += r.matches_correct_at_pixel;
    f.new_at_pixel += r.new_correct_at_pixel;
    f.tracks_stereo_at_pixel += r.tracks_stereo_correct_at_pixel;
    f.tracks_at_birth_pixel += r.tracks_correct_at_birth_pixel;
    f.processed += r.processed;
  }
  f.final_points = results.back().filter.tracked_points;
  std::printf(
      "  matches %d (%.2f %% correct), new %d (%.2f %%), tracks %d (stereo %.2f %% "
      "correct, %.2f %% on their birth point), points at the end %d\n",
      f.matches, 100.0 * f.matches_correct / std::max(1, f.matches), f.new_points,
      100.0 * f.new_correct / std::max(1, f.new_points), f.tracks_reported,
      100.0 * f.tracks_stereo_correct / std::max(1, f.tracks_reported),
      100.0 * f.tracks_correct / std::max(1, f.tracks), f.final_points);
  std::printf(
      "  at the exact left pixel: matches %.2f %%, new %.2f %%, tracks %.2f %% (%.2f %% on the "
      "point of their birth pixel)\n",
      100.0 * f.matches_at_pixel / std::max(1, f.matches),
      100.0 * f.new_at_pixel / std::max(1, f.new_points),
      100.0 * f.tracks_stereo_at_pixel / std::max(1, f.tracks_reported),
      100.0 * f.tracks_at_birth_pixel / std::max(1, f.tracks));
  return f;
}

/// The targets on a rendered drive: >= 99 % correct stereo matches, new points and
/// tracks (stereo pair correct in the frame, and still on a scene point of their birth match),
/// and >= 50 points alive. "Correct" is ImageFrameResult's: one scene point within 1.5 px of
/// both pixels. The stricter figures at the exact left pixel are printed, not asserted: they
/// also fail correct matches of outlines whose keypoint lies a pixel off the object.
/// Where a case is below the targets, its bars are the measured figures minus a margin.
struct DriveBars {
  double matches_correct = 0.99;
  double new_correct = 0.99;
  int tracks_per_frame = 25;
  double tracks_stereo_correct = 0.99;
  double tracks_correct = 0.99;  ///< on their birth point
};

void expectGoodDrive(const DriveFigures& f, int frames, const DriveBars& bars = {}) {
  EXPECT_EQ(f.processed, frames);
  EXPECT_GE(f.matches, 100 * frames);
  EXPECT_GE(f.matches_correct, bars.matches_correct * f.matches);
  EXPECT_GE(f.new_correct, bars.new_correct * f.new_points);
  EXPECT_GE(f.tracks, bars.tracks_per_frame * frames);
  EXPECT_GE(f.tracks_stereo_correct, bars.tracks_stereo_correct * f.tracks_reported);
  EXPECT_GE(f.tracks_correct, bars.tracks_correct * f.tracks);
  EXPECT_GE(f.final_points, 50);
}

TEST(FrontEndConfig, DefaultsAreValidAndProblemsAreNamed) {
  EXPECT_TRUE(FrontEndConfig().validate().empty());
  FrontEndConfig c;
  c.detector = "SURF";
  c.ratio = 1.5;
  c.max_track_window = 1.0;
  const std::vector<std::string> problems = c.validate();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("detector"), std::string::npos);
  EXPECT_NE(problems[1].find("ratio"), std::string::npos);
  EXPECT_NE(problems[2].find("max_track_window"), std::string::npos);
  const CameraIntrinsics k = paperOffroadScenario().left;
  EXPECT_THROW(CalibrationPipeline(FilterConfig(), c, k, k, StereoExtrinsics()),
               std::invalid_argument);
}

TEST(FrontEnd, MatchesAndTracksAreCorrectOnRenderedDrive) {
  const int frames = 60;
  const DriveFigures f = drive(shortDrive(frames), confidentConfig(), FrontEndConfig());
  expectGoodDrive(f, frames);
}

TEST(FrontEnd, ImagesRenderedAsTheBagsAre) {
  // `simulate` renders its drives (the demo, the 1500-frame evaluations) with 1 grey level of
  // noise and 0.5 px blur (scenario_file.h), the drive above without either. 120 frames: the
  // misses are a few long tracks beside an outline whose stereo pair slid along it, so a short
  // drive can miss them. Measured: tracks 99.38 % on their birth point (100.00 % over 60
  // frames); 98.40 % before refined pairs were held to their own noise across the epipolar
  // line (EpipolarMatcher::refinedBandHalfWidth).
  const int frames = 120;
  ImageScenarioOptions as_bags;
  as_bags.render.noise_sigma = 1.0;
  as_bags.render.blur_sigma = 0.5;
  expectGoodDrive(drive(shortDrive(frames), confidentConfig(), FrontEndConfig(), as_bags), frames);
}

TEST(FrontEnd, NoisyBlurredFlickeringImages) {
  // A poorer camera than the bags' (1 grey level, 0.5 px): sensor noise of 3 grey levels,
  // 0.8 px optical blur, and auto-exposure flicker of +-10 % per image, independently left
  // and right. Measured (20 frames): stereo matches 99.84 % correct, new points 99.50 %,
  // tracks 99.20 % stereo-correct and 98.00 % on their birth point, 60 points alive.
  // Below the 99 % of the clean drives on the birth point: the wrong ones are keypoints the
  // noise makes in the sky a few pixels off an object's outline: the patch is the outline's,
  // so the pair is consistent every frame with the object's disparity but the pixel is 2-6 px
  // off it. (94.2 % and 93.3 % before new points were moved to their sub-pixel corner, 98.44 %
  // and 97.66 % before refined pairs were held to their own noise across the epipolar line.)
  const int frames = 20;
  ImageScenarioOptions poor;
  poor.render.noise_sigma = 3.0;
  poor.render.blur_sigma = 0.8;
  poor.exposure_variation = 0.1;
  const DriveFigures f = drive(shortDrive(frames), confidentConfig(), FrontEndConfig(), poor);
  ImageScenarioOptions negative_gain;
  negative_gain.exposure_variation = 1.2;
  EXPECT_THROW(runImageScenario(shortDrive(1), confidentConfig(), FrontEndConfig(), negative_gain),
               std::invalid_argument);
  DriveBars bars;
  bars.tracks_per_frame = 20;
  bars.tracks_stereo_correct = 0.985;
  bars.tracks_correct = 0.975;
  expectGoodDrive(f, frames, bars);
}

TEST(FrontEnd, BlindFramesGiveNothingAndTrackingRestartsAfterThem) {
  // Blind frames are rendered almost black (kBlindFrameExposureGain): the pipeline refuses
  // them (too dark) and finds nothing. Unlike the measurement-level simulator (where every
  // track dies), it keeps its points and re-finds some after the blind stretch: that needs
  // the motion since the last processed pair, which the runner composes over the refused
  // ones. Measured: frame 8 re-finds 12 of 71 tracks (11 correct), 153 of 154 tracks in
  // frames 8-13 correct; with only the last frame's motion it was 139 of 148.
  MeasurementScenario s = shortDrive(14);
  s.blind_frames = {{5, 7}};
  const std::vector<ImageFrameResult> results =
      runImageScenario(s, confidentConfig(), FrontEndConfig());
  ASSERT_EQ(results.size(), 14u);
  int tracks_after = 0, tracks_after_correct = 0;
  for (size_t k = 0; k < results.size(); ++k) {
    const ImageFrameResult& r = results[k];
    std::printf(
        "  frame %zu: features %d/%d, matches %d, tracked %d, failures %d, checked %d, "
        "correct %d, points %d, processed %d\n",
        k, r.front_end.features_left, r.front_end.features_right, r.front_end.stereo_matches,
        r.front_end.tracked, r.front_end.track_failures, r.tracks_checked, r.tracks_correct,
        r.filter.tracked_points, r.processed);
    if (k >= 5 && k <= 7) {
      EXPECT_EQ(r.front_end.stereo_matches, 0) << "frame " << k;
      EXPECT_EQ(r.front_end.tracked, 0) << "frame " << k;
      EXPECT_EQ(r.tracks_checked, 0) << "frame " << k;
    } else {
      EXPECT_GT(r.front_end.stereo_matches, 100) << "frame " << k;
    }
    if (k >= 8) {
      tracks_after += r.tracks_checked;
      tracks_after_correct += r.tracks_correct;
    }
  }
  EXPECT_GE(tracks_after, 6 * 20);
  EXPECT_GE(tracks_after_correct, 0.98 * tracks_after);
}

TEST(FrontEnd, RecordedTrajectoryWithTheSceneAlongIt) {
  // The image-level runner takes the poses and the scene's path from the recording.
  VehicleMotionProfile recorded_motion;
  recorded_motion.speed = 5.0;
  recorded_motion.yaw_rate_amplitude = 0.3;
  recorded_motion.yaw_period = 9.0;
  const VehicleTrajectory analytic(recorded_motion);
  std::vector<StampedPose> poses;
  for (int k = 0; k <= 200; ++k) poses.push_back({50.0 + 0.05 * k, analytic.pose(0.05 * k)});
  MeasurementScenario s = shortDrive(12);
  s.recorded_trajectory = std::make_shared<const PoseTrajectory>(poses);
  s.recorded_start_offset = 4.0;  // in a curve, 20 m from the recording's start
  const DriveFigures f = drive(s, confidentConfig(), FrontEndConfig());
  DriveBars bars;
  bars.tracks_per_frame = 18;  // 12 frames, the first without tracks (measured 21.25)
  expectGoodDrive(f, 12, bars);
}

TEST(FrontEnd, SearchingLostTracksKeepsMoreTracksAtTheSameStereoPrecision) {
  // Off by default: measured (20 frames) 1228 tracks instead of 534, 100 % stereo-correct
  // and 99.43 % on their birth point (with the anchor check; 92.2 % before it: LK from the
  // prediction let tracks on the near ground drift). Not yet measured on the full drives.
  const int frames = 20;
  FrontEndConfig with_search;
  with_search.search_lost_tracks = true;
  const DriveFigures f = drive(shortDrive(frames), confidentConfig(), with_search);
  EXPECT_GE(f.tracks, 50 * frames);
  EXPECT_GE(f.tracks_stereo_correct, 0.99 * f.tracks_reported);
  EXPECT_GE(f.tracks_correct, 0.99 * f.tracks);
  EXPECT_GE(f.final_points, 80);
}

TEST(FrontEnd, PlumbBobDistortedRawImages) {
  const int frames = 40;
  MeasurementScenario s = shortDrive(frames);
  for (CameraIntrinsics* k : {&s.left, &s.right}) {
    k->model = DistortionModel::kPlumbBob;
    k->distortion = {-0.28, 0.074, 0.0002, 0.00002, 0.0};
  }
  expectGoodDrive(drive(s, confidentConfig(), FrontEndConfig()), frames);
}

TEST(FrontEnd, EquidistantDistortedRawImages) {
  const int frames = 40;
  MeasurementScenario s = shortDrive(frames);
  for (CameraIntrinsics* k : {&s.left, &s.right}) {
    k->model = DistortionModel::kEquidistant;
    k->distortion = {-0.01, 0.005, -0.002, 0.0};
  }
  // Measured: tracks on their birth point 99.49 % (98.41 % without FrontEndConfig's
  // corner_half_size: keypoints beside a junction of a near outline with a far surface were
  // carried along the outline), the rest >= 99.7 %.
  expectGoodDrive(drive(s, confidentConfig(), FrontEndConfig()), frames);
}

TEST(FrontEnd, WrongCalibrationBandStillFindsCorrectMatches) {
  // 0.1 m baseline error and 2 deg rotation error on x_camr, default initial sigmas.
  MeasurementScenario s = shortDrive(3);
  s.initial_error.setZero();
  s.initial_error(7) = 0.1;
  s.initial_error(9) = 2.0 * kDeg;
  s.initial_error(11) = 2.0 * kDeg;
  ImageScenarioOptions options;
  const std::vector<ImageFrameResult> results =
      runImageScenario(s, FilterConfig(), FrontEndConfig(), options);
  const ImageFrameResult& first = results.front();
  std::printf("  wrong calibration: %d matches, %d correct\n", first.matches_checked,
              first.matches_correct);
  EXPECT_GE(first.matches_checked, 100);
  // Measured 1114 of 1115 in the first, widest band.
  EXPECT_GE(first.matches_correct, 0.99 * first.matches_checked);
}

class BadImages : public ::testing::Test {
 protected:
  BadImages()
      : intrinsics_(paperOffroadScenario().left),
        pipeline_(FilterConfig(), FrontEndConfig(), intrinsics_, intrinsics_,
                  StereoExtrinsics::fromParameters(paperOffroadScenario().truth)) {
    cv::RNG rng(3);
    good_ = cv::Mat(intrinsics_.height, intrinsics_.width, CV_8UC1);
    rng.fill(good_, cv::RNG::UNIFORM, 0, 255);
  }
  void expectRejected(const cv::Mat& left, const cv::Mat& right, const std::string& word) {
    const CalibrationEstimate before = pipeline_.estimate();
    const PipelineResult r = pipeline_.process(left, right, MotionIncrement());
    EXPECT_FALSE(r.processed);
    EXPECT_NE(r.status.find(word), std::string::npos) << r.status;
    EXPECT_EQ(pipeline_.estimate().parameters, before.parameters);
    EXPECT_EQ(pipeline_.estimate().tangent_covariance, before.tangent_covariance);
    EXPECT_EQ(pipeline_.estimator().filter().pointCount(), 0u);
  }
  CameraIntrinsics intrinsics_;
  CalibrationPipeline pipeline_;
  cv::Mat good_;
};

TEST_F(BadImages, AreRejectedWithAStatusAndTheEstimatorUntouched) {
  const cv::Size size(intrinsics_.width, intrinsics_.height);
  expectRejected(cv::Mat(), good_, "empty");
  expectRejected(cv::Mat::zeros(size, CV_8UC1), good_, "all black");
  expectRejected(good_, cv::Mat(size, CV_8UC1, cv::Scalar(255)), "saturated");
  expectRejected(cv::Mat(8, 8, CV_8UC1, cv::Scalar(5)), good_, "too small");
  expectRejected(good_, cv::Mat(240, 320, CV_8UC1, cv::Scalar(5)), "does not match");
  expectRejected(cv::Mat(size, CV_32FC3, cv::Scalar::all(0.5)), good_, "unsupported");
  // Other encodings of a usable image are accepted.
  cv::Mat bgr, bgra, mono16;
  cv::cvtColor(good_, bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(good_, bgra, cv::COLOR_GRAY2BGRA);
  good_.convertTo(mono16, CV_16U, 16.0);
  EXPECT_TRUE(pipeline_.process(bgr, bgra, MotionIncrement()).processed);
  EXPECT_TRUE(pipeline_.process(mono16, good_, MotionIncrement()).processed);
}

// Issue 17: a refused pair between two good ones must not change what the next one does.
// The caller hands the motion since the last processed pair; were the refused pair's motion
// kept and added to it (as before), the next step would see 0.15 s instead of 0.1 s, and the
// estimate (its motion noise) would differ. The vehicle stands: the images are the same.
TEST_F(BadImages, ARefusedPairChangesNothingForTheNextPair) {
  CalibrationPipeline clean(FilterConfig(), FrontEndConfig(), intrinsics_, intrinsics_,
                            StereoExtrinsics::fromParameters(paperOffroadScenario().truth));
  cv::Mat shifted;  // 12 px of disparity everywhere: stereo matches and new points
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -12, 0, 1, 0);
  cv::warpAffine(good_, shifted, shift, good_.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  MotionIncrement step;
  step.dt = 0.1;
  MotionIncrement half = step;
  half.dt = 0.05;
  for (CalibrationPipeline* p : {&clean, &pipeline_}) {
    ASSERT_TRUE(p->process(good_, shifted, MotionIncrement()).processed);
    ASSERT_TRUE(p->process(good_, shifted, step).processed);
  }
  // The refused pair (0x0, then a wrong size), half a step after the last processed one.
  EXPECT_FALSE(pipeline_.process(cv::Mat(), shifted, half).processed);
  EXPECT_FALSE(pipeline_.process(good_, cv::Mat(240, 320, CV_8UC1, cv::Scalar(9)), half).processed);
  const PipelineResult a = clean.process(good_, shifted, step);
  const PipelineResult b = pipeline_.process(good_, shifted, step);
  ASSERT_TRUE(a.processed && b.processed);
  EXPECT_GT(a.estimate.tracked_points, 0u);
  EXPECT_EQ(a.estimate.parameters, b.estimate.parameters);
  EXPECT_EQ(a.estimate.tangent_covariance, b.estimate.tangent_covariance);
  EXPECT_EQ(a.front_end.tracked, b.front_end.tracked);
  EXPECT_EQ(clean.estimator().filter().pointCount(), pipeline_.estimator().filter().pointCount());
}

// Issue 14: features in both images but no stereo pair (independent noise: a dark, high-gain
// view, rain) is no evidence of a knocked right camera: the whole-image fit finds no
// consistent geometry, so x_camr is neither re-opened nor moved (before: re-opened to 2 deg
// after two such pairs, and the filter then locked onto the next few points). While the fits
// agree, one pair in five is fitted (CalibrationPipeline::wholeImageFitDue), the first at once.
TEST_F(BadImages, ManyFeaturesButNoStereoPairsDoNotReopenTheRightCamera) {
  cv::Mat shifted;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -12, 0, 1, 0);
  cv::warpAffine(good_, shifted, shift, good_.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  MotionIncrement step;
  step.dt = 0.1;
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(pipeline_.process(good_, shifted, step).processed);
  const CalibrationEstimate before = pipeline_.estimate();
  const int fits_before = pipeline_.wholeImageFits();
  cv::RNG rng(11);
  int reopened = 0, refused_by_fit = 0;
  for (int k = 0; k < 30; ++k) {
    cv::Mat left(good_.size(), CV_8UC1), right(good_.size(), CV_8UC1);
    rng.fill(left, cv::RNG::UNIFORM, 0, 255);
    rng.fill(right, cv::RNG::UNIFORM, 0, 255);
    const PipelineResult r = pipeline_.process(left, right, step);
    ASSERT_TRUE(r.processed) << r.status;
    ASSERT_GE(r.front_end.features_left, 200);
    reopened += r.right_camera_reopened;
    refused_by_fit += r.status.find("x_camr kept") != std::string::npos;
  }
  const CalibrationEstimate after = pipeline_.estimate();
  EXPECT_EQ(reopened, 0);
  const int fits = pipeline_.wholeImageFits() - fits_before;
  EXPECT_EQ(fits, 6);  // pairs 1, 6, 11, ..., 26 of the 30
  EXPECT_EQ(refused_by_fit, fits);
  for (int i = 9; i < 12; ++i) {
    EXPECT_NEAR(after.parameters(i), before.parameters(i), 1e-3 * kDeg) << i;
    EXPECT_LT(after.sigmas()(i), 1.5 * before.sigmas()(i)) << i;
  }
}

}  // namespace
}  // namespace osc
