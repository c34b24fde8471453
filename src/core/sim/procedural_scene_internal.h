/// @file procedural_scene_internal.h
/// @brief Private to ProceduralScene's source files (procedural_scene*.cpp): hashing, value
/// noise and the random generator (inline: the renderer's hot path), the grid traversal, and
/// the pieces the scene is built of: the texture, the ground, the path index, the solids, their
/// grid and the backdrop.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/sim/procedural_scene.h"

namespace osc {
namespace procedural_scene_internal {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;

// ---------------------------------------------------------------------------------------------
// Hashing, random numbers and value noise
// ---------------------------------------------------------------------------------------------

/// Integer finaliser (lowbias32): every output bit depends on every input bit.
inline std::uint32_t mix32(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

inline std::uint32_t hashCell(std::int32_t x, std::int32_t y, std::uint32_t seed) {
  return mix32((static_cast<std::uint32_t>(x) * 0x8da6b343U) ^
               (static_cast<std::uint32_t>(y) * 0xd8163841U) ^ seed);
}

/// A cheaper hash for noise lattices (one multiplication): good enough for value noise,
/// and the noise is the renderer's hot path.
inline std::uint32_t latticeHash(std::uint32_t x_term, std::uint32_t y_term, std::uint32_t seed) {
  std::uint32_t h = x_term ^ y_term ^ seed;
  h ^= h >> 15;
  h *= 0x2c1b3c6dU;
  h ^= h >> 12;
  return h;
}

/// Hash -> [0, 1).
inline float unitFloat(std::uint32_t h) {
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

/// floor() for |x| < 2^31 without a libm call (GCC calls libm for std::floor on plain x86-64).
inline std::int32_t fastFloor(double x) {
  const auto i = static_cast<std::int32_t>(x);
  return i - static_cast<std::int32_t>(x < i);
}

/// floor() to a 64-bit integer without a libm call.
inline std::int64_t floorToInt(double x) {
  const auto i = static_cast<std::int64_t>(x);
  return i - static_cast<std::int64_t>(x < static_cast<double>(i));
}

inline float smoothUnit(float t) { return t * t * (3.0f - 2.0f * t); }

/// 2D value noise in [-1, 1] with a unit lattice.
inline float valueNoise(double x, double y, std::uint32_t seed) {
  const std::int32_t ix = fastFloor(x), iy = fastFloor(y);
  const float sx = smoothUnit(static_cast<float>(x - ix));
  const float sy = smoothUnit(static_cast<float>(y - iy));
  const std::uint32_t x0 = static_cast<std::uint32_t>(ix) * 0x8da6b343U, x1 = x0 + 0x8da6b343U;
  const std::uint32_t y0 = static_cast<std::uint32_t>(iy) * 0xd8163841U, y1 = y0 + 0xd8163841U;
  const float v00 = unitFloat(latticeHash(x0, y0, seed)),
              v10 = unitFloat(latticeHash(x1, y0, seed));
  const float v01 = unitFloat(latticeHash(x0, y1, seed)),
              v11 = unitFloat(latticeHash(x1, y1, seed));
  const float a = v00 + (v10 - v00) * sx, b = v01 + (v11 - v01) * sx;
  return 2.0f * (a + (b - a) * sy) - 1.0f;
}

/// SplitMix64: small, fast and identical on every platform (std distributions are not).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Knuth's method: fine for the small means used here.
  int poisson(double mean) {
    const double limit = std::exp(-mean);
    int count = 0;
    for (double p = uniform(); p > limit && count < 1000; p *= uniform()) ++count;
    return count;
  }

 private:
  std::uint64_t state_;
};

/// The texture (about 1 on average) at surface coordinates (u, v) in metres for a sample
/// footprint (m): the atlas at an offset chosen by the seed, plus half the atlas rotated and
/// enlarged 1.618 times, so the sum of the two periodic patterns never repeats.
float texturePattern(double u, double v, double footprint, std::uint32_t seed);

// ---------------------------------------------------------------------------------------------
// Grid traversal (Amanatides & Woo) shared by the ground and the structure grid
// ---------------------------------------------------------------------------------------------

/// Visits, in ray order, the square cells of size `cell` (indices counted from x0, y0) that
/// the ray's x-y projection crosses for t in [t_begin, t_end]. `visit(ix, iy, t_in, t_out)`
/// returns true to stop.
template <class Visit>
void traverseCells(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double x0, double y0,
                   double cell, double inverse_cell, double t_begin, double t_end, Visit&& visit) {
  const double px = o.x() + t_begin * d.x(), py = o.y() + t_begin * d.y();
  std::int64_t ix = floorToInt((px - x0) * inverse_cell), iy = floorToInt((py - y0) * inverse_cell);
  const int step_x = d.x() > 0.0 ? 1 : -1, step_y = d.y() > 0.0 ? 1 : -1;
  double next_x = kInf, next_y = kInf, delta_x = kInf, delta_y = kInf;
  if (d.x() != 0.0) {
    const double inverse = 1.0 / d.x();
    next_x = (x0 + static_cast<double>(ix + (d.x() > 0.0 ? 1 : 0)) * cell - o.x()) * inverse;
    delta_x = cell * std::abs(inverse);
  }
  if (d.y() != 0.0) {
    const double inverse = 1.0 / d.y();
    next_y = (y0 + static_cast<double>(iy + (d.y() > 0.0 ? 1 : 0)) * cell - o.y()) * inverse;
    delta_y = cell * std::abs(inverse);
  }
  double t = t_begin;
  for (int guard = 0; guard < 1000000; ++guard) {
    const double t_out = std::min(std::min(next_x, next_y), t_end);
    if (visit(ix, iy, t, t_out) || t_out >= t_end) return;
    if (next_x < next_y) {
      ix += step_x;
      t = next_x;
      next_x += delta_x;
    } else {
      iy += step_y;
      t = next_y;
      next_y += delta_y;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Ground: a periodic table of heights on a square lattice, bilinear between vertices (so a
// ray meets it in closed form), smooth shading normals from the analytic gradient.
// ---------------------------------------------------------------------------------------------

class Ground {
 public:
  static constexpr int kSize = 128;  // vertices per period along x and y (a power of two)

  void build(double amplitude, double wavelength, std::uint32_t seed);

  double height(double x, double y) const;
  Eigen::Vector3d normal(double x, double y) const;
  double minHeight() const { return min_; }
  double maxHeight() const { return max_; }
  /// Distance to the first ground point along the ray in (0, t_max], else +infinity; the
  /// shading normal there goes to *normal.
  double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                   Eigen::Vector3d* normal) const;

 private:
  /// One lattice vertex; interleaved so a cell's data shares cache lines.
  struct Vertex {
    float height, grad_x, grad_y;
    float cell_max;  // highest vertex of the cell whose lower-left corner this is
  };
  const Vertex& at(std::int64_t i, std::int64_t j) const {
    return vertices_[static_cast<size_t>((i & (kSize - 1)) + kSize * (j & (kSize - 1)))];
  }
  double cellRoot(const Eigen::Vector3d& o, const Eigen::Vector3d& d, std::int64_t i,
                  std::int64_t j, double t_in, double t_out, Eigen::Vector3d* normal) const;
  /// Shading normal at (s, r) in [0, 1]^2 of cell (i, j): interpolated vertex gradients.
  Eigen::Vector3d cellNormal(std::int64_t i, std::int64_t j, float s, float r) const;

  bool flat_ = true;
  double spacing_ = 1.0, inverse_spacing_ = 1.0, min_ = 0.0, max_ = 0.0;
  std::vector<Vertex> vertices_;
};

// ---------------------------------------------------------------------------------------------
// Path: decimated polyline with a grid of its segments for distance queries
// ---------------------------------------------------------------------------------------------

class PathIndex {
 public:
  void build(const std::vector<Eigen::Vector2d>& path, double reach);
  double distance(const Eigen::Vector2d& p) const;
  const std::vector<Eigen::Vector2d>& points() const { return points_; }

 private:
  static constexpr double kCell = 16.0;
  std::vector<Eigen::Vector2d> points_;
  double reach_ = 0.0, x0_ = 0.0, y0_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_begin_, cell_items_;
};

// ---------------------------------------------------------------------------------------------
// Solids: precomputed forms of the primitives and their ray intersections
// ---------------------------------------------------------------------------------------------

struct Solid {
  ScenePrimitive::Shape shape = ScenePrimitive::Shape::kBox;
  double cx = 0.0, cy = 0.0;  // axis (x, y)
  double z0 = 0.0, z1 = 0.0;  // bottom and top
  double hx = 0.0, hy = 0.0;  // box half extents; radius of the round shapes in hx
  double cos_yaw = 1.0, sin_yaw = 0.0;
  double sz = 0.0;     // sphere centre height
  double bound = 0.0;  // radius of the x-y bounding circle
};

/// The precomputed form of a primitive.
Solid makeSolid(const ScenePrimitive& p);

/// Distance along the ray o + t d to where it enters the solid, +infinity if it does not (or
/// nearer than 1e-9); the face (box: 0-3 the sides, 4 the top; round shapes: 0 the side, 1 the
/// top or base) goes to *face.
double intersectSolid(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                      int* face);

/// Outward normal of the solid at its surface point p on face `face`.
Eigen::Vector3d solidNormal(const Solid& s, const Eigen::Vector3d& p, int face);

// ---------------------------------------------------------------------------------------------
// Uniform x-y grid over the solids
// ---------------------------------------------------------------------------------------------

class SolidGrid {
 public:
  void build(const std::vector<Solid>& solids);
  /// Nearest solid hit with distance < *best; updates *best, *index and *face.
  void intersect(const std::vector<Solid>& solids, const Eigen::Vector3d& o,
                 const Eigen::Vector3d& d, double* best, int* index, int* face) const;

 private:
  double cell_ = 12.0, x0_ = 0.0, y0_ = 0.0, z_lo_ = 0.0, z_hi_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_begin_, cell_items_;
  std::vector<float> cell_top_;
};

// ---------------------------------------------------------------------------------------------
// Backdrop: a vertical cylinder around the whole path with a jagged skyline
// ---------------------------------------------------------------------------------------------

class Backdrop {
 public:
  void build(const std::vector<Eigen::Vector2d>& path_points, double distance, double ground_low,
             std::uint32_t seed);
  /// Distance to the cylinder wall from inside (any height), +infinity if none.
  double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const;
  /// Height of the skyline at azimuth `angle` about the centre.
  double skyline(double angle) const;
  /// True if the point on the cylinder wall is below the skyline.
  bool belowSkyline(const Eigen::Vector3d& p) const {
    if (p.z() <= low_) return true;
    if (p.z() > high_) return false;
    return p.z() <= skyline(angle(p));
  }
  double angle(const Eigen::Vector3d& p) const {
    return std::atan2(p.y() - centre_.y(), p.x() - centre_.x());
  }
  const Eigen::Vector2d& centre() const { return centre_; }
  double radius() const { return radius_; }
  /// Lower bound on the distance from p to the wall along any ray.
  double minimumDistance(const Eigen::Vector3d& p) const {
    const double dx = p.x() - centre_.x(), dy = p.y() - centre_.y();
    return radius_ - std::sqrt(dx * dx + dy * dy);
  }

 private:
  double periodicNoise(double angle, int lattice, bool smooth, std::uint32_t seed) const;

  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double radius_ = 1.0, low_ = 0.0, high_ = 1.0;
  int coarse_ = 12, fine_ = 100;
  std::uint32_t seed_ = 0;
};

}  // namespace procedural_scene_internal
}  // namespace osc
