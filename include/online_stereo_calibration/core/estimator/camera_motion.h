/// @file camera_motion.h
/// @brief One camera's motion between two images from the same points seen in both: the
/// essential matrix by RANSAC (five-point, cv::findEssentialMat), its decomposition
/// (cv::recoverPose) and a Gauss-Newton refinement on the Sampson distances of every point
/// within the threshold, in the camera's *body* frame (pose.h: x forward, y left, z up).
///
/// Used by the hand-eye start (mounting_from_motion.h) for the left camera's rotation and
/// translation direction between consecutive frames.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace osc {

/// Thresholds of one camera-motion fit.
struct CameraMotionConfig {
  int min_points = 15;            ///< fewest common points for a fit
  int min_inliers = 12;           ///< fewest RANSAC inliers for a usable fit
  double ransac_threshold = 1.5;  ///< px (converted with the focal length), Sampson distance
  /// Least median parallax (px) of the inliers after removing the fitted rotation: below it
  /// the translation direction (and the essential matrix) is not determined.
  double min_parallax = 1.0;
  double focal = 600.0;  ///< px, to convert the pixel thresholds to normalised units
};

/// The fitted motion. Frames: c0 = camera body at the first image, c1 at the second.
struct CameraMotion {
  bool valid = false;
  std::string why;  ///< when not valid: why (too few points, parallax, ...)
  /// R_c0_c1: rotation of the camera body frame at the second image in the first.
  Eigen::Matrix3d R_prev_curr = Eigen::Matrix3d::Identity();
  /// Unit direction of the camera's translation (c1's origin in c0), in c0 body coordinates.
  Eigen::Vector3d translation_direction = Eigen::Vector3d::UnitX();
  int points = 0;         ///< common points given
  int inliers = 0;        ///< RANSAC inliers in front of both cameras
  double parallax = 0.0;  ///< median parallax (px) of the inliers after derotation
};

/// Fits the motion from normalised undistorted coordinates (x/z, y/z in the optical frame)
/// of the same points in the previous (@p previous) and current (@p current) image.
CameraMotion estimateCameraMotion(const std::vector<Eigen::Vector2d>& previous,
                                  const std::vector<Eigen::Vector2d>& current,
                                  const CameraMotionConfig& config);

}  // namespace osc
