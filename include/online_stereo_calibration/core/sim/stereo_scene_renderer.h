/// @file stereo_scene_renderer.h
/// @brief Renders a ProceduralScene for any camera (pinhole + distortion) and pose, and
/// answers the exact ground-truth questions a front-end test needs: where is a 3D point in
/// the image and is it visible; which 3D point does a pixel see.
///
/// Pixel convention (OpenCV, image_geometry): the centre of pixel (u, v) is at raw pixel
/// coordinates (u, v); the pixel covers [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5].
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/sim/procedural_scene.h"

namespace osc {

/// Exposure gain of the images of a blind frame (MeasurementScenario::blind_frames): the
/// scene at 2 % of its brightness, a few grey levels under the usual pixel noise, so that
/// the front end finds no feature (darkness, a texture-poor view).
constexpr double kBlindFrameExposureGain = 0.02;

/// How one image is produced from the scene.
struct RenderOptions {
  /// Standard deviation of additive Gaussian pixel noise, in grey levels (0-255 scale).
  double noise_sigma = 0.0;
  /// Standard deviation (px) of a Gaussian blur standing for the optics; 0 = none.
  double blur_sigma = 0.0;
  /// Brightness factor of this frame (exposure time x gain), > 0.
  double exposure_gain = 1.0;
  /// bgr8 (CV_8UC3) if true, else mono8 (CV_8UC1).
  bool color = false;
  /// Sub-samples per pixel and axis (1-4) where a pixel straddles a geometric edge (its
  /// neighbours see other surfaces). Textures are band-limited to the pixel footprint
  /// (mip-mapped), so the rest of the image needs a single sample.
  int supersampling = 2;
  /// Supersample every pixel, not only edges (slower; a reference for the adaptive mode).
  bool supersample_all = false;
  /// Seed of the pixel noise: the same seed gives the same noise. Use e.g. the frame index.
  unsigned noise_seed = 0;

  /// All problems, each naming its field; empty when valid.
  std::vector<std::string> validate() const;
};

/// Renderer and ground-truth oracle over one scene. All methods are const and thread-safe.
/// Per camera model (the last four) it caches the undistorted ray of every pixel
/// (undistortion is iterative), so the first render with a new camera takes longer (~0.1 s
/// pinhole, ~0.4 s distorted at 640x480 on one core). About 60 ms per 640x480 frame on one
/// core after that (benchmark/bench_stereo_scene_renderer.cpp).
class StereoSceneRenderer {
 public:
  /// @throws std::invalid_argument naming every bad field of the config.
  explicit StereoSceneRenderer(const SceneConfig& config);
  explicit StereoSceneRenderer(ProceduralScene scene);
  ~StereoSceneRenderer();
  StereoSceneRenderer(StereoSceneRenderer&&) noexcept;
  StereoSceneRenderer& operator=(StereoSceneRenderer&&) noexcept;

  const ProceduralScene& scene() const { return scene_; }

  /// The raw (distorted) image of `camera` at pose T_world_optical (optical frame: z forward,
  /// x right, y down). Pixels that no ray of the camera reaches (beyond a fold of the
  /// distortion model) are black.
  /// Uses cv::parallel_for_ over rows (honours cv::setNumThreads).
  /// @throws std::invalid_argument naming a bad field of the options.
  cv::Mat render(const CameraModel& camera, const Eigen::Isometry3d& T_world_optical,
                 const RenderOptions& options = RenderOptions()) const;

  /// True if the world point is seen by the camera: in front of it, projecting inside the
  /// image (the pixel area, [-0.5, width - 0.5) x [-0.5, height - 0.5)), inside the domain
  /// where the distortion model is one-to-one, and not hidden behind a surface (a ray cast
  /// from the camera centre towards the point; the point may lie on a surface: a hit within
  /// 1e-6 (1 + distance) m of it does not hide it).
  /// `raw_pixel` (optional) receives the exact raw pixel whenever the point is in front of
  /// the camera, visible or not.
  bool projectVisible(const CameraModel& camera, const Eigen::Isometry3d& T_world_optical,
                      const Eigen::Vector3d& p_world, Eigen::Vector2d* raw_pixel) const;

  /// The world point seen at a raw pixel (exact ray cast through the undistorted pixel), or
  /// nothing for the sky or a pixel outside the distortion model's domain.
  std::optional<Eigen::Vector3d> surfacePoint(const CameraModel& camera,
                                              const Eigen::Isometry3d& T_world_optical,
                                              const Eigen::Vector2d& raw_pixel) const;

 private:
  class Cache;
  ProceduralScene scene_;
  std::unique_ptr<Cache> cache_;
};

}  // namespace osc
