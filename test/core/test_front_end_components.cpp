/// @file test_front_end_components.cpp
/// @brief The front end's parts on their own: a keypoint moved onto its corner, bucketing,
/// the epipolar matcher's refined pairs, the epipolar trend, and patch alignment (sub-pixel
/// shifts, resampled templates, refusals, depth discontinuities).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "front_end_test_support.h"
#include "online_stereo_calibration/core/frontend/bucketing.h"
#include "online_stereo_calibration/core/frontend/epipolar_matcher.h"
#include "online_stereo_calibration/core/frontend/epipolar_trend.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/patch_alignment.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

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

}  // namespace
}  // namespace osc
