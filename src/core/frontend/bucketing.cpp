#include "online_stereo_calibration/core/frontend/bucketing.h"

#include <algorithm>
#include <cmath>

namespace osc {

std::vector<int> selectByBuckets(const std::vector<Eigen::Vector2d>& positions,
                                 const std::vector<double>& costs,
                                 const std::vector<Eigen::Vector2d>& occupied, int width,
                                 int height, int cols, int rows, int max_count) {
  std::vector<int> kept;
  if (max_count <= 0 || cols <= 0 || rows <= 0 || width <= 0 || height <= 0) return kept;
  auto cellOf = [&](const Eigen::Vector2d& p) {
    const int c = std::clamp(static_cast<int>(std::floor(p.x() * cols / width)), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(std::floor(p.y() * rows / height)), 0, rows - 1);
    return r * cols + c;
  };
  std::vector<int> best(static_cast<size_t>(cols * rows), -1);
  std::vector<char> blocked(best.size(), 0);
  for (const Eigen::Vector2d& p : occupied) {
    if (p.allFinite()) blocked[static_cast<size_t>(cellOf(p))] = 1;
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i].allFinite()) continue;
    const size_t cell = static_cast<size_t>(cellOf(positions[i]));
    if (blocked[cell]) continue;
    if (best[cell] < 0 || costs[i] < costs[static_cast<size_t>(best[cell])]) {
      best[cell] = static_cast<int>(i);
    }
  }
  for (int i : best) {
    if (i >= 0) kept.push_back(i);
  }
  std::sort(kept.begin(), kept.end(), [&](int a, int b) {
    return costs[static_cast<size_t>(a)] < costs[static_cast<size_t>(b)];
  });
  if (static_cast<int>(kept.size()) > max_count) kept.resize(static_cast<size_t>(max_count));
  return kept;
}

}  // namespace osc
