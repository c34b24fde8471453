/// @file procedural_scene_solids.cpp
/// @brief ProceduralScene's closed-form shapes: the structures' solids (box, cylinder, sphere,
/// cone) and their rays, the x-y grid over them, and the backdrop (a cylinder with a skyline).
#include "procedural_scene_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace osc {
namespace procedural_scene_internal {

// ---------------------------------------------------------------------------------------------
// Solids: precomputed forms of the primitives and their ray intersections
// ---------------------------------------------------------------------------------------------

Solid makeSolid(const ScenePrimitive& p) {
  Solid s;
  s.shape = p.shape;
  s.cx = p.position.x();
  s.cy = p.position.y();
  switch (p.shape) {
    case ScenePrimitive::Shape::kBox:
      s.hx = 0.5 * p.size.x();
      s.hy = 0.5 * p.size.y();
      s.z0 = p.position.z();
      s.z1 = p.position.z() + p.size.z();
      s.cos_yaw = std::cos(p.yaw);
      s.sin_yaw = std::sin(p.yaw);
      s.bound = std::hypot(s.hx, s.hy);
      break;
    case ScenePrimitive::Shape::kCylinder:
    case ScenePrimitive::Shape::kCone:
      s.hx = p.size.x();
      s.z0 = p.position.z();
      s.z1 = p.position.z() + p.size.z();
      s.bound = s.hx;
      break;
    case ScenePrimitive::Shape::kSphere:
      s.hx = p.size.x();
      s.sz = p.position.z();
      s.z0 = s.sz - s.hx;
      s.z1 = s.sz + s.hx;
      s.bound = s.hx;
      break;
  }
  return s;
}

namespace {

constexpr double kMinHitDistance = 1e-9;

/// Entry distance into the slab lo <= p + t*d <= hi; updates [t_near, t_far] and the axis.
inline bool clipSlab(double p, double d, double lo, double hi, int axis, double* t_near,
                     double* t_far, int* near_face) {
  if (d == 0.0) return p >= lo && p <= hi;
  double ta = (lo - p) / d, tb = (hi - p) / d;
  int face = 2 * axis + 1;  // entering through the low side: the "-axis" face
  if (ta > tb) {
    std::swap(ta, tb);
    face = 2 * axis;
  }
  if (ta > *t_near) {
    *t_near = ta;
    *near_face = face;
  }
  *t_far = std::min(*t_far, tb);
  return *t_near <= *t_far;
}

double intersectBox(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d, int* face) {
  const double px = o.x() - s.cx, py = o.y() - s.cy;
  const double lx = s.cos_yaw * px + s.sin_yaw * py, ly = -s.sin_yaw * px + s.cos_yaw * py;
  const double dx = s.cos_yaw * d.x() + s.sin_yaw * d.y(),
               dy = -s.sin_yaw * d.x() + s.cos_yaw * d.y();
  double t_near = -kInf, t_far = kInf;
  int near_face = -1;
  if (!clipSlab(lx, dx, -s.hx, s.hx, 0, &t_near, &t_far, &near_face) ||
      !clipSlab(ly, dy, -s.hy, s.hy, 1, &t_near, &t_far, &near_face) ||
      !clipSlab(o.z(), d.z(), s.z0, s.z1, 2, &t_near, &t_far, &near_face) ||
      t_near < kMinHitDistance) {
    return kInf;
  }
  *face = std::min(near_face, 4);  // the bottom (5) is buried: report it as the top
  return t_near;
}

/// Smaller root of a t^2 + 2 h t + c = 0 (entry of a convex quadric), or +infinity.
inline bool quadraticRoots(double a, double h, double c, double* t_lo, double* t_hi) {
  if (a <= 0.0) return false;
  const double disc = h * h - a * c;
  if (disc < 0.0) return false;
  const double root = std::sqrt(disc);
  const double q = -(h + std::copysign(root, h));
  if (q == 0.0) {
    *t_lo = *t_hi = 0.0;
    return true;
  }
  *t_lo = q / a;
  *t_hi = c / q;
  if (*t_lo > *t_hi) std::swap(*t_lo, *t_hi);
  return true;
}

double intersectCylinder(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                         int* face) {
  const double px = o.x() - s.cx, py = o.y() - s.cy, r2 = s.hx * s.hx;
  double best = kInf;
  double t_lo, t_hi;
  if (quadraticRoots(d.x() * d.x() + d.y() * d.y(), px * d.x() + py * d.y(), px * px + py * py - r2,
                     &t_lo, &t_hi) &&
      t_lo >= kMinHitDistance) {
    const double z = o.z() + t_lo * d.z();
    if (z >= s.z0 && z <= s.z1) {
      best = t_lo;
      *face = 0;
    }
  }
  if (d.z() < 0.0 && o.z() > s.z1) {  // the top cap
    const double t = (s.z1 - o.z()) / d.z();
    const double x = px + t * d.x(), y = py + t * d.y();
    if (t < best && x * x + y * y <= r2) {
      best = t;
      *face = 1;
    }
  }
  return best;
}

double intersectSphere(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d p(o.x() - s.cx, o.y() - s.cy, o.z() - s.sz);
  double t_lo, t_hi;
  if (!quadraticRoots(1.0, p.dot(d), p.squaredNorm() - s.hx * s.hx, &t_lo, &t_hi)) return kInf;
  return t_lo >= kMinHitDistance ? t_lo : kInf;
}

double intersectCone(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                     int* face) {
  // x^2 + y^2 = k^2 w^2 with w = apex height - z in [0, height].
  const double height = s.z1 - s.z0, k = s.hx / height;
  const double px = o.x() - s.cx, py = o.y() - s.cy, w0 = s.z1 - o.z();
  const double k2 = k * k;
  const double a = d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z();
  const double h = px * d.x() + py * d.y() + k2 * w0 * d.z();
  const double c = px * px + py * py - k2 * w0 * w0;
  double best = kInf;
  auto consider = [&](double t) {
    const double w = w0 - t * d.z();
    if (t >= kMinHitDistance && t < best && w >= 0.0 && w <= height) {
      best = t;
      *face = 0;
    }
  };
  if (std::abs(a) > 1e-15) {
    const double disc = h * h - a * c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      consider((-h - root) / a);
      consider((-h + root) / a);
    }
  } else if (h != 0.0) {
    consider(-c / (2.0 * h));
  }
  if (d.z() > 0.0 && o.z() < s.z0) {  // the base disc, seen from below
    const double t = (s.z0 - o.z()) / d.z();
    const double x = px + t * d.x(), y = py + t * d.y();
    if (t < best && x * x + y * y <= s.hx * s.hx) {
      best = t;
      *face = 1;
    }
  }
  return best;
}

}  // namespace

double intersectSolid(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                      int* face) {
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox:
      return intersectBox(s, o, d, face);
    case ScenePrimitive::Shape::kCylinder:
      return intersectCylinder(s, o, d, face);
    case ScenePrimitive::Shape::kSphere:
      *face = 0;
      return intersectSphere(s, o, d);
    case ScenePrimitive::Shape::kCone:
      return intersectCone(s, o, d, face);
  }
  return kInf;
}

Eigen::Vector3d solidNormal(const Solid& s, const Eigen::Vector3d& p, int face) {
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox: {
      if (face == 4) return Eigen::Vector3d::UnitZ();
      const double sign = (face % 2 == 0) ? 1.0 : -1.0;
      if (face < 2) return Eigen::Vector3d(sign * s.cos_yaw, sign * s.sin_yaw, 0.0);
      return Eigen::Vector3d(-sign * s.sin_yaw, sign * s.cos_yaw, 0.0);
    }
    case ScenePrimitive::Shape::kCylinder:
      if (face == 1) return Eigen::Vector3d::UnitZ();
      return Eigen::Vector3d(p.x() - s.cx, p.y() - s.cy, 0.0).normalized();
    case ScenePrimitive::Shape::kSphere:
      return Eigen::Vector3d(p.x() - s.cx, p.y() - s.cy, p.z() - s.sz).normalized();
    case ScenePrimitive::Shape::kCone: {
      if (face == 1) return -Eigen::Vector3d::UnitZ();
      const Eigen::Vector2d radial = Eigen::Vector2d(p.x() - s.cx, p.y() - s.cy).normalized();
      return Eigen::Vector3d(radial.x(), radial.y(), s.hx / (s.z1 - s.z0)).normalized();
    }
  }
  return Eigen::Vector3d::UnitZ();
}

// ---------------------------------------------------------------------------------------------
// Uniform x-y grid over the solids
// ---------------------------------------------------------------------------------------------

void SolidGrid::build(const std::vector<Solid>& solids) {
  nx_ = ny_ = 0;
  if (solids.empty()) return;
  double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf;
  z_lo_ = kInf;
  z_hi_ = -kInf;
  for (const Solid& s : solids) {
    x_lo = std::min(x_lo, s.cx - s.bound);
    x_hi = std::max(x_hi, s.cx + s.bound);
    y_lo = std::min(y_lo, s.cy - s.bound);
    y_hi = std::max(y_hi, s.cy + s.bound);
    z_lo_ = std::min(z_lo_, s.z0);
    z_hi_ = std::max(z_hi_, s.z1);
  }
  // Keep the cell count bounded for very large scenes.
  cell_ = std::max(12.0, std::sqrt((x_hi - x_lo) * (y_hi - y_lo) / 4e6));
  x0_ = x_lo - 1.0;
  y0_ = y_lo - 1.0;
  nx_ = static_cast<int>(std::ceil((x_hi + 1.0 - x0_) / cell_));
  ny_ = static_cast<int>(std::ceil((y_hi + 1.0 - y0_) / cell_));
  std::vector<std::vector<int>> cells(static_cast<size_t>(nx_) * ny_);
  cell_top_.assign(cells.size(), -std::numeric_limits<float>::infinity());
  for (size_t k = 0; k < solids.size(); ++k) {
    const Solid& s = solids[k];
    const int i0 = static_cast<int>((s.cx - s.bound - x0_) / cell_);
    const int i1 = static_cast<int>((s.cx + s.bound - x0_) / cell_);
    const int j0 = static_cast<int>((s.cy - s.bound - y0_) / cell_);
    const int j1 = static_cast<int>((s.cy + s.bound - y0_) / cell_);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const size_t c = static_cast<size_t>(i + nx_ * j);
        cells[c].push_back(static_cast<int>(k));
        cell_top_[c] = std::max(cell_top_[c], static_cast<float>(s.z1));
      }
    }
  }
  cell_begin_.assign(cells.size() + 1, 0);
  cell_items_.clear();
  for (size_t c = 0; c < cells.size(); ++c) {
    cell_items_.insert(cell_items_.end(), cells[c].begin(), cells[c].end());
    cell_begin_[c + 1] = static_cast<int>(cell_items_.size());
  }
}

void SolidGrid::intersect(const std::vector<Solid>& solids, const Eigen::Vector3d& o,
                          const Eigen::Vector3d& d, double* best, int* index, int* face) const {
  if (nx_ == 0) return;
  // Clip the ray to the grid's box (x, y) and to the solids' height range (z).
  double t0 = 0.0, t1 = *best;
  int unused = 0;
  if (!clipSlab(o.x(), d.x(), x0_, x0_ + nx_ * cell_, 0, &t0, &t1, &unused) ||
      !clipSlab(o.y(), d.y(), y0_, y0_ + ny_ * cell_, 1, &t0, &t1, &unused) ||
      !clipSlab(o.z(), d.z(), z_lo_, z_hi_, 2, &t0, &t1, &unused)) {
    return;
  }
  t0 = std::max(t0, 0.0);
  if (!(t0 <= t1)) return;
  traverseCells(o, d, x0_, y0_, cell_, 1.0 / cell_, t0, t1,
                [&](std::int64_t i, std::int64_t j, double t_in, double t_out) {
                  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return true;
                  const size_t c = static_cast<size_t>(i + nx_ * j);
                  // Lowest point of the ray inside the cell: skip cells it passes above.
                  const double z_min = o.z() + (d.z() > 0.0 ? t_in : t_out) * d.z();
                  if (z_min <= cell_top_[c]) {
                    for (int k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
                      const int id = cell_items_[static_cast<size_t>(k)];
                      int f = 0;
                      const double t = intersectSolid(solids[static_cast<size_t>(id)], o, d, &f);
                      if (t < *best) {
                        *best = t;
                        *index = id;
                        *face = f;
                      }
                    }
                  }
                  return *best <= t_out;
                });
}

// ---------------------------------------------------------------------------------------------
// Backdrop: a vertical cylinder around the whole path with a jagged skyline
// ---------------------------------------------------------------------------------------------

void Backdrop::build(const std::vector<Eigen::Vector2d>& path_points, double distance,
                     double ground_low, std::uint32_t seed) {
  Eigen::Vector2d lo = path_points[0], hi = path_points[0];
  for (const Eigen::Vector2d& p : path_points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  centre_ = 0.5 * (lo + hi);
  double reach = 0.0;
  for (const Eigen::Vector2d& p : path_points) reach = std::max(reach, (p - centre_).norm());
  radius_ = reach + distance;
  low_ = ground_low + 0.06 * distance;
  high_ = ground_low + 0.22 * distance;
  coarse_ = std::max(12, static_cast<int>(std::round(kTwoPi * radius_ / 120.0)));
  fine_ = std::max(60, static_cast<int>(std::round(kTwoPi * radius_ / 8.0)));
  seed_ = seed;
}

double Backdrop::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  const double px = o.x() - centre_.x(), py = o.y() - centre_.y();
  double t_lo, t_hi;
  if (!quadraticRoots(d.x() * d.x() + d.y() * d.y(), px * d.x() + py * d.y(),
                      px * px + py * py - radius_ * radius_, &t_lo, &t_hi)) {
    return kInf;
  }
  return t_hi > 0.0 ? t_hi : kInf;
}

double Backdrop::periodicNoise(double angle, int lattice, bool smooth, std::uint32_t seed) const {
  const double x = (angle + kPi) / kTwoPi * lattice;  // in [0, lattice]
  std::int32_t i = std::min(fastFloor(x), lattice - 1);
  float f = static_cast<float>(x - i);
  if (smooth) f = smoothUnit(f);
  const std::int32_t next = i + 1 == lattice ? 0 : i + 1;
  const float a = unitFloat(hashCell(i, 0, seed)), b = unitFloat(hashCell(next, 0, seed));
  return a + (b - a) * f;
}

double Backdrop::skyline(double angle) const {
  const double coarse = periodicNoise(angle, coarse_, true, seed_);
  const double fine = periodicNoise(angle, fine_, false, seed_ ^ 0x3c6ef372U);
  return low_ + (high_ - low_) * (0.78 * coarse + 0.22 * fine);
}

}  // namespace procedural_scene_internal
}  // namespace osc
