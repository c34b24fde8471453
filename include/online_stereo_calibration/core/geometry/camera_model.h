/// @file camera_model.h
/// @brief Pinhole camera with the distortion models of sensor_msgs/CameraInfo:
/// plumb_bob, rational_polynomial and equidistant (fisheye).
///
/// Coordinates: a point in the camera's *optical* frame (z forward, x right, y down);
/// "normalized" = (x/z, y/z) before distortion; "undistorted pixel" = K * normalized.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace osc {

/// Distortion model names as in sensor_msgs/distortion_models.h.
enum class DistortionModel { kNone, kPlumbBob, kRationalPolynomial, kEquidistant };

/// Parses "plumb_bob", "rational_polynomial", "equidistant" (and "" or "none").
/// @throws std::invalid_argument naming the unknown model.
DistortionModel distortionModelFromName(const std::string& name);
std::string distortionModelName(DistortionModel model);

/// Intrinsics as carried by sensor_msgs/CameraInfo.
struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel model = DistortionModel::kNone;
  /// plumb_bob: k1 k2 p1 p2 [k3]; rational_polynomial: k1 k2 p1 p2 k3 k4 k5 k6;
  /// equidistant: k1 k2 k3 k4.
  std::vector<double> distortion;

  Eigen::Matrix3d K() const;
};

/// A validated camera model. Cheap to copy.
class CameraModel {
 public:
  CameraModel() = default;
  /// @throws std::invalid_argument with the offending field named (non-positive focal
  /// length or size, non-finite values, wrong number of distortion coefficients).
  explicit CameraModel(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  Eigen::Matrix3d K() const { return intrinsics_.K(); }

  /// Applies the lens distortion to normalized coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& normalized) const;
  /// Inverse of distort (iterative); exact to ~1e-10 inside the image. Where the lens model
  /// has no valid preimage (see the overload below) the input is returned unchanged.
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted_normalized) const;
  /// Inverse of distort on the part of the model that maps rays one-to-one (from the
  /// optical axis up to the first fold, where a strong barrel polynomial turns back, e.g.
  /// plumb_bob k1 = -0.28 beyond r = 1.09). False, *normalized untouched, where no such
  /// preimage exists (pixels beyond what the polynomial can reach): such a pixel has no
  /// valid ray under this model, and any "solution" would be a wrong, folded one.
  bool undistort(const Eigen::Vector2d& distorted_normalized, Eigen::Vector2d* normalized) const;

  /// Optical-frame point -> raw (distorted) pixel. False if the point is not in front
  /// (z <= 1e-6), pixel untouched then.
  bool project(const Eigen::Vector3d& point_optical, Eigen::Vector2d* pixel) const;
  /// Raw pixel -> normalized undistorted coordinates (x/z, y/z).
  Eigen::Vector2d pixelToNormalized(const Eigen::Vector2d& pixel) const;
  /// As above; false where the lens model has no valid ray for the pixel (undistort).
  bool pixelToNormalized(const Eigen::Vector2d& pixel, Eigen::Vector2d* normalized) const;
  /// Raw pixel -> undistorted pixel K * normalized (the filter's measurement space).
  Eigen::Vector2d undistortPixel(const Eigen::Vector2d& pixel) const;
  /// As above; false where the lens model has no valid ray for the pixel (undistort).
  bool undistortPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* undistorted) const;
  /// Normalized coordinates -> raw pixel.
  Eigen::Vector2d normalizedToPixel(const Eigen::Vector2d& normalized) const;
  /// How the lens stretches small offsets around an undistorted pixel: d raw pixel /
  /// d undistorted pixel there (central differences over +-0.5 px; exactly the identity
  /// without distortion).
  Eigen::Matrix2d lensJacobian(const Eigen::Vector2d& undistorted_pixel) const;
  /// Variance (undistorted px^2) of each coordinate of an undistorted pixel whose raw pixel
  /// has @p raw_sigma (px) per coordinate. Undistorting stretches the raw noise by the inverse
  /// of lensJacobian (a fisheye's edge: 2.4 times radially at 50 deg off its axis); one
  /// variance for both coordinates, so the largest stretch (exactly raw_sigma^2 without
  /// distortion).
  double undistortedPixelVariance(const Eigen::Vector2d& undistorted_pixel, double raw_sigma) const;

  /// True if the pixel lies inside the image with the given margin (pixels).
  bool isInImage(const Eigen::Vector2d& pixel, double margin = 0.0) const;

 private:
  CameraIntrinsics intrinsics_;
};

}  // namespace osc
