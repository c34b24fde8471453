/// @file stereo_scene_renderer.cpp
/// @brief StereoSceneRenderer: tracing the samples of a frame, resolving the pixels, the
/// camera effects, and the public API; the rays and the tiles' candidates in
/// stereo_scene_renderer_rays.cpp.
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "stereo_scene_renderer_internal.h"

namespace osc {

using namespace stereo_scene_renderer_internal;

namespace {

constexpr int kGroundId = 1;  // Sample::id of the ground

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
