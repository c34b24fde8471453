/// @file stereo_rectification.h
/// @brief Stereo rectification from the current left->right estimate (the R and P of
/// sensor_msgs/CameraInfo), and two quality figures of an estimate: how far a frame's stereo
/// pairs lie apart vertically after rectifying with it, and the depth uncertainty its
/// covariance alone causes.
///
/// Frames: optical (z forward, x right, y down). The left->right transform is
/// StereoExtrinsics::leftToRightOptical() (T_lopt_ropt, pose.h).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// How to rectify (cv::stereoRectify's free parameters).
struct RectificationSettings {
  /// Free scaling in [0, 1]: 0 = only valid pixels in the rectified images (zoomed in), 1 =
  /// every source pixel kept (black borders); -1 = OpenCV's default. For equidistant
  /// (fisheye) cameras it is cv::fisheye::stereoRectify's balance (clamped to [0, 1]).
  double alpha = 0.0;
  /// Size of the rectified images (px); 0 = the left camera's image size.
  int width = 0;
  int height = 0;
};

/// A stereo rectification in CameraInfo terms (sensor_msgs/CameraInfo R and P).
struct StereoRectification {
  /// Rotation from each camera's optical frame into its rectified frame (CameraInfo R):
  /// p_rect = R * p_optical.
  Eigen::Matrix3d R_left = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_right = Eigen::Matrix3d::Identity();
  /// Projection of the rectified frames (CameraInfo P, px): P_left = [f 0 cx 0; 0 f cy 0;
  /// 0 0 1 0], P_right the same with P(0,3) = -f * baseline (baseline in m).
  Eigen::Matrix<double, 3, 4> P_left = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix<double, 3, 4> P_right = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 0;   ///< rectified image size (px)
  int height = 0;  ///< rectified image size (px)
  /// The left->right transform it was computed from (T_lopt_ropt).
  Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();

  /// Rectified pixel of a raw (distorted) pixel of the left (or right) camera; false where
  /// the lens model has no valid ray for it.
  bool rectifyLeft(const CameraModel& left, const Eigen::Vector2d& raw,
                   Eigen::Vector2d* rectified) const;
  bool rectifyRight(const CameraModel& right, const Eigen::Vector2d& raw,
                    Eigen::Vector2d* rectified) const;
};

/// R and P of both cameras for the left->right transform T_lopt_ropt (cv::stereoRectify with
/// CALIB_ZERO_DISPARITY; cv::fisheye::stereoRectify for equidistant cameras).
/// @throws std::invalid_argument for an invalid camera, a non-finite transform, a zero
/// baseline, a negative size or an alpha outside [-1, 1] (each named).
StereoRectification computeStereoRectification(const CameraIntrinsics& left,
                                               const CameraIntrinsics& right,
                                               const Eigen::Isometry3d& T_lopt_ropt,
                                               const RectificationSettings& settings);

/// How far (px) rectified images made with @p rectification would move if it were recomputed
/// from @p T_lopt_ropt: the largest focal length times the sum of the rotation angle between
/// the two relative rotations and the angle between the two baseline directions (first order;
/// a change of the baseline length alone moves no pixel, only P's disparity scale).
double rectificationChangePx(const StereoRectification& rectification,
                             const Eigen::Isometry3d& T_lopt_ropt);

/// The rectification error of a frame's stereo pairs.
struct RectificationError {
  double median_px = 0.0;  ///< median |v_left - v_right| of the rectified pairs (px)
  int pairs = 0;           ///< pairs that entered the median
};

/// Median |v_left - v_right| (px) of the pairs' raw pixels rectified with @p rectification;
/// empty when no pair could be rectified (no pairs, or none with a valid ray).
std::optional<RectificationError> rectificationError(const std::vector<StereoObservation>& pairs,
                                                     const CameraModel& left,
                                                     const CameraModel& right,
                                                     const StereoRectification& rectification);

/// 1-sigma depth uncertainty (m) that the calibration's covariance alone causes for a point at
/// @p depth (m) on the left camera's optical axis: the point's two pixels are fixed (exact for
/// @p extrinsics) and triangulated (midpoint, stereo_geometry.h) with x_camr perturbed along
/// the filter's tangent error (pose.h boxPlus on T_caml_camr); first-order propagation
/// sigma^2 = J C J^T with J by central differences and C the x_camr block of
/// @p tangent_covariance (indices 6-11 of [dt_l, dtheta_l, dt_r, dtheta_r]; x_caml does not
/// change a depth in the camera frame).
/// @throws std::invalid_argument for a non-positive or non-finite depth, a non-finite
/// covariance, or a point the cameras cannot triangulate (e.g. zero baseline).
double depthSigmaOnAxis(const StereoExtrinsics& extrinsics, const Matrix12d& tangent_covariance,
                        double depth);

/// Depth (m) of the point on the left optical axis at @p true_depth (m), seen exactly by the
/// cameras of @p truth, triangulated with x_camr perturbed by @p delta_camr (tangent, boxPlus on
/// T_caml_camr). Empty if the perturbed rays do not meet in front of both cameras. The function
/// depthSigmaOnAxis linearises; a Monte-Carlo over it checks that.
std::optional<double> depthOnAxisWithPerturbedCamr(const StereoExtrinsics& truth,
                                                   const Vector6d& delta_camr, double true_depth);

}  // namespace osc
