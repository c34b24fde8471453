/// @file bucketing.h
/// @brief Spatial sampling of new points (seed Sec. II-A): at most one per cell of an image
/// grid, none in a cell that already holds a tracked point.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace osc {

/// Indices of the candidates kept: the lowest cost per cell of a cols x rows grid over the
/// width x height image, skipping cells that contain an `occupied` position, at most
/// max_count in all (the lowest costs first). Sorted ascending by cost.
std::vector<int> selectByBuckets(const std::vector<Eigen::Vector2d>& positions,
                                 const std::vector<double>& costs,
                                 const std::vector<Eigen::Vector2d>& occupied, int width,
                                 int height, int cols, int rows, int max_count);

}  // namespace osc
