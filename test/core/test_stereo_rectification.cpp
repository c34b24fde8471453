// Tests of the stereo rectification from the left->right estimate (core/geometry/
// stereo_rectification.h): R and P as CameraInfo carries them, the rectification error of
// stereo pairs against the renderer's exact truth, and the depth uncertainty from the
// covariance against a hand computation and a Monte-Carlo.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/stereo_rectification.h"
#include "online_stereo_calibration/core/pipeline/live_rectification.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// EuRoC cam0's plumb_bob intrinsics; the right camera slightly different.
CameraIntrinsics euroc(bool right) {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = right ? 457.587 : 458.654;
  in.fy = right ? 456.134 : 457.296;
  in.cx = right ? 379.999 : 367.215;
  in.cy = right ? 255.238 : 248.375;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = right ? std::vector<double>{-0.28368365, 0.07451284, -0.00010473, -3.5559e-05}
                        : std::vector<double>{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return in;
}

/// A rig 0.5 m wide, its right camera a little off every axis (body frame, pose.h).
StereoExtrinsics trueRig() {
  Vector12d p;
  p << 1.5, 0.2, 1.4, 0.0, 0.05, 0.0,  //
      0.02, -0.5, 0.01, 0.3 * kDeg, -0.4 * kDeg, 0.5 * kDeg;
  return StereoExtrinsics::fromParameters(p);
}

/// Exact stereo pairs from the renderer's scene: the surface point behind each pixel of a
/// grid in the left image, projected into the right camera where it is visible there.
std::vector<StereoObservation> renderedTruePairs(const StereoExtrinsics& rig) {
  static const StereoSceneRenderer renderer{SceneConfig()};
  const CameraModel left(euroc(false)), right(euroc(true));
  const ProceduralScene& scene = renderer.scene();
  Vector6d body;
  body << 0.0, 0.0, scene.groundHeight(0.0, 0.0) + 1.5, 0.0, 0.05, 0.3;
  const Eigen::Isometry3d T_world_lopt = poseFromParameters(body) * bodyFromOptical();
  const Eigen::Isometry3d T_world_ropt = T_world_lopt * rig.leftToRightOptical();
  std::vector<StereoObservation> pairs;
  for (double v = 5.3; v < 475.0; v += 17.0) {
    for (double u = 5.7; u < 747.0; u += 17.0) {
      const Eigen::Vector2d left_pixel(u, v);
      const std::optional<Eigen::Vector3d> p =
          renderer.surfacePoint(left, T_world_lopt, left_pixel);
      Eigen::Vector2d right_pixel;
      if (!p || !renderer.projectVisible(right, T_world_ropt, *p, &right_pixel)) continue;
      StereoObservation pair;
      pair.left_pixel = left_pixel;
      pair.right_pixel = right_pixel;
      pairs.push_back(pair);
    }
  }
  return pairs;
}

TEST(StereoRectification, RAndPHaveTheCameraInfoForm) {
  const StereoExtrinsics rig = trueRig();
  const Eigen::Isometry3d T_lopt_ropt = rig.leftToRightOptical();
  RectificationSettings settings;
  settings.alpha = 0.0;
  const StereoRectification r =
      computeStereoRectification(euroc(false), euroc(true), T_lopt_ropt, settings);
  EXPECT_EQ(r.width, 752);
  EXPECT_EQ(r.height, 480);
  EXPECT_LT((r.R_left.transpose() * r.R_left - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((r.R_right.transpose() * r.R_right - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(r.R_left.determinant(), 1.0, 1e-12);
  // The baseline (the right camera's centre in the left optical frame) lies along the
  // rectified x axis, and P_right(0,3) = -f * baseline.
  const Eigen::Vector3d baseline_rect = r.R_left * T_lopt_ropt.translation();
  EXPECT_NEAR(baseline_rect.x(), T_lopt_ropt.translation().norm(), 1e-12);
  EXPECT_NEAR(baseline_rect.tail<2>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(-r.P_right(0, 3) / r.P_right(0, 0), T_lopt_ropt.translation().norm(), 1e-9);
  EXPECT_DOUBLE_EQ(r.P_left(0, 0), r.P_right(0, 0));
  EXPECT_DOUBLE_EQ(r.P_left(1, 2), r.P_right(1, 2));
  EXPECT_DOUBLE_EQ(r.P_left(0, 3), 0.0);
  // Both rotations map into one rectified frame: R_right * R_ropt_lopt == R_left.
  const Eigen::Matrix3d R_ropt_lopt = T_lopt_ropt.linear().transpose();
  EXPECT_LT((r.R_right * R_ropt_lopt - r.R_left).norm(), 1e-9);
  // Output size and alpha are passed on: alpha 1 keeps every pixel (a smaller focal length).
  settings.alpha = 1.0;
  settings.width = 640;
  settings.height = 400;
  const StereoRectification wide =
      computeStereoRectification(euroc(false), euroc(true), T_lopt_ropt, settings);
  EXPECT_EQ(wide.width, 640);
  EXPECT_EQ(wide.height, 400);
  EXPECT_LT(wide.P_left(0, 0), r.P_left(0, 0));
}

TEST(StereoRectification, RefusesBadInputByName) {
  const Eigen::Isometry3d T = trueRig().leftToRightOptical();
  RectificationSettings settings;
  settings.alpha = 1.5;
  EXPECT_THROW(computeStereoRectification(euroc(false), euroc(true), T, settings),
               std::invalid_argument);
  settings.alpha = 0.0;
  EXPECT_THROW(computeStereoRectification(euroc(false), euroc(true), Eigen::Isometry3d::Identity(),
                                          settings),
               std::invalid_argument);
  CameraIntrinsics pinhole = euroc(true);
  pinhole.model = DistortionModel::kNone;
  pinhole.distortion.clear();
  EXPECT_THROW(computeStereoRectification(euroc(false), pinhole, T, settings),
               std::invalid_argument);
  CameraIntrinsics bad = euroc(false);
  bad.fx = 0.0;
  EXPECT_THROW(computeStereoRectification(bad, euroc(true), T, settings), std::invalid_argument);
  EXPECT_THROW(depthSigmaOnAxis(trueRig(), Matrix12d::Identity() * 1e-8, -1.0),
               std::invalid_argument);
}

// The renderer's exact pairs, rectified with the true left->right transform, lie on one
// row; rectified with a right camera pitched by 0.5 deg they lie f * tan(0.5 deg) apart.
TEST(StereoRectification, ErrorOfTheRenderersPairsAgainstTheTruth) {
  const StereoExtrinsics truth = trueRig();
  const std::vector<StereoObservation> pairs = renderedTruePairs(truth);
  ASSERT_GT(pairs.size(), 300u);
  const CameraModel left(euroc(false)), right(euroc(true));
  const RectificationSettings settings;
  const StereoRectification exact =
      computeStereoRectification(euroc(false), euroc(true), truth.leftToRightOptical(), settings);
  const std::optional<RectificationError> at_truth = rectificationError(pairs, left, right, exact);
  ASSERT_TRUE(at_truth);
  EXPECT_EQ(at_truth->pairs, static_cast<int>(pairs.size()));
  EXPECT_LT(at_truth->median_px, 1e-6);

  // The estimate's right camera pitched by 0.5 deg about its body y axis (optical -x).
  const double pitch = 0.5 * kDeg;
  Vector12d p = truth.toParameters();
  p(10) += pitch;
  const StereoExtrinsics off = StereoExtrinsics::fromParameters(p);
  const StereoRectification wrong =
      computeStereoRectification(euroc(false), euroc(true), off.leftToRightOptical(), settings);
  const std::optional<RectificationError> at_off = rectificationError(pairs, left, right, wrong);
  ASSERT_TRUE(at_off);
  const double expected = wrong.P_left(1, 1) * std::tan(pitch);
  EXPECT_NEAR(at_off->median_px, expected, 0.05 * expected);
  // How far the rectified images move: the same 0.5 deg times the focal length.
  const double pitch_angle = Eigen::AngleAxisd(truth.leftToRightOptical().linear().transpose() *
                                               off.leftToRightOptical().linear())
                                 .angle();
  EXPECT_NEAR(rectificationChangePx(exact, off.leftToRightOptical()),
              exact.P_left(0, 0) * pitch_angle, 1e-6);
  EXPECT_NEAR(rectificationChangePx(exact, truth.leftToRightOptical()), 0.0, 1e-6);
  // No pairs: no figure (not a 0 that looks perfect).
  EXPECT_FALSE(rectificationError({}, left, right, exact));
}

Matrix12d camrCovariance(double sigma_t, double sigma_r, double correlation) {
  Matrix12d c = Matrix12d::Zero();
  c.topLeftCorner<6, 6>() = Matrix6d::Identity() * 0.01;  // a loose x_caml: must not matter
  Vector6d s;
  s << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      c(6 + i, 6 + j) = s(i) * s(j) * (i == j ? 1.0 : correlation);
    }
  }
  return c;
}

// Only the yaw of the right camera: its ray to the point meets the axis at the angle phi with
// tan(phi) = b / Z, so Z = b / tan(phi) and dZ = (Z^2 / b + b) * dyaw (first order).
TEST(DepthSigma, YawAloneGivesZSquaredOverBaseline) {
  StereoExtrinsics rig;
  rig.T_caml_camr.translation() = Eigen::Vector3d(0.0, -0.5, 0.0);
  Matrix12d c = Matrix12d::Zero();
  const double sigma_yaw = 0.01 * kDeg;
  c(11, 11) = sigma_yaw * sigma_yaw;
  for (double depth : {10.0, 50.0}) {
    const double expected = (depth * depth / 0.5 + 0.5) * sigma_yaw;
    EXPECT_NEAR(depthSigmaOnAxis(rig, c, depth), expected, 1e-5 * expected) << depth;
  }
  // x_caml's covariance changes nothing.
  c.topLeftCorner<6, 6>() = Matrix6d::Identity();
  EXPECT_NEAR(depthSigmaOnAxis(rig, c, 50.0), 5000.5 * sigma_yaw, 1e-5 * 5000.5 * sigma_yaw);
}

// First-order propagation against a seeded Monte-Carlo of the full (correlated) x_camr
// covariance, at 10 m and 50 m.
TEST(DepthSigma, FirstOrderMatchesAMonteCarloOfTheCovariance) {
  const StereoExtrinsics rig = trueRig();
  const Matrix12d covariance = camrCovariance(1e-3, 0.01 * kDeg, 0.3);
  const Eigen::LLT<Matrix6d> llt(covariance.block<6, 6>(6, 6));
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Matrix6d L = llt.matrixL();
  std::mt19937 rng(42);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (double depth : {10.0, 50.0}) {
    const double linear = depthSigmaOnAxis(rig, covariance, depth);
    const int samples = 20000;
    double sum = 0.0, sum_sq = 0.0;
    int used = 0;
    for (int k = 0; k < samples; ++k) {
      Vector6d z;
      for (int i = 0; i < 6; ++i) z(i) = normal(rng);
      const std::optional<double> d = depthOnAxisWithPerturbedCamr(rig, L * z, depth);
      if (!d) continue;
      ++used;
      sum += *d;
      sum_sq += *d * *d;
    }
    ASSERT_EQ(used, samples) << depth;
    const double mean = sum / used;
    const double monte_carlo = std::sqrt(std::max(0.0, sum_sq / used - mean * mean));
    // 20000 samples estimate a sigma to ~0.5 %; the depth is slightly non-linear at 50 m.
    EXPECT_NEAR(linear, monte_carlo, 0.03 * monte_carlo) << depth << " m";
    EXPECT_GT(linear, 0.0);
  }
  // Grows with the square of the distance (the yaw term dominates).
  EXPECT_GT(depthSigmaOnAxis(rig, covariance, 50.0),
            20.0 * depthSigmaOnAxis(rig, covariance, 10.0));
}

// R and P follow the estimate only when it moved the rectified images by more than the
// threshold, or the cameras changed.
TEST(LiveRectification, RecomputesOnlyWhenTheEstimateMovedEnough) {
  const double update_px = 0.2;
  LiveRectification live(RectificationSettings(), update_px);
  EXPECT_FALSE(live.rectification());
  StereoExtrinsics rig = trueRig();
  EXPECT_TRUE(live.update(euroc(false), euroc(true), rig));
  ASSERT_TRUE(live.rectification());
  const double focal = live.rectification()->P_left(0, 0);
  // A yaw of 0.1 px: kept. Another 0.15 px on top (0.25 px from the published one): redone.
  Vector12d p = rig.toParameters();
  p(11) += 0.1 / focal;
  EXPECT_FALSE(live.update(euroc(false), euroc(true), StereoExtrinsics::fromParameters(p)));
  p(11) += 0.15 / focal;
  EXPECT_TRUE(live.update(euroc(false), euroc(true), StereoExtrinsics::fromParameters(p)));
  EXPECT_LT((live.rectification()->T_lopt_ropt.linear() -
             StereoExtrinsics::fromParameters(p).leftToRightOptical().linear())
                .norm(),
            1e-12);
  CameraIntrinsics other = euroc(true);
  other.cx += 1.0;
  EXPECT_TRUE(live.update(euroc(false), other, StereoExtrinsics::fromParameters(p)));
  EXPECT_THROW(LiveRectification(RectificationSettings(), -1.0), std::invalid_argument);
  RectificationSettings bad;
  bad.alpha = 2.0;
  EXPECT_THROW(LiveRectification(bad, 0.1), std::invalid_argument);
}

// The quality figures of an estimate: the renderer's pairs and the covariance as above.
TEST(LiveRectification, QualityOfAnEstimate) {
  const StereoExtrinsics truth = trueRig();
  const std::vector<StereoObservation> pairs = renderedTruePairs(truth);
  const LiveRectification live(RectificationSettings(), 0.1);
  CalibrationEstimate estimate;
  estimate.extrinsics = truth;
  estimate.tangent_covariance = camrCovariance(1e-3, 0.01 * kDeg, 0.3);
  const CalibrationQuality q = live.quality(euroc(false), euroc(true), pairs, estimate);
  ASSERT_TRUE(q.rectification_error);
  EXPECT_LT(q.rectification_error->median_px, 1e-6);
  EXPECT_EQ(q.depth_sigma_10m, depthSigmaOnAxis(truth, estimate.tangent_covariance, 10.0));
  EXPECT_EQ(q.depth_sigma_50m, depthSigmaOnAxis(truth, estimate.tangent_covariance, 50.0));
  EXPECT_FALSE(live.quality(euroc(false), euroc(true), {}, estimate).rectification_error);
}

}  // namespace
}  // namespace osc
