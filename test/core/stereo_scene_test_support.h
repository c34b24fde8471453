/// @file stereo_scene_test_support.h
/// @brief Helpers of the procedural scene's and renderer's tests (test_stereo_scene_renderer,
/// test_procedural_scene_and_match_truth): a pinhole camera, a vehicle-mounted camera's pose
/// and its right neighbour, and the renderer of the default scene.
#pragma once

#include <Eigen/Geometry>

#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace osc {

inline CameraModel pinhole(int width = 640, int height = 480, double focal = 500.0) {
  CameraIntrinsics in;
  in.width = width;
  in.height = height;
  in.fx = in.fy = focal;
  in.cx = 0.5 * (width - 1);
  in.cy = 0.5 * (height - 1);
  return CameraModel(in);
}

/// Left optical frame of a vehicle-mounted camera 1.5 m above the ground at (x, y).
inline Eigen::Isometry3d cameraPose(const ProceduralScene& scene, double x, double y, double yaw,
                                    double pitch = 0.05) {
  Vector6d body;
  body << x, y, scene.groundHeight(x, y) + 1.5, 0.0, pitch, yaw;
  return poseFromParameters(body) * bodyFromOptical();
}

/// The right camera: `baseline` metres to the right of the left one (optical x is right).
inline Eigen::Isometry3d rightOf(const Eigen::Isometry3d& left, double baseline = 0.5) {
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() = Eigen::Vector3d(baseline, 0.0, 0.0);
  return left * offset;
}

inline const StereoSceneRenderer& defaultRenderer() {
  static const StereoSceneRenderer renderer{SceneConfig()};
  return renderer;
}

}  // namespace osc
