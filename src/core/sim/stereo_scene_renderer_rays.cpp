/// @file stereo_scene_renderer_rays.cpp
/// @brief StereoSceneRenderer's rays: a camera model's undistorted rays at every pixel centre
/// and corner, the bounds of each tile's rays, and each tile's candidate primitives at a pose.
#include "stereo_scene_renderer_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace osc {
namespace stereo_scene_renderer_internal {
namespace {

/// As pixelRay(), NaN for no ray (the form the ray cache stores).
Eigen::Vector2f undistortChecked(const CameraModel& camera, const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector2d> n = pixelRay(camera, pixel);
  return n ? Eigen::Vector2f(n->cast<float>())
           : Eigen::Vector2f::Constant(std::numeric_limits<float>::quiet_NaN());
}

/// Bounds of all rays through each tile: its pixels' corners (sub-sample rays interpolate
/// them) and centres (the fallback where a corner is invalid).
void computeTileBounds(CameraRays* rays) {
  rays->tiles_x = (rays->width + kTile - 1) / kTile;
  rays->tiles_y = (rays->height + kTile - 1) / kTile;
  rays->tile.assign(static_cast<size_t>(rays->tiles_x) * rays->tiles_y, Bounds2());
  rays->tile_row.assign(static_cast<size_t>(rays->tiles_y), Bounds2());
  auto add = [rays](int tu, int tv, const Eigen::Vector2f& n) {
    if (n.allFinite()) rays->tile[static_cast<size_t>(tu + rays->tiles_x * tv)].add(n.x(), n.y());
  };
  for (int v = 0; v <= rays->height; ++v) {
    for (int u = 0; u <= rays->width; ++u) {
      // A corner belongs to up to four tiles.
      for (int tv = std::max(0, (v - 1) / kTile); tv <= std::min(rays->tiles_y - 1, v / kTile);
           ++tv) {
        for (int tu = std::max(0, (u - 1) / kTile); tu <= std::min(rays->tiles_x - 1, u / kTile);
             ++tu) {
          add(tu, tv, rays->cornerAt(u, v));
        }
      }
      if (u < rays->width && v < rays->height) {
        add(u / kTile, v / kTile, rays->centre[static_cast<size_t>(u + rays->width * v)]);
      }
    }
  }
  for (int tv = 0; tv < rays->tiles_y; ++tv) {
    Bounds2& row = rays->tile_row[static_cast<size_t>(tv)];
    for (int tu = 0; tu < rays->tiles_x; ++tu) {
      const Bounds2& b = rays->tile[static_cast<size_t>(tu + rays->tiles_x * tv)];
      if (!(b.x_lo <= b.x_hi)) continue;  // no ray at all in this tile
      row.add(b.x_lo, b.y_lo);
      row.add(b.x_hi, b.y_hi);
    }
    if (!(row.x_lo <= row.x_hi)) continue;
    rays->image.add(row.x_lo, row.y_lo);
    rays->image.add(row.x_hi, row.y_hi);
  }
}

}  // namespace

bool sameIntrinsics(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && a.model == b.model && a.distortion == b.distortion;
}

bool inPrincipalDomain(const CameraModel& camera, const Eigen::Vector2d& n) {
  const double r = n.norm();
  if (!std::isfinite(r)) return false;
  if (r < 1e-12) return true;
  const Eigen::Vector2d direction = n / r;
  constexpr int kSteps = 8;
  double previous = 0.0;
  for (int k = 1; k <= kSteps; ++k) {
    const double radius = camera.distort(n * (static_cast<double>(k) / kSteps)).dot(direction);
    if (!(radius > previous)) return false;
    previous = radius;
  }
  return camera.distort(n * (1.0 + 1e-6)).dot(direction) > previous;
}

std::optional<Eigen::Vector2d> pixelRay(const CameraModel& camera, const Eigen::Vector2d& pixel) {
  Eigen::Vector2d n;
  if (!camera.pixelToNormalized(pixel, &n) || !inPrincipalDomain(camera, n)) return std::nullopt;
  return n;
}

std::shared_ptr<const CameraRays> buildRays(const CameraModel& camera) {
  auto rays = std::make_shared<CameraRays>();
  rays->intrinsics = camera.intrinsics();
  const int w = rays->intrinsics.width, h = rays->intrinsics.height;
  rays->width = w;
  rays->height = h;
  rays->centre.resize(static_cast<size_t>(w) * h);
  rays->corner.resize(static_cast<size_t>(w + 1) * (h + 1));
  rays->angle.resize(static_cast<size_t>(w) * h);
  cv::parallel_for_(cv::Range(0, h + 1), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      for (int u = 0; u <= w; ++u) {
        rays->corner[static_cast<size_t>(u + (w + 1) * v)] =
            undistortChecked(camera, Eigen::Vector2d(u - 0.5, v - 0.5));
        if (u < w && v < h) {
          rays->centre[static_cast<size_t>(u + w * v)] =
              undistortChecked(camera, Eigen::Vector2d(u, v));
        }
      }
    }
  });
  // Angular pixel size from the corner rays (falls back to 1/f where a corner is invalid).
  const float fallback =
      static_cast<float>(1.0 / std::max(rays->intrinsics.fx, rays->intrinsics.fy));
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2f &c00 = rays->cornerAt(u, v), &c10 = rays->cornerAt(u + 1, v),
                            &c01 = rays->cornerAt(u, v + 1);
      float angle = fallback;
      if (c00.allFinite() && c10.allFinite() && c01.allFinite()) {
        const Eigen::Vector3d a = rayOf(c00), b = rayOf(c10), c = rayOf(c01);
        angle = static_cast<float>(std::sqrt(std::atan2(a.cross(b).norm(), a.dot(b)) *
                                             std::atan2(a.cross(c).norm(), a.dot(c))));
      }
      rays->angle[static_cast<size_t>(u + w * v)] = angle;
    }
  }
  computeTileBounds(rays.get());
  return rays;
}

namespace {

/// Only hits at least this far in front of the camera (along the optical axis) are rendered.
constexpr double kNearPlane = 1e-4;

/// Bounds in normalized coordinates of the part of a box in front of the near plane, and a
/// lower bound on the distance of any of its points (false if it is all behind).
bool projectBox(const std::array<Eigen::Vector3d, 8>& corners_optical, Bounds2* bounds,
                double* min_distance) {
  *min_distance = kInf;
  for (int a = 0; a < 8; ++a) {
    const Eigen::Vector3d& p = corners_optical[static_cast<size_t>(a)];
    *min_distance = std::min(*min_distance, std::max(p.z(), kNearPlane));
    if (p.z() >= kNearPlane) bounds->add(p.x() / p.z(), p.y() / p.z());
    // Edges crossing the near plane add their crossing points (corners differ in one bit).
    for (int bit = 1; bit < 8; bit <<= 1) {
      const int b = a ^ bit;
      const Eigen::Vector3d& q = corners_optical[static_cast<size_t>(b)];
      if (b > a && (p.z() < kNearPlane) != (q.z() < kNearPlane)) {
        const Eigen::Vector3d c = p + (kNearPlane - p.z()) / (q.z() - p.z()) * (q - p);
        bounds->add(c.x() / kNearPlane, c.y() / kNearPlane);
      }
    }
  }
  if (!(bounds->x_lo <= bounds->x_hi)) return false;
  // Margin for rounding: the tile bounds are floats.
  const double margin = 1e-5 * (1.0 + std::max(std::abs(bounds->x_lo), std::abs(bounds->x_hi)) +
                                std::max(std::abs(bounds->y_lo), std::abs(bounds->y_hi)));
  bounds->x_lo -= margin;
  bounds->y_lo -= margin;
  bounds->x_hi += margin;
  bounds->y_hi += margin;
  return true;
}

}  // namespace

TileCandidates::TileCandidates(const ProceduralScene& scene, const CameraRays& rays,
                               const Eigen::Isometry3d& T_world_optical)
    : tiles_x_(rays.tiles_x) {
  struct Entry {
    int tile;
    double distance;
    int primitive;
  };
  std::vector<Entry> entries;
  const Eigen::Isometry3d T_optical_world = T_world_optical.inverse();
  const int count = static_cast<int>(scene.primitives().size());
  for (int k = 0; k < count; ++k) {
    std::array<Eigen::Vector3d, 8> corners = scene.boundingCorners(k);
    for (Eigen::Vector3d& c : corners) c = T_optical_world * c;
    Bounds2 bounds;
    double distance = 0.0;
    if (!projectBox(corners, &bounds, &distance) || !bounds.overlaps(rays.image)) continue;
    for (int tv = 0; tv < rays.tiles_y; ++tv) {
      if (!bounds.overlapsY(rays.tile_row[static_cast<size_t>(tv)])) continue;
      for (int tu = 0; tu < rays.tiles_x; ++tu) {
        const int t = tu + rays.tiles_x * tv;
        if (bounds.overlaps(rays.tile[static_cast<size_t>(t)])) entries.push_back({t, distance, k});
      }
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.tile != b.tile ? a.tile < b.tile : a.distance < b.distance;
  });
  begin_.assign(static_cast<size_t>(rays.tiles_x) * rays.tiles_y + 1, 0);
  index_.reserve(entries.size());
  distance_.reserve(entries.size());
  for (const Entry& e : entries) {
    ++begin_[static_cast<size_t>(e.tile) + 1];
    index_.push_back(e.primitive);
    distance_.push_back(e.distance);
  }
  for (size_t t = 1; t < begin_.size(); ++t) begin_[t] += begin_[t - 1];
}

}  // namespace stereo_scene_renderer_internal
}  // namespace osc
