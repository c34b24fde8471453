/// @file test_front_end.cpp
/// @brief The image front end against the renderer's exact ground truth (stereo-match and
/// tracking precision, distorted lenses, a wrong calibration, bad images) and on real EuRoC
/// images with their reference calibration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/frontend/bucketing.h"
#include "online_stereo_calibration/core/frontend/epipolar_trend.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/frontend/patch_alignment.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/tools/kitti_sequence.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// A short drive of the paper scenario from the true calibration.
MeasurementScenario shortDrive(int frames) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = frames;
  s.initial_error.setZero();
  s.step_frame = -1;
  return s;
}

/// A filter that is nearly sure of its (true) calibration.
FilterConfig confidentConfig() {
  FilterConfig c;
  c.initial_caml_translation_sigma = 0.01;
  c.initial_caml_rotation_sigma = 0.2 * kDeg;
  c.initial_camr_translation_sigma = 0.002;
  c.initial_camr_rotation_sigma = 0.05 * kDeg;
  return c;
}

struct DriveFigures {
  int matches = 0, matches_correct = 0;
  int tracks = 0, tracks_correct = 0;
  int tracks_reported = 0, tracks_stereo_correct = 0;
  int new_points = 0, new_correct = 0;
  int matches_at_pixel = 0, new_at_pixel = 0, tracks_stereo_at_pixel = 0;
  int tracks_at_birth_pixel = 0;
  int final_points = 0;
  int processed = 0;
};

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

TEST(CornerNear, MovesAKeypointBesideAJunctionOntoIt) {
  // A T-junction: a horizontal edge (dark above, light below) ends at a dark post whose left
  // outline runs at x = 29.5; the junction is at (29.5, 29.5). A keypoint 2.1 px beside it
  // moves onto it (to 0.8 px: the mixed gradients right at the junction pull it along the
  // post's outline; within the 1.5 px of a correct match, where the keypoint was not).
  cv::Mat image(60, 60, CV_8UC1, cv::Scalar(180));
  image(cv::Rect(0, 0, 30, 30)).setTo(60);
  image(cv::Rect(30, 0, 30, 60)).setTo(10);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  const Eigen::Vector2d junction(29.5, 29.5);
  Eigen::Vector2d corner(-1.0, -1.0);
  ASSERT_TRUE(cornerNear(image, Eigen::Vector2d(28.0, 31.0), 2, 2.0, &corner));
  EXPECT_NEAR(corner.x(), junction.x(), 0.2) << corner.transpose();
  EXPECT_LT((corner - junction).norm(), 1.0) << corner.transpose();
  // Farther than max_shift: refused, the output untouched.
  Eigen::Vector2d untouched(-1.0, -1.0);
  EXPECT_FALSE(cornerNear(image, Eigen::Vector2d(28.0, 31.0), 2, 1.0, &untouched));
  EXPECT_EQ(untouched, Eigen::Vector2d(-1.0, -1.0));
}

TEST(Bucketing, KeepsTheBestPerFreeCellUpToTheCap) {
  const std::vector<Eigen::Vector2d> pos = {{10, 10}, {20, 20}, {150, 10}, {10, 150}, {150, 150}};
  const std::vector<double> cost = {0.3, 0.1, 0.2, 0.05, 0.4};
  const std::vector<Eigen::Vector2d> occupied = {{160, 160}};
  const std::vector<int> kept = selectByBuckets(pos, cost, occupied, 200, 200, 2, 2, 10);
  EXPECT_EQ(kept, (std::vector<int>{3, 1, 2}));
  EXPECT_EQ(selectByBuckets(pos, cost, occupied, 200, 200, 2, 2, 2), (std::vector<int>{3, 1}));
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

TEST(EpipolarMatcher, RefinedPairsHaveNoKeypointFloorButKeepTheCalibrationsSpread) {
  FrontEndConfig config;
  config.pixel_sigma = 0.1;  // keypoints' band below the floor
  EpipolarMatcher matcher(config, 1.0);
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  Eigen::Isometry3d T_caml_camr = Eigen::Isometry3d::Identity();
  T_caml_camr.translation() = Eigen::Vector3d(0.0, -0.5, 0.0);  // body frames: right is -y
  const Eigen::Vector2d left(300.0, 200.0), right(290.0, 200.0);
  matcher.setGeometry(K, K, T_caml_camr, Matrix6d::Zero());
  const EpipolarMatcher::Lines lines = matcher.lines(left);
  // A keypoint on the pixel grid keeps min_band; a refined pair its own noise only.
  EXPECT_DOUBLE_EQ(matcher.bandHalfWidth(lines, right), config.min_band);
  EXPECT_NEAR(matcher.refinedBandHalfWidth(lines, right, config.refined_pixel_sigma),
              config.band_sigmas * std::sqrt(2.0) * config.refined_pixel_sigma, 1e-9);
  EXPECT_LT(matcher.refinedBandHalfWidth(lines, right, config.refined_pixel_sigma), 0.5);
  // An uncertain x_camr (1 deg about the baseline tilts the line) widens both.
  Matrix6d P = Matrix6d::Zero();
  P(3, 3) = std::pow(1.0 * kDeg, 2);
  matcher.setGeometry(K, K, T_caml_camr, P);
  const EpipolarMatcher::Lines uncertain = matcher.lines(left);
  EXPECT_GT(matcher.refinedBandHalfWidth(uncertain, right, config.refined_pixel_sigma), 1.0);
  EXPECT_GT(matcher.bandHalfWidth(uncertain, right), config.min_band);
}

TEST(EpipolarTrend, RecoversTheCommonDistanceDespiteSlidPairs) {
  // A knocked right camera: 0.8 px everywhere (pitch_r) and 0.3 px per focal length of column
  // (roll_r); one pair in five slid along an outline by a further +-1 px.
  const double center = 320.0, focal = 500.0;
  const Eigen::Vector2d truth(0.8, 0.3);
  cv::RNG rng(7);
  std::vector<EpipolarResidual> residuals;
  for (int i = 0; i < 200; ++i) {
    EpipolarResidual r;
    r.right_pixel = Eigen::Vector2d(rng.uniform(0.0, 640.0), rng.uniform(0.0, 480.0));
    r.distance =
        truth.dot(Eigen::Vector2d(1.0, (r.right_pixel.x() - center) / focal)) + rng.gaussian(0.05);
    if (i % 5 == 0) r.distance += (i % 10 == 0) ? 1.0 : -1.0;
    residuals.push_back(r);
  }
  const EpipolarTrend trend = EpipolarTrend::fit(residuals, center, focal);
  EXPECT_NEAR(trend.coefficients()(0), truth(0), 0.02);
  EXPECT_NEAR(trend.coefficients()(1), truth(1), 0.05);
  int within = 0;
  for (int i = 1; i < 200; ++i) {
    if (i % 5 == 0) continue;
    const EpipolarResidual& r = residuals[static_cast<size_t>(i)];
    within += std::abs(r.distance - trend.at(r.right_pixel)) < 0.2;
  }
  EXPECT_GE(within, 155);  // of the 159 unslid pairs (0.05 px noise)
  // Too few pairs: no trend, every pair against its own line.
  std::vector<EpipolarResidual> few(residuals.begin(),
                                    residuals.begin() + EpipolarTrend::kMinResiduals - 1);
  EXPECT_EQ(EpipolarTrend::fit(few, center, focal).coefficients(), Eigen::Vector2d::Zero());
  // A common distance within the pairs' own noise is no trend either.
  for (EpipolarResidual& r : residuals) r.distance = 0.03 + rng.gaussian(0.05);
  EXPECT_EQ(EpipolarTrend::fit(residuals, center, focal).coefficients(), Eigen::Vector2d::Zero());
}

/// A smooth random texture (blurred noise), mono8.
cv::Mat texture(int width, int height, int seed) {
  cv::Mat noise(height, width, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

TEST(PatchAlignment, RecoversASubPixelShiftAndBrightnessOffset) {
  const cv::Mat source = texture(120, 100, 1);
  // target(x) = source(x - shift) + 20 grey levels.
  const Eigen::Vector2d shift(1.3, -0.7);
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shift.x(), 0, 1, shift.y());
  cv::Mat target;
  cv::warpAffine(source, target, M, source.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  target += cv::Scalar(20);
  PatchAlignmentConfig config;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(40, 50), Eigen::Vector2d(70.4, 33.6)}) {
    // Started from the nearest integer pixel, as from a keypoint.
    const Eigen::Vector2d guess = (p + shift).array().round().matrix();
    const PatchAlignment a = alignPatch(source, p, target, guess, config);
    ASSERT_TRUE(a.ok) << "ncc " << a.ncc << " eigen ratio " << a.eigen_ratio;
    EXPECT_NEAR(a.position.x(), p.x() + shift.x(), 0.1);
    EXPECT_NEAR(a.position.y(), p.y() + shift.y(), 0.1);
    EXPECT_GT(a.ncc, 0.99);
  }
  // Beyond max_shift from the guess: refused.
  config.max_shift = 1.0;
  EXPECT_FALSE(
      alignPatch(source, Eigen::Vector2d(40, 50), target, Eigen::Vector2d(40, 50), config).ok);
}

/// Aligns patches of a texture into the texture warped by the linear map A about a centre
/// c (target(c + A (x - c)) = source(x)), from a guess 0.6 px off, once with the template
/// resampled for A (template_sampling = A^-1) and once plain. Mean errors and NCCs.
struct WarpedAlignment {
  double error_fitted = 0.0, error_plain = 0.0, ncc_fitted = 0.0, ncc_plain = 0.0;
};

WarpedAlignment alignUnderWarp(const Eigen::Matrix2d& A) {
  const Eigen::Vector2d c(60, 50);
  const cv::Mat source = texture(120, 100, 7);
  const Eigen::Vector2d t = c - A * c;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << A(0, 0), A(0, 1), t.x(), A(1, 0), A(1, 1), t.y());
  cv::Mat target;
  cv::warpAffine(source, target, M, source.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  PatchAlignmentConfig config;
  config.min_ncc = 0.0;  // compare positions, not the NCC check
  config.max_shift = 5.0;
  WarpedAlignment w;
  const std::vector<Eigen::Vector2d> points = {{52, 44}, {66.5, 55.2}, {57, 58}, {70, 41}};
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d truth = c + A * (p - c);
    const Eigen::Vector2d guess = (truth.array() + 0.6).matrix();
    config.template_sampling = A.inverse();
    const PatchAlignment fitted = alignPatch(source, p, target, guess, config);
    config.template_sampling = Eigen::Matrix2d::Identity();
    const PatchAlignment plain = alignPatch(source, p, target, guess, config);
    w.error_fitted += (fitted.position - truth).norm() / points.size();
    w.error_plain += (plain.position - truth).norm() / points.size();
    w.ncc_fitted += fitted.ncc / points.size();
    w.ncc_plain += plain.ncc / points.size();
  }
  std::printf("  mean error resampled %.3f px (NCC %.3f), plain %.3f px (NCC %.3f)\n",
              w.error_fitted, w.ncc_fitted, w.error_plain, w.ncc_plain);
  return w;
}

TEST(PatchAlignment, ResampledTemplateFollowsAnApproachingSurface) {
  // The surface appears 1.3 times larger, as a point approached by the camera.
  const WarpedAlignment w = alignUnderWarp(1.3 * Eigen::Matrix2d::Identity());
  EXPECT_LT(w.error_fitted, 0.1);
  EXPECT_GT(w.ncc_fitted, 0.98);
  EXPECT_GT(w.ncc_fitted, w.ncc_plain + 0.02);  // the plain template fits the surface worse
  EXPECT_GT(w.error_plain, 3.0 * w.error_fitted);
}

TEST(PatchAlignment, ResampledTemplateFollowsALensSqueeze) {
  // A fisheye lens squeezes a patch moving outwards along the radius (here at 30 deg to the
  // x axis) more than across it (CameraModel::lensJacobian; the front end's templateSampling).
  const double angle = M_PI / 6.0;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(angle).toRotationMatrix();
  const Eigen::Matrix2d A = R * Eigen::Vector2d(0.8, 0.95).asDiagonal() * R.transpose();
  const WarpedAlignment w = alignUnderWarp(A);
  EXPECT_LT(w.error_fitted, 0.1);
  EXPECT_GT(w.ncc_fitted, 0.98);
  EXPECT_GT(w.ncc_fitted, w.ncc_plain + 0.02);
  EXPECT_GT(w.error_plain, 3.0 * w.error_fitted);
}

TEST(PatchAlignment, RefusesStraightEdgesAndDifferentContent) {
  // A vertical step edge: its position along the edge is unknown (aperture problem).
  cv::Mat edge(60, 60, CV_8UC1, cv::Scalar(40));
  edge.colRange(30, 60).setTo(200);
  const PatchAlignment a = alignPatch(edge, Eigen::Vector2d(30, 30), edge, Eigen::Vector2d(30, 30),
                                      PatchAlignmentConfig());
  EXPECT_FALSE(a.ok);
  EXPECT_LT(a.eigen_ratio, 0.05);
  // Unrelated textures: low NCC.
  const PatchAlignment b =
      alignPatch(texture(60, 60, 2), Eigen::Vector2d(30, 30), texture(60, 60, 3),
                 Eigen::Vector2d(30, 30), PatchAlignmentConfig());
  EXPECT_FALSE(b.ok);
}

TEST(PatchAlignment, SeesADepthDiscontinuityAcrossThePatch) {
  // Left view: a textured foreground over the left half of the image in front of a textured
  // background. Right view: the foreground moves 6 px, the background 1 px.
  const cv::Mat background = texture(140, 80, 4), foreground = texture(140, 80, 5);
  auto view = [&](double fg_shift, double bg_shift) {
    cv::Mat bg, fg;
    const cv::Mat Mb = (cv::Mat_<double>(2, 3) << 1, 0, -bg_shift, 0, 1, 0);
    const cv::Mat Mf = (cv::Mat_<double>(2, 3) << 1, 0, -fg_shift, 0, 1, 0);
    cv::warpAffine(background, bg, Mb, background.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::warpAffine(foreground, fg, Mf, foreground.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    const int edge = static_cast<int>(std::lround(70 - fg_shift));
    fg.colRange(0, edge).copyTo(bg.colRange(0, edge));
    return bg;
  };
  const cv::Mat left = view(0.0, 0.0), right = view(6.0, 1.0);
  const Eigen::Vector2d along(-1.0, 0.0);  // positive disparity: right pixel = left - d
  // On the contour: the foreground half wants -6 px, the background half -1 px.
  EXPECT_TRUE(straddlesDepthDiscontinuity(left, Eigen::Vector2d(70, 40), right,
                                          Eigen::Vector2d(64, 40), along, 4, 8));
  // Inside the foreground and inside the background: one disparity.
  EXPECT_FALSE(straddlesDepthDiscontinuity(left, Eigen::Vector2d(40, 40), right,
                                           Eigen::Vector2d(34, 40), along, 4, 8));
  EXPECT_FALSE(straddlesDepthDiscontinuity(left, Eigen::Vector2d(110, 40), right,
                                           Eigen::Vector2d(109, 40), along, 4, 8));
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

// ---------------------------------------------------------------------------------------
// Real images: EuRoC V1_01_easy, 752x480, plumb_bob.
// ---------------------------------------------------------------------------------------

const std::string kEurocDir = std::string(OSC_SOURCE_DIR) + "/../shared/data/euroc_v101_micro";

struct EurocCamera {
  CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_body_sensor = Eigen::Isometry3d::Identity();
};

EurocCamera readEurocCamera(const std::string& file) {
  cv::FileStorage fs(file, cv::FileStorage::READ);
  EurocCamera c;
  std::vector<double> k, d, t;
  std::vector<int> res;
  fs["intrinsics"] >> k;
  fs["distortion_coefficients"] >> d;
  fs["resolution"] >> res;
  fs["T_BS"]["data"] >> t;
  c.intrinsics.width = res.at(0);
  c.intrinsics.height = res.at(1);
  c.intrinsics.fx = k.at(0);
  c.intrinsics.fy = k.at(1);
  c.intrinsics.cx = k.at(2);
  c.intrinsics.cy = k.at(3);
  c.intrinsics.model = DistortionModel::kPlumbBob;
  c.intrinsics.distortion = {d.at(0), d.at(1), d.at(2), d.at(3), 0.0};
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = t.at(static_cast<size_t>(i));
  c.T_body_sensor.matrix() = m;
  return c;
}

TEST(FrontEndEuroc, EpipolarGuidedMatchingOnRealImages) {
  if (!std::ifstream(kEurocDir + "/cam0/sensor.yaml").good()) {
    GTEST_SKIP() << "EuRoC data not found at " << kEurocDir;
  }
  const EurocCamera cam0 = readEurocCamera(kEurocDir + "/cam0/sensor.yaml");
  const EurocCamera cam1 = readEurocCamera(kEurocDir + "/cam1/sensor.yaml");
  const Eigen::Isometry3d T_lopt_ropt = cam0.T_body_sensor.inverse() * cam1.T_body_sensor;
  StereoExtrinsics reference;
  reference.T_caml_camr = bodyFromOptical() * T_lopt_ropt * bodyFromOptical().inverse();
  ASSERT_TRUE(reference.leftToRightOptical().isApprox(T_lopt_ropt, 1e-9));
  EXPECT_NEAR(T_lopt_ropt.translation().norm(), 0.110, 0.002);

  // The reference calibration, with a small uncertainty.
  Matrix12d P = Matrix12d::Zero();
  P.diagonal() << Eigen::Vector3d::Constant(0.01 * 0.01), Eigen::Vector3d::Constant(1e-4),
      Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(std::pow(0.05 * kDeg, 2));
  CalibrationPipeline pipeline(FilterConfig(), FrontEndConfig(), cam0.intrinsics, cam1.intrinsics,
                               reference);
  const CameraModel left(cam0.intrinsics), right(cam1.intrinsics);
  const Eigen::Matrix3d F = fundamentalMatrix(left.K(), right.K(), T_lopt_ropt);
  const std::vector<std::string> left_files = sortedPngs(kEurocDir + "/cam0");
  const std::vector<std::string> right_files = sortedPngs(kEurocDir + "/cam1");
  ASSERT_EQ(left_files.size(), right_files.size());
  ASSERT_GE(left_files.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    pipeline.reset(reference, P);
    const cv::Mat l = cv::imread(left_files[i * left_files.size() / 4], cv::IMREAD_UNCHANGED);
    const cv::Mat r = cv::imread(right_files[i * left_files.size() / 4], cv::IMREAD_UNCHANGED);
    const PipelineResult result = pipeline.process(l, r, MotionIncrement());
    ASSERT_TRUE(result.processed) << result.status;
    const std::vector<StereoObservation>& matches = pipeline.frontEnd().lastStereoMatches();
    std::vector<double> sampson, depth;
    for (const StereoObservation& m : matches) {
      const Eigen::Vector2d ul = left.undistortPixel(m.left_pixel);
      const Eigen::Vector2d ur = right.undistortPixel(m.right_pixel);
      sampson.push_back(sampsonDistance(F, ul, ur) / std::sqrt(2.0));
      const auto tri = triangulateMidpoint(left.K().inverse() * ul.homogeneous(),
                                           right.K().inverse() * ur.homogeneous(), T_lopt_ropt);
      depth.push_back(tri ? tri->point_left.z() : -1.0);
    }
    ASSERT_GE(matches.size(), 200u);
    std::nth_element(sampson.begin(), sampson.begin() + sampson.size() / 2, sampson.end());
    const double median_sampson = sampson[sampson.size() / 2];
    const long plausible =
        std::count_if(depth.begin(), depth.end(), [](double z) { return z >= 1.0 && z <= 15.0; });
    std::printf("  pair %zu: %zu matches, median Sampson %.3f px, %.1f %% depths in 1-15 m\n", i,
                matches.size(), median_sampson, 100.0 * plausible / matches.size());
    EXPECT_LE(median_sampson, 0.3);
    EXPECT_GE(plausible, 0.95 * matches.size());
  }
}

// Issue 14: the rig's rotation and baseline direction from the images alone. On the EuRoC
// pairs the fit agrees with the reference calibration within 0.1 deg and within 4 of its own
// sigmas; two unrelated images give no valid fit (no false evidence of a knock).
TEST(GlobalStereoFit, RecoversTheRigOfRealEurocPairsWithoutACalibration) {
  if (!std::ifstream(kEurocDir + "/cam0/sensor.yaml").good()) {
    GTEST_SKIP() << "EuRoC data not found at " << kEurocDir;
  }
  const EurocCamera cam0 = readEurocCamera(kEurocDir + "/cam0/sensor.yaml");
  const EurocCamera cam1 = readEurocCamera(kEurocDir + "/cam1/sensor.yaml");
  const Eigen::Isometry3d T_lopt_ropt = cam0.T_body_sensor.inverse() * cam1.T_body_sensor;
  const CameraModel left(cam0.intrinsics), right(cam1.intrinsics);
  const FeatureDetector detector{FrontEndConfig()};
  const std::vector<std::string> left_files = sortedPngs(kEurocDir + "/cam0");
  const std::vector<std::string> right_files = sortedPngs(kEurocDir + "/cam1");
  ASSERT_GE(left_files.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const size_t k = i * left_files.size() / 4;
    const FeatureSet l = detector.detect(cv::imread(left_files[k], cv::IMREAD_GRAYSCALE), left);
    const FeatureSet r = detector.detect(cv::imread(right_files[k], cv::IMREAD_GRAYSCALE), right);
    // The baseline direction a user would assume: along the left camera's x axis.
    const GlobalStereoFit fit = fitStereoGeometry(l, r, left, right, Eigen::Vector3d::UnitX());
    ASSERT_TRUE(fit.valid) << fit.why;
    const double angle = rotationAngleBetween(fit.R_lopt_ropt, T_lopt_ropt.linear());
    const double sigma = std::sqrt(fit.rotation_covariance.eigenvalues().real().maxCoeff());
    const double free_direction = std::acos(
        std::min(1.0, fit.free_baseline_direction.dot(T_lopt_ropt.translation().normalized())));
    std::printf(
        "  pair %zu: %s; rotation off by %.4f deg (sigma %.4f); the free five-point solution's "
        "baseline direction %.1f deg off\n",
        i, fit.why.c_str(), angle / kDeg, sigma / kDeg, free_direction / kDeg);
    EXPECT_LT(angle, 0.1 * kDeg);
    EXPECT_LT(angle, 4.0 * sigma);
  }
  // Unrelated content in the two images (independent random textures): no valid fit.
  cv::Mat noise_left(480, 752, CV_8UC1), noise_right(480, 752, CV_8UC1);
  cv::RNG rng(5);
  rng.fill(noise_left, cv::RNG::UNIFORM, 0, 255);
  rng.fill(noise_right, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise_left, noise_left, cv::Size(3, 3), 0);
  cv::GaussianBlur(noise_right, noise_right, cv::Size(3, 3), 0);
  const GlobalStereoFit none =
      fitStereoGeometry(detector.detect(noise_left, left), detector.detect(noise_right, right),
                        left, right, Eigen::Vector3d::UnitX());
  EXPECT_FALSE(none.valid) << none.why;
}

// ---- diagnostics (temporary) ----
struct DiagCtx {
  const StereoSceneRenderer* renderer;
  const CameraModel* left;
  const CameraModel* right;
  Eigen::Isometry3d Tl, Tr;
};
// depth (m, along optical z) of the surface seen at a pixel, -1 for sky
double diagDepth(const DiagCtx& c, const CameraModel& cam, const Eigen::Isometry3d& T,
                 const Eigen::Vector2d& px) {
  const auto p = c.renderer->surfacePoint(cam, T, px);
  if (!p) return -1.0;
  return (T.inverse() * *p).z();
}
// largest relative depth change within r px around px
double diagEdge(const DiagCtx& c, const CameraModel& cam, const Eigen::Isometry3d& T,
                const Eigen::Vector2d& px, double r) {
  const double d0 = diagDepth(c, cam, T, px);
  double worst = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const double d = diagDepth(c, cam, T, px + r * Eigen::Vector2d(dx, dy));
      if (d0 < 0 || d < 0) {
        if ((d0 < 0) != (d < 0)) worst = std::max(worst, 10.0);
        continue;
      }
      worst = std::max(worst, std::abs(d - d0) / d0);
    }
  return worst;
}
// prints one line about a pair; returns error (px) or -1 if not visible
double diagPair(const DiagCtx& c, const char* tag, const Eigen::Vector2d& pl,
                const Eigen::Vector2d& pr, bool print_ok) {
  const auto p = c.renderer->surfacePoint(*c.left, c.Tl, pl);
  Eigen::Vector2d proj(-1, -1);
  bool vis = false;
  if (p) vis = c.renderer->projectVisible(*c.right, c.Tr, *p, &proj);
  const double err = p ? (proj - pr).norm() : -1.0;
  const bool ok =
      checkStereoMatch(*c.renderer, *c.left, *c.right, c.Tl, c.Tr, pl, pr, 1.5).point.has_value();
  if (ok && !print_ok) return err;
  const double depth = diagDepth(c, *c.left, c.Tl, pl);
  std::printf(
      "%s %s L(%.0f,%.0f) R(%.1f,%.1f) true(%.1f,%.1f) vis %d err %.2f dx %.2f dy %.2f depth %.1f "
      "edgeL %.2f edgeR %.2f\n",
      tag, ok ? "OK " : "BAD", pl.x(), pl.y(), pr.x(), pr.y(), proj.x(), proj.y(), vis, err,
      pr.x() - proj.x(), pr.y() - proj.y(), depth, diagEdge(c, *c.left, c.Tl, pl, 2.0),
      diagEdge(c, *c.right, c.Tr, pr, 2.0));
  return err;
}

/// Diagnostics, not a check (run with --gtest_also_run_disabled_tests): prints every wrong
/// stereo match (M) and track (T) with its true pixel, error along/across the line, depth
/// and depth discontinuity around the pixel (edgeL/R: largest relative depth change within
/// 2 px; 10 = sky), every track off its birth point (B), and a SUMMARY. Environment:
/// DIAG_FRAMES, DIAG_DISTORT (plumb_bob, or "equidistant"), D_QUIET, D_IMG (debug image of
/// frame 5), D_CROP=id (x8 crops of that point's images from its birth on,
/// /tmp/crop_ID_FRAME.png, and the depths around it), D_INNOV (each track's innovation against
/// the filter's prediction: I lines), D_NOISE, D_BLUR, D_FLICKER (the image options) and D_*
/// overrides of the FrontEndConfig.
TEST(FrontEndDiag, DISABLED_DumpWrongMatchesAndTracks) {
  const int frames = std::getenv("DIAG_FRAMES") ? std::atoi(std::getenv("DIAG_FRAMES")) : 25;
  MeasurementScenario s = shortDrive(frames);
  if (std::getenv("DIAG_DISTORT")) {  // "equidistant", or anything else for plumb_bob
    const bool equidistant = std::string(std::getenv("DIAG_DISTORT")) == "equidistant";
    for (CameraIntrinsics* k : {&s.left, &s.right}) {
      k->model = equidistant ? DistortionModel::kEquidistant : DistortionModel::kPlumbBob;
      k->distortion = equidistant ? std::vector<double>{-0.01, 0.005, -0.002, 0.0}
                                  : std::vector<double>{-0.28, 0.074, 0.0002, 0.00002, 0.0};
      if (std::getenv("D_K")) {  // comma-separated distortion coefficients
        k->distortion.clear();
        std::string list = std::getenv("D_K");
        for (size_t at = 0; at < list.size();) {
          const size_t end = std::min(list.find(',', at), list.size());
          k->distortion.push_back(std::atof(list.substr(at, end - at).c_str()));
          at = end + 1;
        }
      }
    }
  }
  MeasurementSimulator sim(s);
  ImageScenarioOptions options;
  if (std::getenv("D_NOISE")) options.render.noise_sigma = std::atof(std::getenv("D_NOISE"));
  if (std::getenv("D_BLUR")) options.render.blur_sigma = std::atof(std::getenv("D_BLUR"));
  if (std::getenv("D_FLICKER")) options.exposure_variation = std::atof(std::getenv("D_FLICKER"));
  SceneConfig scene = options.scene;
  scene.path = sim.groundTrack();
  const StereoSceneRenderer renderer(scene);
  DiagCtx c{&renderer, &sim.leftCamera(), &sim.rightCamera(), {}, {}};
  FrontEndConfig fe;
  auto envd = [](const char* n, double* v) {
    if (std::getenv(n)) *v = std::atof(std::getenv(n));
  };
  auto envi = [](const char* n, int* v) {
    if (std::getenv(n)) *v = std::atoi(std::getenv(n));
  };
  if (std::getenv("D_DET")) fe.detector = std::getenv("D_DET");
  envi("D_MAXF", &fe.max_features);
  envi("D_FAST", &fe.fast_threshold);
  envd("D_RATIO", &fe.ratio);
  envd("D_TRATIO", &fe.track_ratio);
  envd("D_NCC", &fe.min_patch_ncc);
  if (std::getenv("D_SEARCH")) fe.search_lost_tracks = true;
  envi("D_DISC", &fe.discontinuity_search);
  envd("D_SNCC", &fe.min_search_ncc);
  envd("D_FB", &fe.max_forward_backward);
  envd("D_EIG", &fe.min_patch_eigen_ratio);
  envd("D_RSIG", &fe.refined_pixel_sigma);
  envd("D_ANCHOR", &fe.max_anchor_shift);
  envd("D_TSHIFT", &fe.max_temporal_shift);
  envi("D_CORNER", &fe.corner_half_size);
  envd("D_CORNER_SHIFT", &fe.max_corner_shift);
  envd("D_MAXD", &fe.max_descriptor_distance);
  envd("D_TMAXD", &fe.max_track_descriptor_distance);
  envi("D_HALF", &fe.patch_half_size);
  const bool quiet = std::getenv("D_QUIET") != nullptr;
  // D_CROP=id: x8 crops of that point's left and right images around its pixels
  // (/tmp/crop_ID_FRAME.png; the reported pixel in red, `left_truth` / `right_truth` in green)
  // and the left image's depth (m, -1 sky) every 2 px around it. True if it was that point.
  auto showCrop = [&](int frame, const StereoObservation& o, const Eigen::Vector2d& left_truth,
                      const Eigen::Vector2d& right_truth) {
    if (!std::getenv("D_CROP") || o.id != std::strtoul(std::getenv("D_CROP"), nullptr, 10))
      return false;
    RenderOptions ro = options.render;
    ro.noise_seed = 2u * static_cast<unsigned>(frame) + 1u;
    const cv::Mat li = renderer.render(*c.left, c.Tl, ro);
    ro.noise_seed += 1u;
    const cv::Mat ri = renderer.render(*c.right, c.Tr, ro);
    auto crop = [](const cv::Mat& im, const Eigen::Vector2d& at, const Eigen::Vector2d& truth) {
      const int R = 12, S = 8;
      cv::Mat out;
      cv::Mat patch;
      cv::getRectSubPix(im, cv::Size(2 * R + 1, 2 * R + 1),
                        cv::Point2f(std::round(at.x()), std::round(at.y())), patch);
      cv::resize(patch, out, cv::Size(), S, S, cv::INTER_NEAREST);
      cv::cvtColor(out, out, cv::COLOR_GRAY2BGR);
      auto mark = [&](const Eigen::Vector2d& p, cv::Scalar col) {
        const Eigen::Vector2d q =
            (p - Eigen::Vector2d(std::round(at.x()) - R, std::round(at.y()) - R)) * S +
            Eigen::Vector2d(S / 2, S / 2);
        cv::circle(out, cv::Point(q.x(), q.y()), 5, col, 2);
      };
      mark(at, cv::Scalar(0, 0, 255));
      mark(truth, cv::Scalar(0, 255, 0));
      return out;
    };
    std::printf("DEPTHS id %lu frame %d\n", (unsigned long)o.id, frame);
    for (int dy = -6; dy <= 6; dy += 2) {
      for (int dx = -6; dx <= 6; dx += 2)
        std::printf(" %6.1f", diagDepth(c, *c.left, c.Tl, o.left_pixel + Eigen::Vector2d(dx, dy)));
      std::printf("\n");
    }
    cv::Mat both;
    cv::hconcat(crop(li, o.left_pixel, left_truth), crop(ri, o.right_pixel, right_truth), both);
    cv::imwrite("/tmp/crop_" + std::to_string(o.id) + "_" + std::to_string(frame) + ".png", both);
    return true;
  };
  DriveFigures f;
  std::map<PointId, std::pair<std::vector<Eigen::Vector3d>, int>> births;
  runImageScenario(
      s, confidentConfig(), fe, options,
      [&](const ImageFrameResult& r, const CalibrationPipeline& pipeline) {
        SimulatedFrame frame;
        sim.nextFrame(&frame);
        c.Tl = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
        c.Tr = c.Tl * frame.truth.leftToRightOptical();
        f.matches += r.matches_checked;
        f.matches_correct += r.matches_correct;
        f.tracks += r.tracks_checked;
        f.tracks_correct += r.tracks_correct;
        f.tracks_reported += r.tracks_reported;
        f.tracks_stereo_correct += r.tracks_stereo_correct;
        f.new_points += r.new_checked;
        f.new_correct += r.new_correct;
        f.final_points = r.filter.tracked_points;
        std::printf("FRAME %d matches %d/%d tracks %d/%d birth %d/%d points %d\n", r.filter.frame,
                    r.matches_correct, r.matches_checked, r.tracks_stereo_correct,
                    r.tracks_reported, r.tracks_correct, r.tracks_checked, r.filter.tracked_points);
        for (const auto& o : pipeline.frontEnd().lastTracked()) {
          auto it = births.find(o.id);
          if (it == births.end() || it->second.first.empty()) continue;
          // The birth candidate nearest the pair now.
          Eigen::Vector2d pl, pr;
          bool vl = false, vr = false;
          double el = 1e9, er = 1e9;
          for (const Eigen::Vector3d& p : it->second.first) {
            Eigen::Vector2d ql, qr;
            const bool wl = renderer.projectVisible(*c.left, c.Tl, p, &ql);
            const bool wr = renderer.projectVisible(*c.right, c.Tr, p, &qr);
            const double dl = (ql - o.left_pixel).norm(), dr = (qr - o.right_pixel).norm();
            if (std::max(dl, dr) < std::max(el, er)) {
              pl = ql, pr = qr, vl = wl, vr = wr, el = dl, er = dr;
            }
          }
          showCrop(r.filter.frame, o, pl, pr);
          const bool off_birth = !(vl && vr && el <= 1.5 && er <= 1.5);
          // The track's innovation against the filter's prediction (undistorted pixels: the
          // reported raw ones are the same on the pinhole drives only).
          if (std::getenv("D_INNOV")) {
            for (const TrackWindow& w : pipeline.frontEnd().lastWindows()) {
              if (w.id != o.id) continue;
              const Eigen::Vector4d z(o.left_pixel.x(), o.left_pixel.y(), o.right_pixel.x(),
                                      o.right_pixel.y());
              const Eigen::Vector4d e = z - w.z;
              std::printf(
                  "I id %lu frame %d age %d bad %d e %.2f %.2f %.2f %.2f nis %.2f sd %.2f %.2f "
                  "%.2f %.2f\n",
                  (unsigned long)o.id, r.filter.frame, r.filter.frame - it->second.second,
                  off_birth, e(0), e(1), e(2), e(3), e.dot(w.S.inverse() * e), std::sqrt(w.S(0, 0)),
                  std::sqrt(w.S(1, 1)), std::sqrt(w.S(2, 2)), std::sqrt(w.S(3, 3)));
            }
          }
          if (off_birth && !quiet)
            std::printf(
                "B id %lu age %d vis %d%d L(%.0f,%.0f) errL %.2f (%.2f,%.2f) errR %.2f depth %.1f "
                "edgeL %.2f\n",
                (unsigned long)o.id, r.filter.frame - it->second.second, vl, vr, o.left_pixel.x(),
                o.left_pixel.y(), el, o.left_pixel.x() - pl.x(), o.left_pixel.y() - pl.y(), er,
                diagDepth(c, *c.left, c.Tl, o.left_pixel),
                diagEdge(c, *c.left, c.Tl, o.left_pixel, 2.0));
        }
        for (const auto& o : pipeline.frontEnd().lastNewCandidates()) {
          if (!pipeline.estimator().filter().hasPoint(o.id)) continue;
          births[o.id] = {scenePointsOfStereoMatch(renderer, *c.left, *c.right, c.Tl, c.Tr,
                                                   o.left_pixel, o.right_pixel, 1.5),
                          r.filter.frame};
          if (showCrop(r.filter.frame, o, o.left_pixel, o.right_pixel))
            std::printf("BIRTH of %lu above: disparity %.2f\n", (unsigned long)o.id,
                        o.left_pixel.x() - o.right_pixel.x());
        }
        if (std::getenv("D_IMG") && r.filter.frame == 5)
          cv::imwrite(std::getenv("D_IMG"), pipeline.debugImage());
        if (quiet) return;
        for (const auto& o : pipeline.frontEnd().lastStereoMatches())
          diagPair(c, "M", o.left_pixel, o.right_pixel, false);
        for (const auto& o : pipeline.frontEnd().lastTracked())
          diagPair(c, ("T " + std::to_string(o.id)).c_str(), o.left_pixel, o.right_pixel, false);
      });
  std::printf(
      "SUMMARY matches %d (%.2f %%) new %d (%.2f %%) tracks %d (stereo %.2f %%, birth %.2f %% of "
      "%d) points %d\n",
      f.matches, 100.0 * f.matches_correct / std::max(1, f.matches), f.new_points,
      100.0 * f.new_correct / std::max(1, f.new_points), f.tracks_reported,
      100.0 * f.tracks_stereo_correct / std::max(1, f.tracks_reported),
      100.0 * f.tracks_correct / std::max(1, f.tracks), f.tracks, f.final_points);
}

}  // namespace
}  // namespace osc
