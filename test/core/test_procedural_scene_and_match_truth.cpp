// Tests of the procedural scene (its configuration's validation, ground hits on the height
// field, backdrop and sky) and of the stereo-match truth the front end's tests are scored with
// (exact pairs, pairs within the tolerance, wrong pairs).
#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"
#include "stereo_scene_test_support.h"

namespace osc {
namespace {

constexpr double kPi = 3.14159265358979323846;

void expectRejected(const SceneConfig& config, const std::string& field) {
  try {
    const ProceduralScene scene(config);
    ADD_FAILURE() << "config with a bad " << field << " was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(SceneConfig, DefaultIsValid) { EXPECT_TRUE(SceneConfig().validate().empty()); }

TEST(SceneConfig, BadFieldsAreRejectedByName) {
  SceneConfig c;
  c.structure_density = -1.0;
  expectRejected(c, "structure_density");
  c = SceneConfig();
  c.ground_undulation = std::nan("");
  expectRejected(c, "ground_undulation");
  c = SceneConfig();
  c.min_structure_distance = 90.0;
  expectRejected(c, "max_structure_distance");
  c = SceneConfig();
  c.backdrop_distance = 50.0;
  expectRejected(c, "backdrop_distance");
  c = SceneConfig();
  c.path = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(std::nan(""), 1.0)};
  expectRejected(c, "path");
  c = SceneConfig();
  c.path = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(30000.0, 0.0)};
  expectRejected(c, "path");
  c = SceneConfig();
  c.extra_primitives.emplace_back();
  c.extra_primitives.back().size.x() = -1.0;
  expectRejected(c, "extra_primitives[0]");
  c = SceneConfig();
  c.ambient = 2.0;
  expectRejected(c, "ambient");
}

TEST(StereoMatchTruth, ExactPairsPairsWithinTheToleranceAndWrongPairs) {
  const StereoSceneRenderer& r = defaultRenderer();
  const CameraModel camera = pinhole();
  const Eigen::Isometry3d left = cameraPose(r.scene(), 0.0, 0.0, 0.2);
  const Eigen::Isometry3d right = rightOf(left);
  const double tolerance = 1.5;
  int checked = 0;
  for (const Eigen::Vector2d& l :
       {Eigen::Vector2d(320, 400), Eigen::Vector2d(200, 350), Eigen::Vector2d(450, 300)}) {
    const std::optional<Eigen::Vector3d> p = r.surfacePoint(camera, left, l);
    Eigen::Vector2d q;
    if (!p || !r.projectVisible(camera, right, *p, &q)) continue;
    ++checked;
    // The true pair: the exact surface point.
    const StereoMatchTruth exact =
        checkStereoMatch(r, camera, camera, left, right, l, q, tolerance);
    EXPECT_TRUE(exact.at_pixel);
    ASSERT_TRUE(exact.point.has_value());
    EXPECT_LT((*exact.point - *p).norm(), 1e-6);
    // Both pixels 1.2 px off, in opposite directions: the surface at the left pixel projects
    // ~2.4 px from the right one, but p is within 1.2 px of both: correct, not at the pixel.
    const Eigen::Vector2d off(1.2, 0.0);
    const StereoMatchTruth near =
        checkStereoMatch(r, camera, camera, left, right, l + off, q - off, tolerance);
    EXPECT_FALSE(near.at_pixel);
    EXPECT_TRUE(near.point.has_value());
    EXPECT_FALSE(
        scenePointsOfStereoMatch(r, camera, camera, left, right, l + off, q - off, tolerance)
            .empty());
    // 2.5 px off each way: no scene point explains the pair.
    const Eigen::Vector2d far(2.5, 0.0);
    EXPECT_FALSE(
        checkStereoMatch(r, camera, camera, left, right, l + far, q - far, tolerance).point);
    EXPECT_TRUE(
        scenePointsOfStereoMatch(r, camera, camera, left, right, l + far, q - far, tolerance)
            .empty());
  }
  EXPECT_GE(checked, 2);
}

TEST(ProceduralScene, GroundHitsLieOnTheHeightField) {
  const ProceduralScene& scene = defaultRenderer().scene();
  const Eigen::Vector3d origin(3.0, 4.0, scene.groundHeight(3.0, 4.0) + 1.5);
  int ground_hits = 0;
  double lowest = 0.0, highest = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double azimuth = 0.0031 * k * 2.0 * kPi, depression = 0.02 + 0.0007 * k;
    const Eigen::Vector3d d(std::cos(azimuth) * std::cos(depression),
                            std::sin(azimuth) * std::cos(depression), -std::sin(depression));
    SceneHit hit;
    if (!scene.intersect(origin, d, 1e9, &hit) || hit.surface != SceneHit::Surface::kGround)
      continue;
    ++ground_hits;
    EXPECT_NEAR(hit.point.z(), scene.groundHeight(hit.point.x(), hit.point.y()), 1e-9);
    EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-6);
    EXPECT_GT(hit.normal.z(), 0.95);  // gentle slopes
    lowest = std::min(lowest, hit.point.z());
    highest = std::max(highest, hit.point.z());
  }
  EXPECT_GT(ground_hits, 1000);
  EXPECT_GE(lowest, -SceneConfig().ground_undulation - 1e-9);
  EXPECT_LE(highest, SceneConfig().ground_undulation + 1e-9);
  EXPECT_GT(highest - lowest, 0.1);  // it does undulate
}

TEST(ProceduralScene, BackdropAndSky) {
  SceneConfig config;
  config.generate_structures = false;
  const ProceduralScene scene(config);
  const Eigen::Vector3d circle = scene.backdropCircle();
  EXPECT_NEAR(circle.z(), config.backdrop_distance, 1e-9);  // path = the origin
  const Eigen::Vector3d origin(0.0, 0.0, 1.5);
  SceneHit hit;
  // Just above the horizon: the backdrop wall, backdrop_distance away.
  ASSERT_TRUE(
      scene.intersect(origin, Eigen::Vector3d(std::cos(0.01), 0.0, std::sin(0.01)), 1e9, &hit));
  EXPECT_EQ(hit.surface, SceneHit::Surface::kBackdrop);
  EXPECT_NEAR(hit.point.head<2>().norm(), config.backdrop_distance, 1e-6);
  // Steeply up: the sky (no surface point).
  EXPECT_FALSE(scene.intersect(origin, Eigen::Vector3d(0.6, 0.0, 0.8), 1e9, &hit));
}

}  // namespace
}  // namespace osc
