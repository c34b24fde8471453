/// @file procedural_scene_ground.cpp
/// @brief ProceduralScene's ground (a periodic table of heights a ray meets in closed form)
/// and its path index (distances to the vehicle's path).
#include "procedural_scene_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace osc {
namespace procedural_scene_internal {
namespace {

/// Smallest root in [0, length] of a*s^2 + b*s + c, given c >= 0 ("above" at s = 0).
double firstRoot(double a, double b, double c, double length) {
  if (c <= 0.0) return 0.0;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return kInf;
  // With c > 0 the first positive root is c / q when b < 0 (also when a is ~0: the linear
  // root), and q / a when b >= 0 and a < 0; otherwise both roots are negative.
  double root;
  if (b < 0.0) {
    root = c / (0.5 * (std::sqrt(disc) - b));
  } else {
    if (!(a < 0.0)) return kInf;
    root = -0.5 * (b + std::sqrt(disc)) / a;
  }
  return root <= length ? root : kInf;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Ground: a periodic table of heights on a square lattice, bilinear between vertices (so a
// ray meets it in closed form), smooth shading normals from the analytic gradient.
// ---------------------------------------------------------------------------------------------

void Ground::build(double amplitude, double wavelength, std::uint32_t seed) {
  flat_ = !(amplitude > 0.0);
  if (flat_) return;
  spacing_ = wavelength / 8.0;  // period = 16 wavelengths
  inverse_spacing_ = 1.0 / spacing_;
  // A sum of plane waves with whole numbers of cycles per period: smooth, isotropic-looking
  // and exactly periodic, so the table tiles the whole plane without seams.
  struct Wave {
    double kx, ky, amplitude, phase;
  };
  Rng rng(0x6a09e667f3bcc909ULL ^ seed);
  std::vector<Wave> waves;
  const double cycles = kSize * spacing_ / wavelength;
  while (waves.size() < 24) {
    const double angle = rng.uniform(0.0, kPi), magnitude = cycles * rng.uniform(0.5, 1.8);
    const double m = std::round(magnitude * std::cos(angle)),
                 n = std::round(magnitude * std::sin(angle));
    if (m == 0.0 && n == 0.0) continue;
    const double k = kTwoPi / (kSize * spacing_);
    waves.push_back({k * m, k * n, 1.0 / std::hypot(m, n), rng.uniform(0.0, kTwoPi)});
  }
  vertices_.resize(static_cast<size_t>(kSize) * kSize);
  double peak = 0.0;
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      double value = 0.0, dx = 0.0, dy = 0.0;
      for (const Wave& w : waves) {
        const double arg = w.kx * i * spacing_ + w.ky * j * spacing_ + w.phase;
        const double sine = std::sin(arg);
        value += w.amplitude * std::cos(arg);
        dx -= w.amplitude * w.kx * sine;
        dy -= w.amplitude * w.ky * sine;
      }
      vertices_[static_cast<size_t>(i + kSize * j)] = {
          static_cast<float>(value), static_cast<float>(dx), static_cast<float>(dy), 0.0f};
      peak = std::max(peak, std::abs(value));
    }
  }
  const float scale = static_cast<float>(amplitude / peak);
  min_ = kInf;
  max_ = -kInf;
  for (Vertex& v : vertices_) {
    v.height *= scale;
    v.grad_x *= scale;
    v.grad_y *= scale;
    min_ = std::min(min_, static_cast<double>(v.height));
    max_ = std::max(max_, static_cast<double>(v.height));
  }
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      vertices_[static_cast<size_t>(i + kSize * j)].cell_max =
          std::max(std::max(at(i, j).height, at(i + 1, j).height),
                   std::max(at(i, j + 1).height, at(i + 1, j + 1).height));
    }
  }
}

double Ground::height(double x, double y) const {
  if (flat_) return 0.0;
  const double gx = x * inverse_spacing_, gy = y * inverse_spacing_;
  const std::int64_t i = floorToInt(gx), j = floorToInt(gy);
  const double s = gx - static_cast<double>(i), r = gy - static_cast<double>(j);
  const double h00 = at(i, j).height, h10 = at(i + 1, j).height;
  const double h01 = at(i, j + 1).height, h11 = at(i + 1, j + 1).height;
  return h00 + (h10 - h00) * s + (h01 - h00) * r + (h00 - h10 - h01 + h11) * s * r;
}

Eigen::Vector3d Ground::normal(double x, double y) const {
  if (flat_) return Eigen::Vector3d::UnitZ();
  const double gx = x * inverse_spacing_, gy = y * inverse_spacing_;
  const std::int64_t i = floorToInt(gx), j = floorToInt(gy);
  return cellNormal(i, j, static_cast<float>(gx - static_cast<double>(i)),
                    static_cast<float>(gy - static_cast<double>(j)));
}

Eigen::Vector3d Ground::cellNormal(std::int64_t i, std::int64_t j, float s, float r) const {
  const Vertex &v00 = at(i, j), &v10 = at(i + 1, j), &v01 = at(i, j + 1), &v11 = at(i + 1, j + 1);
  const float w00 = (1.0f - s) * (1.0f - r), w10 = s * (1.0f - r), w01 = (1.0f - s) * r,
              w11 = s * r;
  const float nx = -(w00 * v00.grad_x + w10 * v10.grad_x + w01 * v01.grad_x + w11 * v11.grad_x);
  const float ny = -(w00 * v00.grad_y + w10 * v10.grad_y + w01 * v01.grad_y + w11 * v11.grad_y);
  const float inverse_norm = 1.0f / std::sqrt(nx * nx + ny * ny + 1.0f);
  return Eigen::Vector3d(nx * inverse_norm, ny * inverse_norm, inverse_norm);
}

double Ground::cellRoot(const Eigen::Vector3d& o, const Eigen::Vector3d& d, std::int64_t i,
                        std::int64_t j, double t_in, double t_out, Eigen::Vector3d* normal) const {
  // Height along the ray inside the cell is quadratic in s = t - t_in (bilinear patch).
  const double h00 = at(i, j).height, h10 = at(i + 1, j).height;
  const double h01 = at(i, j + 1).height, h11 = at(i + 1, j + 1).height;
  const double e1 = h10 - h00, e2 = h01 - h00, e3 = h00 - h10 - h01 + h11;
  const double sa = (o.x() + t_in * d.x()) * inverse_spacing_ - static_cast<double>(i);
  const double ra = (o.y() + t_in * d.y()) * inverse_spacing_ - static_cast<double>(j);
  const double sd = d.x() * inverse_spacing_, rd = d.y() * inverse_spacing_;
  const double za = o.z() + t_in * d.z();
  const double c = za - (h00 + e1 * sa + e2 * ra + e3 * sa * ra);
  const double b = d.z() - (e1 * sd + e2 * rd + e3 * (sa * rd + ra * sd));
  const double a = -e3 * sd * rd;
  const double s = firstRoot(a, b, c, t_out - t_in);
  if (!(s < kInf)) return kInf;
  const auto clamp01 = [](double x) { return static_cast<float>(std::min(1.0, std::max(0.0, x))); };
  *normal = cellNormal(i, j, clamp01(sa + sd * s), clamp01(ra + rd * s));
  return t_in + s;
}

double Ground::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                         Eigen::Vector3d* normal) const {
  if (flat_) {
    if (!(d.z() < 0.0) || !(o.z() > 0.0)) return kInf;
    const double t = -o.z() / d.z();
    *normal = Eigen::Vector3d::UnitZ();
    return t <= t_max ? t : kInf;
  }
  // Only the part of the ray inside the slab of possible heights can meet the ground.
  double t0 = 0.0, t1 = t_max;
  if (d.z() < 0.0) {
    const double inverse = 1.0 / d.z();
    t0 = std::max(t0, (max_ - o.z()) * inverse);
    t1 = std::min(t1, (min_ - o.z()) * inverse);
  } else if (d.z() > 0.0) {
    t1 = std::min(t1, (max_ - o.z()) / d.z());
  } else if (o.z() > max_ || o.z() < min_) {
    return kInf;
  }
  if (!(t0 <= t1) || !std::isfinite(t1)) return kInf;
  double hit = kInf;
  traverseCells(o, d, 0.0, 0.0, spacing_, inverse_spacing_, t0, t1,
                [&](std::int64_t i, std::int64_t j, double t_in, double t_out) {
                  // The ray's lowest point in the cell is above its highest vertex: no hit.
                  if (o.z() + (d.z() < 0.0 ? t_out : t_in) * d.z() > at(i, j).cell_max)
                    return false;
                  hit = cellRoot(o, d, i, j, t_in, t_out, normal);
                  return hit < kInf;
                });
  return hit;
}

// ---------------------------------------------------------------------------------------------
// Path: decimated polyline with a grid of its segments for distance queries
// ---------------------------------------------------------------------------------------------

void PathIndex::build(const std::vector<Eigen::Vector2d>& path, double reach) {
  reach_ = reach;
  points_.clear();
  if (path.empty()) points_.push_back(Eigen::Vector2d::Zero());
  for (const Eigen::Vector2d& p : path) {
    if (points_.empty() || (p - points_.back()).norm() >= 1.0) points_.push_back(p);
  }
  if (!path.empty() && (path.back() - points_.back()).norm() > 0.0) points_.push_back(path.back());
  Eigen::Vector2d lo = points_[0], hi = points_[0];
  for (const Eigen::Vector2d& p : points_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  x0_ = lo.x() - reach - kCell;
  y0_ = lo.y() - reach - kCell;
  nx_ = static_cast<int>(std::ceil((hi.x() - x0_ + reach + kCell) / kCell));
  ny_ = static_cast<int>(std::ceil((hi.y() - y0_ + reach + kCell) / kCell));
  // Counting sort of the segments into the cells their bounding boxes overlap.
  const size_t segments = std::max<size_t>(1, points_.size() - 1);
  std::vector<std::vector<int>> cells(static_cast<size_t>(nx_) * ny_);
  for (size_t k = 0; k < segments; ++k) {
    const Eigen::Vector2d a = points_[k], b = points_[std::min(k + 1, points_.size() - 1)];
    const int i0 = static_cast<int>((std::min(a.x(), b.x()) - x0_) / kCell);
    const int i1 = static_cast<int>((std::max(a.x(), b.x()) - x0_) / kCell);
    const int j0 = static_cast<int>((std::min(a.y(), b.y()) - y0_) / kCell);
    const int j1 = static_cast<int>((std::max(a.y(), b.y()) - y0_) / kCell);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i)
        cells[static_cast<size_t>(i + nx_ * j)].push_back(static_cast<int>(k));
    }
  }
  cell_begin_.assign(cells.size() + 1, 0);
  cell_items_.clear();
  for (size_t c = 0; c < cells.size(); ++c) {
    cell_items_.insert(cell_items_.end(), cells[c].begin(), cells[c].end());
    cell_begin_[c + 1] = static_cast<int>(cell_items_.size());
  }
}

double PathIndex::distance(const Eigen::Vector2d& p) const {
  const int i0 = std::max(0, static_cast<int>(std::floor((p.x() - reach_ - x0_) / kCell)));
  const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor((p.x() + reach_ - x0_) / kCell)));
  const int j0 = std::max(0, static_cast<int>(std::floor((p.y() - reach_ - y0_) / kCell)));
  const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor((p.y() + reach_ - y0_) / kCell)));
  double best = kInf;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const size_t c = static_cast<size_t>(i + nx_ * j);
      for (int k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
        const auto segment = static_cast<size_t>(cell_items_[static_cast<size_t>(k)]);
        const Eigen::Vector2d a = points_[segment];
        const Eigen::Vector2d b = points_[std::min(segment + 1, points_.size() - 1)];
        const Eigen::Vector2d ab = b - a;
        const double len2 = ab.squaredNorm();
        const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, (a + s * ab - p).norm());
      }
    }
  }
  return best <= reach_ ? best : kInf;
}

}  // namespace procedural_scene_internal
}  // namespace osc
