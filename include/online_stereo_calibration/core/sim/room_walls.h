/// @file room_walls.h
/// @brief The four walls of a room around a path, for indoor drives (a MAV in a room).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/sim/procedural_scene.h"

namespace osc {

/// Four textured boxes (0.2 m thick, `height` tall, standing on z = 0) whose inner faces lie
/// `margin` metres beyond the x-y bounding box of `path` (an empty path: the origin). Their
/// texture seeds follow from `seed`. Add them to SceneConfig::extra_primitives.
std::vector<ScenePrimitive> roomWalls(const std::vector<Eigen::Vector2d>& path, double margin,
                                      double height, unsigned seed);

}  // namespace osc
