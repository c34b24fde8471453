#include "online_stereo_calibration/core/sim/room_walls.h"

#include <cmath>

namespace osc {

std::vector<ScenePrimitive> roomWalls(const std::vector<Eigen::Vector2d>& path, double margin,
                                      double height, unsigned seed) {
  constexpr double kThickness = 0.2;
  Eigen::Vector2d low = Eigen::Vector2d::Zero(), high = Eigen::Vector2d::Zero();
  if (!path.empty()) {
    low = high = path.front();
    for (const Eigen::Vector2d& p : path) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  low.array() -= margin;
  high.array() += margin;
  const Eigen::Vector2d centre = 0.5 * (low + high);
  const Eigen::Vector2d inner = high - low;  // inner extent along x and y
  std::vector<ScenePrimitive> walls;
  // x = low / high walls span y (yawed 90 deg), y = low / high walls span x; each overlaps the
  // corners so no gap opens between them.
  const double half = 0.5 * kThickness;
  const struct {
    Eigen::Vector2d position;
    double length;
    double yaw;
  } sides[] = {
      {{low.x() - half, centre.y()}, inner.y() + 2.0 * kThickness, M_PI / 2.0},
      {{high.x() + half, centre.y()}, inner.y() + 2.0 * kThickness, M_PI / 2.0},
      {{centre.x(), low.y() - half}, inner.x() + 2.0 * kThickness, 0.0},
      {{centre.x(), high.y() + half}, inner.x() + 2.0 * kThickness, 0.0},
  };
  for (int k = 0; k < 4; ++k) {
    ScenePrimitive wall;
    wall.shape = ScenePrimitive::Shape::kBox;
    wall.position = Eigen::Vector3d(sides[k].position.x(), sides[k].position.y(), 0.0);
    wall.size = Eigen::Vector3d(sides[k].length, kThickness, height);
    wall.yaw = sides[k].yaw;
    wall.tint = Eigen::Vector3f::Constant(0.55f + 0.05f * static_cast<float>(k));
    wall.texture_seed = seed * 7919u + 101u * static_cast<unsigned>(k + 1);
    walls.push_back(wall);
  }
  return walls;
}

}  // namespace osc
