#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace osc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTile = 16;     // image tiles (px) that share one list of candidate primitives
constexpr int kGroundId = 1;  // Sample::id of the ground

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

bool sameIntrinsics(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && a.model == b.model && a.distortion == b.distortion;
}

/// True if the distortion is one-to-one from the optical axis out to normalized point n:
/// the distorted radius keeps growing along the ray. Beyond a fold (e.g. k1 < 0 without a
/// compensating k2) a raw pixel can have a second, spurious preimage far off-axis or on the
/// opposite side; those rays do not exist in the real camera.
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

/// Normalized coordinates of a raw pixel, or nothing if no ray of the camera reaches it.
std::optional<Eigen::Vector2d> pixelRay(const CameraModel& camera, const Eigen::Vector2d& pixel) {
  Eigen::Vector2d n;
  if (!camera.pixelToNormalized(pixel, &n) || !inPrincipalDomain(camera, n)) return std::nullopt;
  return n;
}

/// As pixelRay(), NaN for no ray (the form the ray cache stores).
Eigen::Vector2f undistortChecked(const CameraModel& camera, const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector2d> n = pixelRay(camera, pixel);
  return n ? Eigen::Vector2f(n->cast<float>())
           : Eigen::Vector2f::Constant(std::numeric_limits<float>::quiet_NaN());
}

/// Unit ray through normalized coordinates n (optical frame).
Eigen::Vector3d rayOf(const Eigen::Vector2f& n) {
  const double x = n.x(), y = n.y(), inverse_norm = 1.0 / std::sqrt(x * x + y * y + 1.0);
  return Eigen::Vector3d(x * inverse_norm, y * inverse_norm, inverse_norm);
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

/// Radiance and surface identity of one image sample.
struct Sample {
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();
  int id = -1;  // -1 no ray, 0 sky, kGroundId, 2 backdrop, 3 + 8 * primitive + face
};

Sample traceSample(const ProceduralScene& scene, const PrimitiveCandidates& candidates,
                   const Eigen::Vector3d& origin, const Eigen::Matrix3d& rotation,
                   const Eigen::Vector2f& normalized, float pixel_angle) {
  Sample sample;
  if (!normalized.allFinite()) return sample;
  const Eigen::Vector3d direction = rotation * rayOf(normalized);
  SceneHit hit;
  if (!scene.intersectCandidates(origin, direction, kInf, candidates, &hit)) {
    sample.colour = scene.skyColor(direction);
    sample.id = 0;
    return sample;
  }
  // The footprint is an ellipse on a tilted surface, stretched by 1 / cosine along the view;
  // an isotropic filter has to compromise between blurring across it and aliasing along it
  // (cosine^-0.75 aliases little on the ground seen at grazing angles).
  const float cosine = std::max(0.02f, static_cast<float>(std::abs(hit.normal.dot(direction))));
  const float stretch = 1.0f / (cosine * std::sqrt(std::sqrt(1.0f / cosine)));  // cosine^-0.75
  const double footprint = hit.distance * static_cast<double>(pixel_angle * stretch);
  sample.colour = scene.shade(hit, footprint);
  switch (hit.surface) {
    case SceneHit::Surface::kGround:
      sample.id = kGroundId;
      break;
    case SceneHit::Surface::kBackdrop:
      sample.id = 2;
      break;
    case SceneHit::Surface::kStructure:
      sample.id = 3 + 8 * hit.primitive + hit.face;
      break;
  }
  return sample;
}

/// Normalized ray at a position inside pixel (u, v), offsets in [0, 1] from its top-left
/// corner, by bilinear interpolation of the corner rays (far below 0.01 px off the exact ray).
Eigen::Vector2f subpixelRay(const CameraRays& rays, int u, int v, float a, float b) {
  const Eigen::Vector2f &c00 = rays.cornerAt(u, v), &c10 = rays.cornerAt(u + 1, v),
                        &c01 = rays.cornerAt(u, v + 1), &c11 = rays.cornerAt(u + 1, v + 1);
  if (!(c00.allFinite() && c10.allFinite() && c01.allFinite() && c11.allFinite())) {
    return rays.centre[static_cast<size_t>(u + rays.width * v)];
  }
  return (1.0f - b) * ((1.0f - a) * c00 + a * c10) + b * ((1.0f - a) * c01 + a * c11);
}

/// The centre samples of a frame, one array per field: the edge search reads only ids.
struct SampleImage {
  std::vector<Eigen::Vector3f> colour;
  std::vector<int> id;

  void resize(size_t count) {
    colour.resize(count);
    id.resize(count);
  }
  void set(size_t k, const Sample& s) {
    colour[k] = s.colour;
    id[k] = s.id;
  }
};

/// Buffers of one render, kept for the next: allocating ~10 MB anew each frame costs page
/// faults.
struct Scratch {
  SampleImage samples;
  cv::Mat image, grey, noise;
};

/// Traces the samples of one frame: a camera's rays at one pose.
struct FrameTracer {
  const ProceduralScene& scene;
  const CameraRays& rays;
  const TileCandidates& candidates;
  Eigen::Matrix3d rotation;  // R_world_optical
  Eigen::Vector3d origin;    // camera centre, world

  Sample centre(int u, int v) const {
    const size_t k = static_cast<size_t>(u + rays.width * v);
    return traceSample(scene, candidates.at(u, v), origin, rotation, rays.centre[k], rays.angle[k]);
  }

  /// Mean of n x n stratified samples over pixel (u, v), each band-limited to its share of
  /// the pixel (their mean is then the pixel's box filter).
  Eigen::Vector3f supersampled(int u, int v, int n) const {
    const float step = 1.0f / static_cast<float>(n);
    const float angle = step * rays.angle[static_cast<size_t>(u + rays.width * v)];
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector2f ray = subpixelRay(rays, u, v, (i + 0.5f) * step, (j + 0.5f) * step);
        sum += traceSample(scene, candidates.at(u, v), origin, rotation, ray, angle).colour;
      }
    }
    return sum * (step * step);
  }
};

/// Pass 1: one sample at every pixel centre.
void traceCentres(const FrameTracer& tracer, SampleImage* samples) {
  const int w = tracer.rays.width, h = tracer.rays.height;
  samples->resize(static_cast<size_t>(w) * h);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      for (int u = 0; u < w; ++u) samples->set(static_cast<size_t>(u + w * v), tracer.centre(u, v));
    }
  });
}

/// True if pixel (u, v) straddles a geometric edge: a 4-neighbour sees another surface.
/// (The ground can also hide part of itself behind a gentle crest, but both sides are the
/// same ground texture, so that edge has next to no contrast to alias.)
bool atEdge(const SampleImage& samples, int w, int h, int u, int v) {
  const size_t k = static_cast<size_t>(u + w * v);
  const int id = samples.id[k];
  return (u > 0 && samples.id[k - 1] != id) || (u + 1 < w && samples.id[k + 1] != id) ||
         (v > 0 && samples.id[k - static_cast<size_t>(w)] != id) ||
         (v + 1 < h && samples.id[k + static_cast<size_t>(w)] != id);
}

/// Pass 2: the image (float BGR, 0-255 scale, times the exposure gain), supersampling the
/// pixels at edges (or every pixel if asked). Textures are anti-aliased analytically, so
/// the other pixels keep their single sample.
void resolvePixels(const FrameTracer& tracer, const SampleImage& samples,
                   const RenderOptions& options, cv::Mat* image) {
  const int w = tracer.rays.width, h = tracer.rays.height, n = options.supersampling;
  const float scale = static_cast<float>(255.0 * options.exposure_gain);
  image->create(h, w, CV_32FC3);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      auto* row = image->ptr<cv::Vec3f>(v);
      for (int u = 0; u < w; ++u) {
        const size_t k = static_cast<size_t>(u + w * v);
        const bool supersample =
            n > 1 && samples.id[k] >= 0 && (options.supersample_all || atEdge(samples, w, h, u, v));
        const Eigen::Vector3f colour =
            supersample ? tracer.supersampled(u, v, n) : samples.colour[k];
        row[u] = cv::Vec3f(colour.z() * scale, colour.y() * scale, colour.x() * scale);  // BGR
      }
    }
  });
}

/// Camera effects on the float image: optics blur, grey conversion, sensor noise, then
/// 8-bit quantisation (rounded and saturated).
cv::Mat applyCameraEffects(const RenderOptions& options, Scratch* scratch) {
  cv::Mat& image = scratch->image;
  if (options.blur_sigma > 0.0) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), options.blur_sigma, options.blur_sigma,
                     cv::BORDER_REFLECT);
  }
  cv::Mat& result = options.color ? image : scratch->grey;
  if (!options.color) cv::cvtColor(image, result, cv::COLOR_BGR2GRAY);
  if (options.noise_sigma > 0.0) {
    scratch->noise.create(result.size(), result.type());
    cv::RNG rng(0x9e3779b97f4a7c15ULL ^ options.noise_seed);
    rng.fill(scratch->noise, cv::RNG::NORMAL, 0.0, options.noise_sigma);
    result += scratch->noise;
  }
  cv::Mat out;
  result.convertTo(out, options.color ? CV_8UC3 : CV_8UC1);
  return out;
}

}  // namespace

std::vector<std::string> RenderOptions::validate() const {
  std::vector<std::string> errors;
  if (!(std::isfinite(noise_sigma) && noise_sigma >= 0.0))
    errors.push_back("noise_sigma must be >= 0");
  if (!(std::isfinite(blur_sigma) && blur_sigma >= 0.0 && blur_sigma <= 20.0)) {
    errors.push_back("blur_sigma must be in [0, 20] px");
  }
  if (!(std::isfinite(exposure_gain) && exposure_gain > 0.0))
    errors.push_back("exposure_gain must be > 0");
  if (supersampling < 1 || supersampling > 4) errors.push_back("supersampling must be in [1, 4]");
  return errors;
}

/// What renders remember between calls: the rays of the few most recently used camera
/// models (shared with renders in flight) and spare scratch buffers.
class StereoSceneRenderer::Cache {
 public:
  std::shared_ptr<const CameraRays> rays(const CameraModel& camera) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t k = 0; k < rays_.size(); ++k) {
      if (sameIntrinsics(rays_[k]->intrinsics, camera.intrinsics())) {
        std::rotate(rays_.begin(), rays_.begin() + static_cast<std::ptrdiff_t>(k),
                    rays_.begin() + static_cast<std::ptrdiff_t>(k) + 1);
        return rays_.front();
      }
    }
    rays_.insert(rays_.begin(), buildRays(camera));
    if (rays_.size() > kCameras) rays_.pop_back();
    return rays_.front();
  }

  std::unique_ptr<Scratch> takeScratch() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (scratch_.empty()) return std::make_unique<Scratch>();
    std::unique_ptr<Scratch> s = std::move(scratch_.back());
    scratch_.pop_back();
    return s;
  }

  void returnScratch(std::unique_ptr<Scratch> s) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (scratch_.size() < kScratch) scratch_.push_back(std::move(s));
  }

 private:
  static constexpr size_t kCameras = 4, kScratch = 2;
  std::mutex mutex_;
  std::vector<std::shared_ptr<const CameraRays>> rays_;
  std::vector<std::unique_ptr<Scratch>> scratch_;
};

StereoSceneRenderer::StereoSceneRenderer(const SceneConfig& config)
    : StereoSceneRenderer(ProceduralScene(config)) {}

StereoSceneRenderer::StereoSceneRenderer(ProceduralScene scene)
    : scene_(std::move(scene)), cache_(std::make_unique<Cache>()) {}

StereoSceneRenderer::~StereoSceneRenderer() = default;
StereoSceneRenderer::StereoSceneRenderer(StereoSceneRenderer&&) noexcept = default;
StereoSceneRenderer& StereoSceneRenderer::operator=(StereoSceneRenderer&&) noexcept = default;

cv::Mat StereoSceneRenderer::render(const CameraModel& camera,
                                    const Eigen::Isometry3d& T_world_optical,
                                    const RenderOptions& options) const {
  const std::vector<std::string> errors = options.validate();
  if (!errors.empty()) {
    std::string message = "invalid RenderOptions:";
    for (const std::string& e : errors) message += " " + e + ";";
    throw std::invalid_argument(message);
  }
  const std::shared_ptr<const CameraRays> rays = cache_->rays(camera);
  const TileCandidates candidates(scene_, *rays, T_world_optical);
  const FrameTracer tracer{scene_, *rays, candidates, T_world_optical.linear(),
                           T_world_optical.translation()};
  std::unique_ptr<Scratch> scratch = cache_->takeScratch();
  traceCentres(tracer, &scratch->samples);
  resolvePixels(tracer, scratch->samples, options, &scratch->image);
  cv::Mat out = applyCameraEffects(options, scratch.get());
  cache_->returnScratch(std::move(scratch));
  return out;
}

bool StereoSceneRenderer::projectVisible(const CameraModel& camera,
                                         const Eigen::Isometry3d& T_world_optical,
                                         const Eigen::Vector3d& p_world,
                                         Eigen::Vector2d* raw_pixel) const {
  const Eigen::Vector3d p_optical = T_world_optical.inverse() * p_world;
  Eigen::Vector2d pixel;
  if (!camera.project(p_optical, &pixel)) return false;
  if (raw_pixel != nullptr) *raw_pixel = pixel;
  const CameraIntrinsics& in = camera.intrinsics();
  if (!(pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < in.width - 0.5 &&
        pixel.y() < in.height - 0.5)) {
    return false;
  }
  // Outside the one-to-one domain (e.g. a strong barrel distortion folding back), a point
  // far off-axis can land inside the image; the camera does not see it there.
  if (!inPrincipalDomain(camera, p_optical.head<2>() / p_optical.z())) return false;
  const Eigen::Vector3d origin = T_world_optical.translation();
  const double distance = (p_world - origin).norm();
  if (!(distance > 1e-9)) return false;
  SceneHit hit;
  const double tolerance = 1e-6 * (1.0 + distance);
  return !scene_.intersect(origin, (p_world - origin) / distance, distance, &hit) ||
         hit.distance >= distance - tolerance;
}

std::optional<Eigen::Vector3d> StereoSceneRenderer::surfacePoint(
    const CameraModel& camera, const Eigen::Isometry3d& T_world_optical,
    const Eigen::Vector2d& raw_pixel) const {
  const std::optional<Eigen::Vector2d> n = pixelRay(camera, raw_pixel);
  if (!n) return std::nullopt;
  const Eigen::Vector3d direction =
      T_world_optical.linear() * Eigen::Vector3d(n->x(), n->y(), 1.0).normalized();
  SceneHit hit;
  if (!scene_.intersect(T_world_optical.translation(), direction, kInf, &hit)) return std::nullopt;
  return hit.point;
}

}  // namespace osc
