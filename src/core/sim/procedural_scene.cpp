/// @file procedural_scene.cpp
/// @brief ProceduralScene: the structures' generation, SceneConfig::validate, construction,
/// the ray queries and the shading (the pieces in procedural_scene_{texture,ground,solids}.cpp).
#include "online_stereo_calibration/core/sim/procedural_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "procedural_scene_internal.h"

namespace osc {

using namespace procedural_scene_internal;

namespace {

const Eigen::Vector3f kHorizon(0.8f, 0.83f, 0.87f);  // sky colour at the horizon

// ---------------------------------------------------------------------------------------------
// Structure generation
// ---------------------------------------------------------------------------------------------

constexpr double kTile = 32.0;  // generation cell: its structures depend on seed + index only

Eigen::Vector3f jitterTint(Rng* rng, const Eigen::Vector3f& base, float amount) {
  const float brightness = static_cast<float>(rng->uniform(1.0 - amount, 1.0 + amount));
  Eigen::Vector3f tint = base * brightness;
  for (int c = 0; c < 3; ++c) tint[c] *= static_cast<float>(rng->uniform(0.92, 1.08));
  return tint.cwiseMin(1.0f);
}

/// One random structure (1-2 primitives) at (x, y) and the radius it occupies.
double makeStructure(Rng* rng, double x, double y, const Ground& ground,
                     std::vector<ScenePrimitive>* out) {
  const double bottom = ground.minHeight() - 0.3;  // buried: no gap on undulating ground
  const double base = ground.height(x, y);
  const double kind = rng->uniform();
  auto seed = [rng]() { return static_cast<std::uint32_t>(rng->next()); };
  if (kind < 0.3) {  // building, container
    static const Eigen::Vector3f palette[] = {
        {0.62f, 0.62f, 0.6f}, {0.62f, 0.4f, 0.32f}, {0.72f, 0.64f, 0.5f}, {0.46f, 0.52f, 0.62f}};
    ScenePrimitive box;
    box.shape = ScenePrimitive::Shape::kBox;
    box.size = Eigen::Vector3d(rng->uniform(2.0, 9.0), rng->uniform(2.0, 9.0), 0.0);
    box.size.z() = base - bottom + rng->uniform(1.5, 8.0);
    box.position = Eigen::Vector3d(x, y, bottom);
    box.yaw = rng->uniform(0.0, kPi);
    box.tint = jitterTint(rng, palette[rng->next() % 4], 0.15f);
    box.texture_seed = seed();
    out->push_back(box);
    return 0.5 * std::hypot(box.size.x(), box.size.y());
  }
  if (kind < 0.55) {  // wall
    ScenePrimitive wall;
    wall.shape = ScenePrimitive::Shape::kBox;
    wall.size = Eigen::Vector3d(rng->uniform(4.0, 15.0), rng->uniform(0.2, 0.45), 0.0);
    wall.size.z() = base - bottom + rng->uniform(1.5, 4.0);
    wall.position = Eigen::Vector3d(x, y, bottom);
    wall.yaw = rng->uniform(0.0, kPi);
    wall.tint = jitterTint(rng, Eigen::Vector3f(0.66f, 0.63f, 0.58f), 0.2f);
    wall.texture_seed = seed();
    out->push_back(wall);
    return 0.5 * std::hypot(wall.size.x(), wall.size.y());
  }
  // Tree: a trunk with a round or a conical crown.
  ScenePrimitive trunk;
  trunk.shape = ScenePrimitive::Shape::kCylinder;
  const double trunk_height = rng->uniform(1.8, 3.5);
  trunk.size = Eigen::Vector3d(rng->uniform(0.12, 0.35), 0.0, base - bottom + trunk_height + 0.5);
  trunk.position = Eigen::Vector3d(x, y, bottom);
  trunk.tint = jitterTint(rng, Eigen::Vector3f(0.45f, 0.34f, 0.25f), 0.15f);
  trunk.texture_seed = seed();
  out->push_back(trunk);
  ScenePrimitive crown;
  crown.tint = jitterTint(rng, Eigen::Vector3f(0.34f, 0.5f, 0.26f), 0.2f);
  crown.texture_seed = seed();
  double radius = 0.0;
  if (rng->uniform() < 0.5) {
    crown.shape = ScenePrimitive::Shape::kSphere;
    radius = rng->uniform(1.0, 3.0);
    crown.size = Eigen::Vector3d(radius, 0.0, 0.0);
    crown.position = Eigen::Vector3d(x, y, base + trunk_height + 0.8 * radius);
  } else {
    crown.shape = ScenePrimitive::Shape::kCone;
    radius = rng->uniform(1.0, 2.5);
    crown.size = Eigen::Vector3d(radius, 0.0, rng->uniform(3.0, 8.0));
    crown.position = Eigen::Vector3d(x, y, base + 0.6 * trunk_height);
  }
  out->push_back(crown);
  return radius;
}

void appendError(std::vector<std::string>* errors, bool ok, const std::string& message) {
  if (!ok) errors->push_back(message);
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// SceneConfig
// ---------------------------------------------------------------------------------------------

std::vector<std::string> SceneConfig::validate() const {
  std::vector<std::string> e;
  appendError(&e, finite(ground_undulation) && ground_undulation >= 0.0 && ground_undulation <= 5.0,
              "ground_undulation must be in [0, 5] m");
  appendError(&e,
              finite(ground_wavelength) && ground_wavelength >= 10.0 * ground_undulation &&
                  ground_wavelength >= 4.0 && ground_wavelength <= 1000.0,
              "ground_wavelength must be in [4, 1000] m and at least 10 x ground_undulation");
  appendError(&e,
              finite(structure_density) && structure_density >= 0.0 && structure_density <= 500.0,
              "structure_density must be in [0, 500] per hectare");
  appendError(&e, finite(min_structure_distance) && min_structure_distance >= 0.0,
              "min_structure_distance must be >= 0 m");
  appendError(&e,
              finite(max_structure_distance) && max_structure_distance > min_structure_distance &&
                  max_structure_distance <= 1000.0,
              "max_structure_distance must be in (min_structure_distance, 1000] m");
  appendError(&e,
              finite(backdrop_distance) && backdrop_distance > max_structure_distance &&
                  backdrop_distance <= 5000.0,
              "backdrop_distance must be in (max_structure_distance, 5000] m");
  bool path_finite = true;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < path.size(); ++k) {
    path_finite = path_finite && path[k].allFinite();
    lo = k == 0 ? path[k] : lo.cwiseMin(path[k]);
    hi = k == 0 ? path[k] : hi.cwiseMax(path[k]);
  }
  appendError(&e, path_finite, "path must hold finite points");
  appendError(&e,
              !path_finite || ((hi - lo).maxCoeff() <= 20000.0 && lo.cwiseAbs().maxCoeff() <= 1e5 &&
                               hi.cwiseAbs().maxCoeff() <= 1e5),
              "path must span at most 20 km and stay within 100 km of the origin");
  for (size_t k = 0; k < extra_primitives.size(); ++k) {
    const ScenePrimitive& p = extra_primitives[k];
    const bool round = p.shape != ScenePrimitive::Shape::kBox;
    const bool sphere = p.shape == ScenePrimitive::Shape::kSphere;
    const bool ok = p.position.allFinite() && finite(p.yaw) && p.size.allFinite() &&
                    p.size.x() > 0.0 && (round || p.size.y() > 0.0) &&
                    (sphere || p.size.z() > 0.0) && p.tint.allFinite() && p.tint.minCoeff() >= 0.0f;
    appendError(&e, ok,
                "extra_primitives[" + std::to_string(k) +
                    "] needs finite values, positive sizes and a non-negative tint");
  }
  appendError(&e, finite(sun_elevation) && sun_elevation > 0.0 && sun_elevation <= kPi / 2.0,
              "sun_elevation must be in (0, pi/2] rad");
  appendError(&e, finite(sun_azimuth), "sun_azimuth must be finite");
  appendError(&e, finite(ambient) && ambient >= 0.0 && ambient <= 1.0, "ambient must be in [0, 1]");
  return e;
}

// ---------------------------------------------------------------------------------------------
// ProceduralScene
// ---------------------------------------------------------------------------------------------

struct ProceduralScene::Impl {
  SceneConfig config;
  Ground ground;
  PathIndex path;
  Backdrop backdrop;
  std::vector<ScenePrimitive> primitives;
  std::vector<Solid> solids;
  SolidGrid grid;
  Eigen::Vector3d sun = Eigen::Vector3d::UnitZ();
  std::uint32_t ground_seed = 0, backdrop_seed = 0;

  void generateStructures();
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 double max_distance, const PrimitiveCandidates* candidates, SceneHit* hit) const;
  /// Texture coordinates (u, v) in metres, pattern seed and tint of a hit.
  void surfaceFrame(const SceneHit& hit, double* u, double* v, std::uint32_t* seed,
                    Eigen::Vector3f* tint, double* scale) const;
};

void ProceduralScene::Impl::generateStructures() {
  const double reach = config.max_structure_distance + 15.0 + kTile;
  const std::vector<Eigen::Vector2d>& points = path.points();
  Eigen::Vector2d lo = points[0], hi = points[0];
  for (const Eigen::Vector2d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int tx0 = static_cast<int>(std::floor((lo.x() - reach) / kTile));
  const int ty0 = static_cast<int>(std::floor((lo.y() - reach) / kTile));
  const int nx = static_cast<int>(std::floor((hi.x() + reach) / kTile)) - tx0 + 1;
  const int ny = static_cast<int>(std::floor((hi.y() + reach) / kTile)) - ty0 + 1;
  // Mark the tiles near the path, then fill each from its own seed.
  std::vector<char> near(static_cast<size_t>(nx) * ny, 0);
  const int r = static_cast<int>(std::ceil(reach / kTile));
  for (const Eigen::Vector2d& p : points) {
    const int ci = static_cast<int>(std::floor(p.x() / kTile)) - tx0;
    const int cj = static_cast<int>(std::floor(p.y() / kTile)) - ty0;
    for (int j = std::max(0, cj - r); j <= std::min(ny - 1, cj + r); ++j) {
      for (int i = std::max(0, ci - r); i <= std::min(nx - 1, ci + r); ++i)
        near[static_cast<size_t>(i + nx * j)] = 1;
    }
  }
  const double mean_count = config.structure_density * kTile * kTile / 1e4;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (!near[static_cast<size_t>(i + nx * j)]) continue;
      const std::uint32_t tile_seed = hashCell(tx0 + i, ty0 + j, mix32(config.seed) ^ 0xa54ff53aU);
      Rng rng((static_cast<std::uint64_t>(tile_seed) << 32) | mix32(tile_seed + 1U));
      const int count = rng.poisson(mean_count);
      for (int n = 0; n < count; ++n) {
        const double x = (tx0 + i + rng.uniform()) * kTile, y = (ty0 + j + rng.uniform()) * kTile;
        std::vector<ScenePrimitive> parts;
        const double radius = makeStructure(&rng, x, y, ground, &parts);
        const double distance = path.distance(Eigen::Vector2d(x, y));
        if (distance <= config.max_structure_distance &&
            distance - radius >= config.min_structure_distance) {
          primitives.insert(primitives.end(), parts.begin(), parts.end());
        }
      }
    }
  }
}

void ProceduralScene::Impl::surfaceFrame(const SceneHit& hit, double* u, double* v,
                                         std::uint32_t* seed, Eigen::Vector3f* tint,
                                         double* scale) const {
  const Eigen::Vector3d& p = hit.point;
  *scale = 1.0;
  if (hit.surface == SceneHit::Surface::kGround) {
    *u = p.x();
    *v = p.y();
    *seed = ground_seed;
    *tint = Eigen::Vector3f(0.55f, 0.5f, 0.4f);
    return;
  }
  if (hit.surface == SceneHit::Surface::kBackdrop) {
    *u = backdrop.radius() * backdrop.angle(p);
    *v = p.z();
    *seed = backdrop_seed;
    *tint = Eigen::Vector3f(0.4f, 0.47f, 0.42f);
    *scale = 8.0;
    return;
  }
  const ScenePrimitive& prim = primitives[static_cast<size_t>(hit.primitive)];
  const Solid& s = solids[static_cast<size_t>(hit.primitive)];
  *seed = mix32(prim.texture_seed + 0x9e3779b9U * static_cast<std::uint32_t>(hit.face));
  *tint = prim.tint;
  const double px = p.x() - s.cx, py = p.y() - s.cy;
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox: {
      const double lx = s.cos_yaw * px + s.sin_yaw * py, ly = -s.sin_yaw * px + s.cos_yaw * py;
      *u = hit.face < 2 ? ly : lx;
      *v = hit.face == 4 ? ly : p.z();
      return;
    }
    case ScenePrimitive::Shape::kCylinder:
      *u = hit.face == 1 ? px : s.hx * std::atan2(py, px);
      *v = hit.face == 1 ? py : p.z();
      return;
    case ScenePrimitive::Shape::kSphere: {
      const double polar = std::acos(std::clamp((p.z() - s.sz) / s.hx, -1.0, 1.0));
      *u = s.hx * std::sin(polar) * std::atan2(py, px);
      *v = s.hx * polar;
      return;
    }
    case ScenePrimitive::Shape::kCone: {
      if (hit.face == 1) {
        *u = px;
        *v = py;
        return;
      }
      const double k = s.hx / (s.z1 - s.z0), w = s.z1 - p.z();
      *u = k * w * std::atan2(py, px);
      *v = w * std::sqrt(1.0 + k * k);
      return;
    }
  }
}

ProceduralScene::ProceduralScene(const SceneConfig& config) {
  const std::vector<std::string> errors = config.validate();
  if (!errors.empty()) {
    std::string message = "invalid SceneConfig:";
    for (const std::string& e : errors) message += " " + e + ";";
    throw std::invalid_argument(message);
  }
  auto impl = std::make_shared<Impl>();
  impl->config = config;
  impl->ground.build(config.ground_undulation, config.ground_wavelength,
                     mix32(config.seed ^ 0x510e527fU));
  impl->path.build(config.path, config.max_structure_distance + 100.0);
  impl->backdrop.build(impl->path.points(), config.backdrop_distance, impl->ground.minHeight(),
                       mix32(config.seed ^ 0x9b05688cU));
  impl->ground_seed = mix32(config.seed ^ 0x1f83d9abU);
  impl->backdrop_seed = mix32(config.seed ^ 0x5be0cd19U);
  if (config.generate_structures && config.structure_density > 0.0) impl->generateStructures();
  impl->primitives.insert(impl->primitives.end(), config.extra_primitives.begin(),
                          config.extra_primitives.end());
  impl->solids.reserve(impl->primitives.size());
  for (const ScenePrimitive& p : impl->primitives) impl->solids.push_back(makeSolid(p));
  impl->grid.build(impl->solids);
  impl->sun = Eigen::Vector3d(std::cos(config.sun_elevation) * std::cos(config.sun_azimuth),
                              std::cos(config.sun_elevation) * std::sin(config.sun_azimuth),
                              std::sin(config.sun_elevation));
  impl_ = std::move(impl);
}

const SceneConfig& ProceduralScene::config() const { return impl_->config; }

const std::vector<ScenePrimitive>& ProceduralScene::primitives() const { return impl_->primitives; }

double ProceduralScene::groundHeight(double x, double y) const {
  return impl_->ground.height(x, y);
}

Eigen::Vector3d ProceduralScene::groundNormal(double x, double y) const {
  return impl_->ground.normal(x, y);
}

double ProceduralScene::distanceToPath(const Eigen::Vector2d& xy) const {
  return impl_->path.distance(xy);
}

Eigen::Vector3d ProceduralScene::backdropCircle() const {
  return Eigen::Vector3d(impl_->backdrop.centre().x(), impl_->backdrop.centre().y(),
                         impl_->backdrop.radius());
}

bool ProceduralScene::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_distance, SceneHit* hit) const {
  return impl_->intersect(origin, direction, max_distance, nullptr, hit);
}

bool ProceduralScene::intersectCandidates(const Eigen::Vector3d& origin,
                                          const Eigen::Vector3d& direction, double max_distance,
                                          const PrimitiveCandidates& candidates,
                                          SceneHit* hit) const {
  return impl_->intersect(origin, direction, max_distance, &candidates, hit);
}

std::array<Eigen::Vector3d, 8> ProceduralScene::boundingCorners(int index) const {
  const Solid& s = impl_->solids.at(static_cast<size_t>(index));
  std::array<Eigen::Vector3d, 8> corners;
  for (int k = 0; k < 8; ++k) {
    const double a = (k & 1) ? 1.0 : -1.0, b = (k & 2) ? 1.0 : -1.0;
    const double z = (k & 4) ? s.z1 : s.z0;
    if (s.shape == ScenePrimitive::Shape::kBox) {
      corners[static_cast<size_t>(k)] =
          Eigen::Vector3d(s.cx + a * s.hx * s.cos_yaw - b * s.hy * s.sin_yaw,
                          s.cy + a * s.hx * s.sin_yaw + b * s.hy * s.cos_yaw, z);
    } else {
      corners[static_cast<size_t>(k)] = Eigen::Vector3d(s.cx + a * s.hx, s.cy + b * s.hx, z);
    }
  }
  return corners;
}

bool ProceduralScene::Impl::intersect(const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& direction, double max_distance,
                                      const PrimitiveCandidates* candidates, SceneHit* hit) const {
  // A descending ray's search for the ground is bounded by the slab of ground heights; a
  // ground hit nearer than the backdrop wall can be needs no wall test (most ground rays).
  const bool descending = direction.z() < 0.0;
  double t_backdrop = descending ? kInf : backdrop.intersect(origin, direction);
  Eigen::Vector3d ground_normal;
  const double t_ground =
      ground.intersect(origin, direction, std::min(max_distance, t_backdrop), &ground_normal);
  if (descending && !(t_ground < backdrop.minimumDistance(origin)))
    t_backdrop = backdrop.intersect(origin, direction);
  double best = std::min(max_distance, t_backdrop);
  SceneHit::Surface surface = SceneHit::Surface::kBackdrop;
  if (t_ground <= best) {
    best = t_ground;
    surface = SceneHit::Surface::kGround;
  }
  int index = -1, face = 0;
  if (candidates == nullptr) {
    grid.intersect(solids, origin, direction, &best, &index, &face);
  } else {
    for (size_t k = 0; k < candidates->count && candidates->min_distance[k] < best; ++k) {
      int f = 0;
      const int id = candidates->index[k];
      const double t = intersectSolid(solids[static_cast<size_t>(id)], origin, direction, &f);
      if (t < best) {
        best = t;
        index = id;
        face = f;
      }
    }
  }
  if (index >= 0) surface = SceneHit::Surface::kStructure;
  if (surface == SceneHit::Surface::kBackdrop) {
    // Nothing nearer: the backdrop wall below the skyline, else the sky.
    if (!(t_backdrop <= max_distance)) return false;
    if (!backdrop.belowSkyline(origin + t_backdrop * direction)) return false;
  }
  hit->surface = surface;
  hit->distance = best;
  hit->point = origin + best * direction;
  hit->primitive = index;
  hit->face = face;
  switch (surface) {
    case SceneHit::Surface::kGround:
      hit->normal = ground_normal;
      break;
    case SceneHit::Surface::kStructure:
      hit->normal = solidNormal(solids[static_cast<size_t>(index)], hit->point, face);
      break;
    case SceneHit::Surface::kBackdrop: {
      const Eigen::Vector2d inward = backdrop.centre() - hit->point.head<2>();
      hit->normal = Eigen::Vector3d(inward.x(), inward.y(), 0.0).normalized();
      break;
    }
  }
  return true;
}

Eigen::Vector3f ProceduralScene::shade(const SceneHit& hit, double footprint) const {
  const Impl& s = *impl_;
  double u = 0.0, v = 0.0, scale = 1.0;
  std::uint32_t seed = 0;
  Eigen::Vector3f tint;
  s.surfaceFrame(hit, &u, &v, &seed, &tint, &scale);
  const double inverse_scale = 1.0 / scale;
  const float pattern =
      texturePattern(u * inverse_scale, v * inverse_scale, footprint * inverse_scale, seed);
  const double lambert =
      s.config.ambient + (1.0 - s.config.ambient) * std::max(0.0, hit.normal.dot(s.sun));
  const Eigen::Vector3f colour = tint * (pattern * static_cast<float>(lambert));
  // Aerial perspective: far surfaces fade a little towards the horizon's colour.
  const float haze = static_cast<float>(hit.distance / (hit.distance + 2500.0));
  return colour + haze * (kHorizon - colour);
}

Eigen::Vector3f ProceduralScene::skyColor(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3f zenith(0.42f, 0.56f, 0.84f);
  const float up = static_cast<float>(std::max(0.0, direction.z()));
  Eigen::Vector3f colour = kHorizon + std::sqrt(up) * (zenith - kHorizon);
  if (direction.z() > 0.02) {
    // Soft clouds, a function of the direction only (the sky is at infinity).
    const double scale = 1.5 / (direction.z() + 0.15);
    const float n =
        valueNoise(scale * direction.x(), scale * direction.y(), impl_->backdrop_seed ^ 0x1234567U);
    const float cover =
        0.35f * smoothUnit(std::min(1.0f, std::max(0.0f, 1.25f * n))) * std::min(1.0f, 10.0f * up);
    colour += cover * (Eigen::Vector3f(0.93f, 0.93f, 0.94f) - colour);
  }
  return colour;
}

}  // namespace osc
