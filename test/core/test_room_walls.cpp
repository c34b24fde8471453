// The room of an indoor drive (room_walls.h): four walls whose inner faces stand the margin
// beyond the path's bounding box, closed at the corners, as seen by rays of the scene.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/sim/procedural_scene.h"
#include "online_stereo_calibration/core/sim/room_walls.h"

namespace osc {
namespace {

ProceduralScene roomScene(const std::vector<Eigen::Vector2d>& path, double margin, double height) {
  SceneConfig config;
  config.ground_undulation = 0.0;
  config.generate_structures = false;
  config.path = path;
  config.extra_primitives = roomWalls(path, margin, height, config.seed);
  return ProceduralScene(config);
}

TEST(RoomWalls, InnerFacesStandTheMarginBeyondThePath) {
  const std::vector<Eigen::Vector2d> path = {{-2.0, -1.0}, {0.5, 3.0}, {2.0, 0.0}};
  const double margin = 1.5, height = 3.0;
  const ProceduralScene scene = roomScene(path, margin, height);
  ASSERT_EQ(scene.primitives().size(), 4u);
  const Eigen::Vector3d origin(0.0, 0.5, 1.2);
  // Bounding box x in [-2, 2], y in [-1, 3]: inner faces at x = -3.5, 3.5, y = -2.5, 4.5.
  const struct {
    Eigen::Vector3d direction;
    double distance;
  } rays[] = {{{1, 0, 0}, 3.5}, {{-1, 0, 0}, 3.5}, {{0, 1, 0}, 4.0}, {{0, -1, 0}, 3.0}};
  for (const auto& ray : rays) {
    SceneHit hit;
    ASSERT_TRUE(scene.intersect(origin, ray.direction, 1e3, &hit)) << ray.direction.transpose();
    EXPECT_EQ(hit.surface, SceneHit::Surface::kStructure) << ray.direction.transpose();
    EXPECT_NEAR(hit.distance, ray.distance, 1e-6) << ray.direction.transpose();
  }
  // Above the walls the ray leaves the room; towards a corner it hits a wall (no gap).
  SceneHit hit;
  if (scene.intersect(origin, Eigen::Vector3d(1, 0, 2).normalized(), 1e3, &hit)) {
    EXPECT_NE(hit.surface, SceneHit::Surface::kStructure);  // the backdrop, else the sky
  }
  const Eigen::Vector3d corner = Eigen::Vector3d(3.5, 4.5, 1.2) - origin;
  ASSERT_TRUE(scene.intersect(origin, corner.normalized(), 1e3, &hit));
  EXPECT_EQ(hit.surface, SceneHit::Surface::kStructure);
  EXPECT_NEAR(hit.distance, corner.norm(), 0.3);
}

TEST(RoomWalls, WallsAreTexturedDifferently) {
  const std::vector<ScenePrimitive> walls = roomWalls({}, 2.0, 4.0, 7);
  ASSERT_EQ(walls.size(), 4u);
  for (int a = 0; a < 4; ++a) {
    EXPECT_EQ(walls[a].shape, ScenePrimitive::Shape::kBox);
    EXPECT_DOUBLE_EQ(walls[a].size.z(), 4.0);
    for (int b = a + 1; b < 4; ++b) EXPECT_NE(walls[a].texture_seed, walls[b].texture_seed);
  }
}

}  // namespace
}  // namespace osc
