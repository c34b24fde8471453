/// @file procedural_scene.h
/// @brief A static, seeded, procedurally generated outdoor scene for simulation: a gently
/// undulating textured ground, upright structures (boxes, walls, trees) along the vehicle's
/// path, a far backdrop with a jagged skyline, and a sky at infinity. It answers ray queries
/// exactly and shades surfaces with a band-limited texture.
///
/// World frame: z up, the vehicle drives roughly in the x-y plane. Every texture is a
/// function of the surface point alone, so a point looks the same from any viewpoint (up to
/// the band limit; Lambert shading does not depend on the viewpoint either). The texture is
/// a mip-mapped pattern atlas baked once per process (~0.2 s, on the first shade()) from
/// procedural layers: spectral fractal noise, sharp-edged blobs and rectangular patches from
/// 5 cm to 1.6 m, sampled twice per point (rotated, enlarged) so it never repeats.
/// Generation, texture and everything else are deterministic from the seed on a given
/// platform (libm may differ in the last bits elsewhere).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace osc {

/// One upright solid of the scene. Its bottom may be buried in the ground.
struct ScenePrimitive {
  enum class Shape { kBox, kCylinder, kSphere, kCone };
  Shape shape = Shape::kBox;
  /// Box, cylinder, cone: centre of the bottom face (world, m). Sphere: its centre.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  /// Box: full length along its own x axis, width along its y axis, height.
  /// Cylinder and cone: (radius, unused, height). Sphere: (radius, unused, unused). Metres.
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  /// Box only: angle (rad) from the world x axis to the box's x axis, about z.
  double yaw = 0.0;
  /// Linear RGB albedo multiplier of the texture, each channel in [0, 1].
  Eigen::Vector3f tint = Eigen::Vector3f::Constant(0.6f);
  /// Selects the texture pattern: different seeds give unrelated patterns.
  std::uint32_t texture_seed = 0;
};

/// Parameters of a ProceduralScene. All lengths in metres, angles in radians.
struct SceneConfig {
  /// Seed of everything random in the scene (layout, sizes, textures).
  unsigned seed = 7;
  /// Largest height of the ground's undulation about z = 0; 0 gives the flat plane z = 0.
  double ground_undulation = 0.3;
  /// Horizontal wavelength of the undulation; long against its height keeps slopes gentle.
  double ground_wavelength = 40.0;
  /// Mean number of generated structures per hectare (10^4 m^2) near the path.
  double structure_density = 40.0;
  /// No generated structure comes closer than this to the path (its footprint, not centre).
  double min_structure_distance = 2.0;
  /// Structures are generated with centres up to this distance from the path.
  double max_structure_distance = 80.0;
  /// Least distance from the path to the far backdrop: a vertical cylinder around the whole
  /// path (centred on its bounding box, so parts of a long path are farther from it) with a
  /// jagged top 6-22 % of this distance tall; the sky lies above it.
  double backdrop_distance = 200.0;
  /// x-y polyline the vehicle drives (world frame). Empty means the origin alone: the
  /// structures then stand 2-80 m around the origin. Its extent must stay below 20 km.
  std::vector<Eigen::Vector2d> path;
  /// Solids added to the generated ones as they are (e.g. a wall placed by a test).
  std::vector<ScenePrimitive> extra_primitives;
  /// Generate no structures at all (ground, backdrop and extra_primitives only).
  bool generate_structures = true;
  /// Direction of the sun: elevation above the horizon and azimuth from +x towards +y.
  double sun_elevation = 0.9;
  double sun_azimuth = 0.6;
  /// Share of the light that is ambient (lights surfaces facing away from the sun), [0, 1].
  double ambient = 0.35;

  /// All problems of this config, each naming its field; empty when valid.
  std::vector<std::string> validate() const;
};

/// A ray's first intersection with the scene.
struct SceneHit {
  enum class Surface { kGround, kStructure, kBackdrop };
  Surface surface = Surface::kGround;
  /// Distance along the (unit) ray direction, metres.
  double distance = 0.0;
  /// The intersection point, world frame.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// Unit shading normal, world frame (the ground's is interpolated, so it is smooth).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// Index into ProceduralScene::primitives() for kStructure, else -1.
  int primitive = -1;
  /// Face of the primitive (box: 0..4 = +x,-x,+y,-y,top; cylinder and cone: 0 side, 1 cap).
  int face = 0;
};

/// A subset of the primitives for ProceduralScene::intersectCandidates, e.g. those whose
/// bounds overlap one image tile, sorted by `min_distance` (ascending).
struct PrimitiveCandidates {
  /// Indices into ProceduralScene::primitives().
  const int* index = nullptr;
  /// Lower bounds on the distance along any of the rays at which each can be hit.
  const double* min_distance = nullptr;
  std::size_t count = 0;
};

/// The scene. Immutable after construction, so every const method is thread-safe; copies
/// share the generated data.
class ProceduralScene {
 public:
  /// Generates the structures of every cell near the path (deterministic from the seed and
  /// the cell index, so a cell does not depend on how long the path is).
  /// @throws std::invalid_argument listing every problem of config.validate().
  explicit ProceduralScene(const SceneConfig& config);

  const SceneConfig& config() const;

  /// First surface hit by origin + t * direction for 0 < t <= max_distance; `direction`
  /// must be a unit vector. False when the ray escapes to the sky.
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 double max_distance, SceneHit* hit) const;

  /// As intersect(), but of the structures only the candidates are tested (the caller
  /// guarantees the others cannot be hit, e.g. by culling against the rays of an image tile).
  /// This is what makes rendering fast; the answer is the same as intersect()'s.
  bool intersectCandidates(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                           double max_distance, const PrimitiveCandidates& candidates,
                           SceneHit* hit) const;

  /// Corners (world frame) of a box that encloses primitive `index`: for culling.
  std::array<Eigen::Vector3d, 8> boundingCorners(int index) const;

  /// Linear RGB radiance (about [0, 1]) of a hit surface: texture times Lambert shading,
  /// with a little haze towards the horizon's colour with distance. `footprint` is the
  /// size (m) of the area one image sample covers there; texture detail finer than it is
  /// faded out (the texture's anti-aliasing).
  Eigen::Vector3f shade(const SceneHit& hit, double footprint) const;

  /// Linear RGB radiance of the sky seen in a direction (at infinity: it has no 3D point).
  Eigen::Vector3f skyColor(const Eigen::Vector3d& direction) const;

  /// Height of the ground at (x, y), the surface intersect() hits (to put a vehicle on it).
  double groundHeight(double x, double y) const;
  /// Unit (shading) normal of the ground at (x, y).
  Eigen::Vector3d groundNormal(double x, double y) const;

  /// Every solid: the generated ones, then config().extra_primitives.
  const std::vector<ScenePrimitive>& primitives() const;

  /// Distance from an x-y point to the path, or +infinity beyond
  /// max_structure_distance + 100 m of it.
  double distanceToPath(const Eigen::Vector2d& xy) const;

  /// Centre (x, y) and radius of the backdrop cylinder.
  Eigen::Vector3d backdropCircle() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace osc
