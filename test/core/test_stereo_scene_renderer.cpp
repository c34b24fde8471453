// Tests of the renderer of the procedural scene: exact ground truth (pixel <-> surface point
// round trips for every distortion model, pixels without a ray, occlusion, the exact ray cast),
// image properties the front end relies on (stereo patches agree, corners are plentiful,
// structures line a long drive), noise, exposure and blur, determinism, concurrency, and the
// render options' validation.
#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"
#include "stereo_scene_test_support.h"

namespace osc {
namespace {

/// EuRoC cam0's plumb_bob intrinsics (k2 keeps the distortion one-to-one over the image).
CameraModel euroc() {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = 458.654;
  in.fy = 457.296;
  in.cx = 367.215;
  in.cy = 248.375;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return CameraModel(in);
}

/// k1 = -0.28 alone: r_d = r (1 - 0.28 r^2) folds back beyond r = 1.09, so the image corners
/// (r_d up to 0.8) have no ray at all.
CameraModel strongBarrel() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 500.0;
  in.cx = 319.5;
  in.cy = 239.5;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28, 0.0, 0.0, 0.0, 0.0};
  return CameraModel(in);
}

CameraModel fisheye() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 260.0;
  in.cx = 321.0;
  in.cy = 238.0;
  in.model = DistortionModel::kEquidistant;
  in.distortion = {-0.013, 0.006, -0.002, 0.0004};
  return CameraModel(in);
}

CameraModel rational() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 420.0;
  in.cx = 318.0;
  in.cy = 242.0;
  in.model = DistortionModel::kRationalPolynomial;
  in.distortion = {-0.25, 0.06, 1e-4, -2e-4, 0.0, 0.05, 0.01, 0.0};
  return CameraModel(in);
}

TEST(RenderOptions, BadFieldsAreRejectedByName) {
  RenderOptions options;
  options.supersampling = 0;
  try {
    defaultRenderer().render(pinhole(), Eigen::Isometry3d::Identity(), options);
    ADD_FAILURE() << "supersampling 0 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("supersampling"), std::string::npos) << e.what();
  }
  options = RenderOptions();
  options.exposure_gain = 0.0;
  EXPECT_FALSE(options.validate().empty());
  options = RenderOptions();
  options.noise_sigma = -1.0;
  EXPECT_FALSE(options.validate().empty());
}

TEST(StereoSceneRenderer, ImageSizesAndTypes) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 0.0);
  RenderOptions options;
  const cv::Mat mono = r.render(pinhole(), T, options);
  EXPECT_EQ(mono.type(), CV_8UC1);
  EXPECT_EQ(mono.cols, 640);
  EXPECT_EQ(mono.rows, 480);
  options.color = true;
  const cv::Mat colour = r.render(pinhole(), T, options);
  EXPECT_EQ(colour.type(), CV_8UC3);
  EXPECT_EQ(colour.size(), mono.size());
  const cv::Mat large = r.render(pinhole(1280, 960, 1000.0), T, RenderOptions());
  EXPECT_EQ(large.type(), CV_8UC1);
  EXPECT_EQ(large.cols, 1280);
  EXPECT_EQ(large.rows, 960);
  // Colour and mono show the same scene: the grey conversion of one is close to the other.
  cv::Mat grey;
  cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
  EXPECT_LT(cv::norm(grey, mono, cv::NORM_L1) / mono.total(), 1.0);
  // A plausible exposure: neither black nor saturated.
  const double mean = cv::mean(mono)[0];
  EXPECT_GT(mean, 60.0);
  EXPECT_LT(mean, 200.0);
}

TEST(StereoSceneRenderer, DeterministicFromSeed) {
  const CameraModel cam = pinhole();
  const StereoSceneRenderer& a = defaultRenderer();
  const StereoSceneRenderer b{SceneConfig()};
  const Eigen::Isometry3d T = cameraPose(a.scene(), 3.0, -1.0, 0.4);
  const cv::Mat first = a.render(cam, T);
  EXPECT_EQ(cv::norm(first, a.render(cam, T), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first, b.render(cam, T), cv::NORM_INF), 0.0);
  SceneConfig other;
  other.seed = 8;
  const StereoSceneRenderer c(other);
  EXPECT_GT(cv::norm(first, c.render(cam, T), cv::NORM_L1) / first.total(), 10.0);
}

TEST(StereoSceneRenderer, NoiseIsSeededAndHasTheRequestedSigma) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 1.0);
  RenderOptions options;
  const cv::Mat clean = r.render(pinhole(), T, options);
  options.noise_sigma = 4.0;
  options.noise_seed = 3;
  const cv::Mat noisy = r.render(pinhole(), T, options);
  EXPECT_EQ(cv::norm(noisy, r.render(pinhole(), T, options), cv::NORM_INF), 0.0);
  options.noise_seed = 4;
  EXPECT_GT(cv::norm(noisy, r.render(pinhole(), T, options), cv::NORM_L1), 0.0);
  cv::Mat difference;
  cv::subtract(noisy, clean, difference, cv::noArray(), CV_32F);
  cv::Scalar mean, sigma;
  cv::meanStdDev(difference, mean, sigma);
  EXPECT_NEAR(sigma[0], 4.0, 0.4);  // a little below 4 where pixels saturate
  EXPECT_NEAR(mean[0], 0.0, 0.2);
}

TEST(StereoSceneRenderer, ExposureGainAndBlur) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 2.0);
  RenderOptions options;
  const cv::Mat normal = r.render(pinhole(), T, options);
  options.exposure_gain = 0.5;
  const cv::Mat dark = r.render(pinhole(), T, options);
  EXPECT_NEAR(cv::mean(dark)[0] / cv::mean(normal)[0], 0.5, 0.02);
  options = RenderOptions();
  options.blur_sigma = 1.5;
  const cv::Mat blurred = r.render(pinhole(), T, options);
  auto sharpness = [](const cv::Mat& image) {
    cv::Mat laplacian;
    cv::Laplacian(image, laplacian, CV_32F);
    return cv::norm(laplacian, cv::NORM_L2);
  };
  EXPECT_LT(sharpness(blurred), 0.5 * sharpness(normal));
}

TEST(StereoSceneRenderer, AdaptiveSupersamplingMatchesFullSupersampling) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, -0.5);
  RenderOptions options;
  const cv::Mat adaptive = r.render(pinhole(), T, options);
  options.supersample_all = true;
  const cv::Mat full = r.render(pinhole(), T, options);
  // The texture is filtered a little differently (mip levels against sub-samples), so
  // compare after removing the finest detail: edges and shading must agree.
  cv::Mat a, b;
  cv::GaussianBlur(adaptive, a, cv::Size(0, 0), 1.0);
  cv::GaussianBlur(full, b, cv::Size(0, 0), 1.0);
  EXPECT_LT(cv::norm(a, b, cv::NORM_L1) / a.total(), 1.2);
  EXPECT_LT(cv::norm(adaptive, full, cv::NORM_L1) / adaptive.total(), 4.0);
}

/// surfacePoint() then projectVisible() gives the pixel back, for many pixels of a camera.
void expectRoundTrips(const CameraModel& camera, double min_hit_fraction) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 1.0, 2.0, 0.3, 0.1);
  const CameraIntrinsics& in = camera.intrinsics();
  int pixels = 0, hits = 0, visible = 0;
  double worst = 0.0;
  for (double v = 0.3; v < in.height - 1; v += 9.0) {
    for (double u = 0.6; u < in.width - 1; u += 9.0) {
      ++pixels;
      const Eigen::Vector2d pixel(u, v);
      const std::optional<Eigen::Vector3d> p = r.surfacePoint(camera, T, pixel);
      if (!p) continue;
      ++hits;
      Eigen::Vector2d back;
      if (r.projectVisible(camera, T, *p, &back)) ++visible;
      worst = std::max(worst, (back - pixel).norm());
    }
  }
  EXPECT_GT(hits, min_hit_fraction * pixels) << distortionModelName(in.model);
  EXPECT_EQ(visible, hits) << distortionModelName(in.model);
  EXPECT_LT(worst, 1e-6) << distortionModelName(in.model);
}

TEST(StereoSceneRenderer, SurfacePointRoundTripsPinhole) { expectRoundTrips(pinhole(), 0.5); }
TEST(StereoSceneRenderer, SurfacePointRoundTripsPlumbBob) { expectRoundTrips(euroc(), 0.5); }
TEST(StereoSceneRenderer, SurfacePointRoundTripsStrongBarrel) {
  expectRoundTrips(strongBarrel(), 0.45);
}
TEST(StereoSceneRenderer, SurfacePointRoundTripsEquidistant) { expectRoundTrips(fisheye(), 0.5); }
TEST(StereoSceneRenderer, SurfacePointRoundTripsRationalPolynomial) {
  expectRoundTrips(rational(), 0.5);
}

TEST(StereoSceneRenderer, PixelsWithoutARayAreBlackAndHaveNoSurfacePoint) {
  // With k1 = -0.28 alone no ray reaches the image corners.
  const StereoSceneRenderer& r = defaultRenderer();
  const CameraModel camera = strongBarrel();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 0.0);
  EXPECT_FALSE(r.surfacePoint(camera, T, Eigen::Vector2d(2.0, 2.0)));
  const cv::Mat image = r.render(camera, T);
  EXPECT_EQ(image.at<std::uint8_t>(0, 0), 0);
  EXPECT_EQ(image.at<std::uint8_t>(479, 639), 0);
  EXPECT_GT(image.at<std::uint8_t>(240, 320), 0);
  // A point far off-axis lands inside the image through the fold: not visible.
  Eigen::Vector2d pixel;
  const Eigen::Vector3d p_optical(1.6, 0.0, 1.0);  // r = 1.6: r_d = 0.45, inside the image
  const Eigen::Vector3d p_world = T * p_optical;
  ASSERT_TRUE(camera.project(p_optical, &pixel));
  ASSERT_TRUE(camera.isInImage(pixel));
  EXPECT_FALSE(r.projectVisible(camera, T, p_world, &pixel));
}

TEST(StereoSceneRenderer, OcclusionBehindAWall) {
  SceneConfig config;
  config.generate_structures = false;
  ScenePrimitive wall;
  wall.shape = ScenePrimitive::Shape::kBox;
  wall.position = Eigen::Vector3d(10.0, 0.0, -1.0);
  wall.size = Eigen::Vector3d(0.5, 6.0, 5.0);
  config.extra_primitives.push_back(wall);
  const StereoSceneRenderer r(config);
  const CameraModel camera = pinhole();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 0.0, 0.0);
  Eigen::Vector2d pixel(-1.0, -1.0);
  // Behind the wall: projects into the image but is hidden.
  EXPECT_FALSE(r.projectVisible(camera, T, Eigen::Vector3d(20.0, 0.5, 1.2), &pixel));
  EXPECT_TRUE(camera.isInImage(pixel));
  // On the wall's front face: visible, and the ray through its pixel ends there.
  const Eigen::Vector3d on_wall(9.75, 0.5, 1.2);
  ASSERT_TRUE(r.projectVisible(camera, T, on_wall, &pixel));
  const std::optional<Eigen::Vector3d> seen = r.surfacePoint(camera, T, pixel);
  ASSERT_TRUE(seen);
  EXPECT_LT((*seen - on_wall).norm(), 1e-9);
  // Beside the wall the far point is visible.
  EXPECT_TRUE(r.projectVisible(camera, T, Eigen::Vector3d(20.0, 8.0, 1.2), &pixel));
  // Behind the camera and outside the field of view: not visible.
  EXPECT_FALSE(r.projectVisible(camera, T, Eigen::Vector3d(-5.0, 0.0, 1.2), &pixel));
  EXPECT_FALSE(r.projectVisible(camera, T, Eigen::Vector3d(10.0, 30.0, 1.2), &pixel));
  // Below the ground.
  EXPECT_FALSE(r.projectVisible(camera, T, Eigen::Vector3d(6.0, -3.0, -1.0), &pixel));
}

// The renderer culls primitives per image tile; a wall running past the camera (from behind
// it to far ahead, crossing its image plane) must still appear exactly where the exact ray
// cast of surfacePoint() sees it.
TEST(StereoSceneRenderer, RenderedSurfacesMatchTheExactRayCast) {
  SceneConfig config;
  config.generate_structures = false;
  ScenePrimitive wall;
  wall.shape = ScenePrimitive::Shape::kBox;
  wall.position = Eigen::Vector3d(5.0, 3.0, -1.0);
  wall.size = Eigen::Vector3d(30.0, 0.3, 4.0);  // x from -10 to 20, inner face at y = 2.85
  wall.tint = Eigen::Vector3f(0.9f, 0.05f, 0.05f);
  config.extra_primitives.push_back(wall);
  const StereoSceneRenderer r(config);
  const CameraModel camera = euroc();
  const Eigen::Isometry3d T = cameraPose(r.scene(), 0.0, 0.0, 0.3, 0.0);
  RenderOptions options;
  options.color = true;
  const cv::Mat image = r.render(camera, T, options);
  auto on_wall = [&](int u, int v) {
    const std::optional<Eigen::Vector3d> p = r.surfacePoint(camera, T, Eigen::Vector2d(u, v));
    return p && p->y() > 2.85 - 1e-6 && p->y() < 3.15 + 1e-6 &&
           std::abs(p->x() - 5.0) < 15.0 + 1e-6;
  };
  int wall_pixels = 0, other_pixels = 0;
  for (int v = 5; v < image.rows - 5; v += 6) {
    for (int u = 5; u < image.cols - 5; u += 6) {
      const bool wall_here = on_wall(u, v);
      // Skip pixels next to the wall's outline (they mix both).
      if (on_wall(u - 1, v) != wall_here || on_wall(u + 1, v) != wall_here ||
          on_wall(u, v - 1) != wall_here || on_wall(u, v + 1) != wall_here) {
        continue;
      }
      const cv::Vec3b bgr = image.at<cv::Vec3b>(v, u);
      if (wall_here) {
        ++wall_pixels;
        EXPECT_TRUE(bgr[2] >= 2 * bgr[1] && bgr[2] > bgr[1]) << "wall missing at " << u << "," << v;
      } else {
        ++other_pixels;
        EXPECT_LT(bgr[2], 1.5 * bgr[1] + 5) << "wall wrongly at " << u << "," << v;
      }
    }
  }
  EXPECT_GT(wall_pixels, 500);
  EXPECT_GT(other_pixels, 500);
}

double ncc(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat result;
  cv::matchTemplate(a, b, result, cv::TM_CCOEFF_NORMED);
  return result.at<float>(0, 0);
}

TEST(StereoSceneRenderer, StereoPatchesAgreeAtTrueCorrespondences) {
  const StereoSceneRenderer& r = defaultRenderer();
  const CameraModel camera = pinhole();
  const Eigen::Isometry3d left = cameraPose(r.scene(), 0.0, 0.0, 0.2);
  const Eigen::Isometry3d right = rightOf(left);
  const cv::Mat left_image = r.render(camera, left), right_image = r.render(camera, right);
  std::vector<cv::KeyPoint> corners;
  cv::FAST(left_image, corners, 20, true);
  ASSERT_GT(corners.size(), 200u);
  const cv::Size patch(11, 11);
  const cv::Rect2f inside(8.0f, 8.0f, 640.0f - 16.0f, 480.0f - 16.0f);
  std::vector<double> correct, shifted;
  int seen = 0, visible = 0;
  for (const cv::KeyPoint& k : corners) {
    const std::optional<Eigen::Vector3d> p =
        r.surfacePoint(camera, left, Eigen::Vector2d(k.pt.x, k.pt.y));
    if (!p) continue;
    ++seen;
    Eigen::Vector2d q;
    if (!r.projectVisible(camera, right, *p, &q)) continue;
    ++visible;
    const cv::Point2f pr(static_cast<float>(q.x()), static_cast<float>(q.y()));
    const cv::Point2f wrong = pr + cv::Point2f(10.0f, 0.0f);  // along the epipolar line
    if (!inside.contains(k.pt) || !inside.contains(pr) || !inside.contains(wrong)) continue;
    cv::Mat a, b, c;
    cv::getRectSubPix(left_image, patch, k.pt, a, CV_32F);
    cv::getRectSubPix(right_image, patch, pr, b, CV_32F);
    cv::getRectSubPix(right_image, patch, wrong, c, CV_32F);
    correct.push_back(ncc(a, b));
    shifted.push_back(ncc(a, c));
  }
  ASSERT_GT(correct.size(), 150u);
  EXPECT_GT(visible, 0.8 * seen);  // only occlusion by a near structure hides a point
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const double good = static_cast<double>(std::count_if(correct.begin(), correct.end(),
                                                        [](double x) { return x > 0.8; })) /
                      static_cast<double>(correct.size());
  EXPECT_GT(median(correct), 0.9);
  EXPECT_GT(good, 0.85);
  EXPECT_LT(median(shifted), 0.4);
}

TEST(StereoSceneRenderer, TexturesAreRichInCorners) {
  const StereoSceneRenderer& r = defaultRenderer();
  const cv::Mat image = r.render(pinhole(), cameraPose(r.scene(), 0.0, 0.0, 0.0));
  std::vector<cv::KeyPoint> fast, orb;
  cv::FAST(image, fast, 20, true);
  EXPECT_GE(fast.size(), 300u);
  cv::ORB::create(1000)->detect(image, orb);
  EXPECT_GE(orb.size(), 300u);
}

/// A 5.25 km drive (1500 frames at 3.5 m/s and 10 Hz) that turns both ways.
std::vector<Eigen::Vector2d> longDrive() {
  std::vector<Eigen::Vector2d> path{Eigen::Vector2d::Zero()};
  double heading = 0.0;
  for (int k = 1; k <= 1500; ++k) {
    const double s = 3.5 * k;
    heading = 0.9 * std::sin(s / 700.0) + 0.4 * std::sin(s / 230.0);
    path.push_back(path.back() + 3.5 * Eigen::Vector2d(std::cos(heading), std::sin(heading)));
  }
  return path;
}

double footprintRadius(const ScenePrimitive& p) {
  return p.shape == ScenePrimitive::Shape::kBox ? 0.5 * std::hypot(p.size.x(), p.size.y())
                                                : p.size.x();
}

TEST(StereoSceneRenderer, StructuresLineALongDriveAndKeepClearOfIt) {
  SceneConfig config;
  config.path = longDrive();
  const StereoSceneRenderer r(config);
  const ProceduralScene& scene = r.scene();
  ASSERT_GT(scene.primitives().size(), 1000u);
  for (const ScenePrimitive& p : scene.primitives()) {
    const double distance = scene.distanceToPath(p.position.head<2>());
    EXPECT_GE(distance - footprintRadius(p), config.min_structure_distance - 1e-9);
    EXPECT_LE(distance, config.max_structure_distance + 1e-9);
  }
  // Every 500 m there are structures near the path, and the view along it is rich.
  for (size_t k = 0; k < config.path.size(); k += 143) {
    const Eigen::Vector2d& at = config.path[k];
    const long near = std::count_if(
        scene.primitives().begin(), scene.primitives().end(),
        [&](const ScenePrimitive& p) { return (p.position.head<2>() - at).norm() < 60.0; });
    EXPECT_GT(near, 10) << "at path point " << k;
  }
  const size_t k = 1200;
  const Eigen::Vector2d heading = (config.path[k + 1] - config.path[k]).normalized();
  const cv::Mat image =
      r.render(pinhole(), cameraPose(scene, config.path[k].x(), config.path[k].y(),
                                     std::atan2(heading.y(), heading.x())));
  std::vector<cv::KeyPoint> fast;
  cv::FAST(image, fast, 20, true);
  EXPECT_GE(fast.size(), 300u);
}

TEST(StereoSceneRenderer, ConcurrentRendersAgreeWithSequentialOnes) {
  const StereoSceneRenderer& r = defaultRenderer();
  const Eigen::Isometry3d left = cameraPose(r.scene(), 0.0, 0.0, 0.7);
  const cv::Mat expected_left = r.render(euroc(), left),
                expected_right = r.render(euroc(), rightOf(left));
  cv::Mat got_left, got_right;
  std::thread a([&] { got_left = r.render(euroc(), left); });
  std::thread b([&] { got_right = r.render(euroc(), rightOf(left)); });
  a.join();
  b.join();
  EXPECT_EQ(cv::norm(expected_left, got_left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(expected_right, got_right, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace osc
