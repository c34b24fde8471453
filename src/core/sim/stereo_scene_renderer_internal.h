/// @file stereo_scene_renderer_internal.h
/// @brief Private to StereoSceneRenderer's source files (stereo_scene_renderer*.cpp): a camera
/// model's rays and the candidate primitives of each image tile, which the tracer reads.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {
namespace stereo_scene_renderer_internal {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTile = 16;  // image tiles (px) that share one list of candidate primitives

/// Axis-aligned bounds in normalized image coordinates (x/z, y/z).
struct Bounds2 {
  double x_lo = kInf, x_hi = -kInf, y_lo = kInf, y_hi = -kInf;
  void add(double x, double y) {
    x_lo = std::min(x_lo, x);
    x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y);
    y_hi = std::max(y_hi, y);
  }
  bool overlapsY(const Bounds2& o) const { return y_lo <= o.y_hi && o.y_lo <= y_hi; }
  bool overlaps(const Bounds2& o) const { return overlapsY(o) && x_lo <= o.x_hi && o.x_lo <= x_hi; }
};

/// Undistorted rays of one camera model: normalized (x/z, y/z) at every pixel centre and
/// every pixel corner, each pixel's angular size, and the bounds of the rays of each tile.
struct CameraRays {
  CameraIntrinsics intrinsics;
  int width = 0, height = 0, tiles_x = 0, tiles_y = 0;
  std::vector<Eigen::Vector2f> centre;  // width * height, NaN where no ray reaches the pixel
  std::vector<Eigen::Vector2f> corner;  // (width + 1) * (height + 1), corner (u - .5, v - .5)
  std::vector<float> angle;             // width * height, radians
  std::vector<Bounds2> tile;            // tiles_x * tiles_y: every ray through the tile
  std::vector<Bounds2> tile_row;        // tiles_y: union of a row of tiles
  Bounds2 image;                        // union of all

  const Eigen::Vector2f& cornerAt(int u, int v) const {
    return corner[static_cast<size_t>(u + (width + 1) * v)];
  }
};

/// True if @p a and @p b describe the same camera model (every field equal).
bool sameIntrinsics(const CameraIntrinsics& a, const CameraIntrinsics& b);

/// True if the distortion is one-to-one from the optical axis out to normalized point n:
/// the distorted radius keeps growing along the ray. Beyond a fold (e.g. k1 < 0 without a
/// compensating k2) a raw pixel can have a second, spurious preimage far off-axis or on the
/// opposite side; those rays do not exist in the real camera.
bool inPrincipalDomain(const CameraModel& camera, const Eigen::Vector2d& n);

/// Normalized coordinates of a raw pixel, or nothing if no ray of the camera reaches it.
std::optional<Eigen::Vector2d> pixelRay(const CameraModel& camera, const Eigen::Vector2d& pixel);

/// Unit ray through normalized coordinates n (optical frame).
inline Eigen::Vector3d rayOf(const Eigen::Vector2f& n) {
  const double x = n.x(), y = n.y(), inverse_norm = 1.0 / std::sqrt(x * x + y * y + 1.0);
  return Eigen::Vector3d(x * inverse_norm, y * inverse_norm, inverse_norm);
}

/// A camera model's rays (CameraRays), with the bounds of each tile's rays.
std::shared_ptr<const CameraRays> buildRays(const CameraModel& camera);

/// Per image tile, the primitives whose bounds overlap the tile's rays, nearest first.
class TileCandidates {
 public:
  TileCandidates(const ProceduralScene& scene, const CameraRays& rays,
                 const Eigen::Isometry3d& T_world_optical);
  PrimitiveCandidates at(int u, int v) const {
    const size_t t = static_cast<size_t>(u / kTile + tiles_x_ * (v / kTile));
    const auto b = static_cast<size_t>(begin_[t]);
    return PrimitiveCandidates{index_.data() + b, distance_.data() + b,
                               static_cast<size_t>(begin_[t + 1] - begin_[t])};
  }

 private:
  int tiles_x_ = 0;
  std::vector<int> begin_, index_;
  std::vector<double> distance_;
};

}  // namespace stereo_scene_renderer_internal
}  // namespace osc
