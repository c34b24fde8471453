/// @file measurement_model.h
/// @brief The stereo measurement of a point (seed eq. 29-30) and its inverse, stereo
/// triangulation (Sec. II-A). Measurements are *undistorted* pixels K * (x/z, y/z): the
/// front end removes the lens distortion with the camera model first.
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace osc {

/// Pinhole projection matrices of the two cameras (K of CameraInfo).
struct StereoIntrinsics {
  Eigen::Matrix3d K_left = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d K_right = Eigen::Matrix3d::Identity();
};

/// Seed eq. 29-30: z = [K_l * p, K_r * T_ropt_lopt * p] after perspective division.
/// False if the point is not at least min_depth in front of both cameras.
bool projectStereo(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_ropt_lopt,
                   const StereoIntrinsics& intrinsics, double min_depth, Eigen::Vector4d* z);

/// The same for a homogeneous point [d; w] (position d / w, point_coordinates.h). A point at
/// or beyond infinity (w <= 0) projects by its direction d, which must be in front of both.
bool projectHomogeneousStereo(const Eigen::Vector4d& point_lopt,
                              const Eigen::Isometry3d& T_ropt_lopt,
                              const StereoIntrinsics& intrinsics, double min_depth,
                              Eigen::Vector4d* z);

/// Inverse-depth triangulation of an undistorted stereo measurement z: the direction (a, b)
/// = (x/z, y/z) of the left pixel's ray and the inverse depth rho = 1/z that best puts the
/// point on the right pixel (linear least squares on the right image's two coordinates).
/// Defined for any disparity, also a negative one (rho < 0, a noisy far point); empty only
/// if the right pixel gives no information on rho (the rays are parallel for every depth).
std::optional<Eigen::Vector3d> triangulateInverseDepth(const Eigen::Vector4d& z,
                                                       const Eigen::Isometry3d& T_lopt_ropt,
                                                       const StereoIntrinsics& intrinsics);

/// Midpoint triangulation of an undistorted stereo measurement z; empty if the rays do not
/// meet in front of both cameras.
std::optional<Eigen::Vector3d> triangulateStereo(const Eigen::Vector4d& z,
                                                 const Eigen::Isometry3d& T_lopt_ropt,
                                                 const StereoIntrinsics& intrinsics);

}  // namespace osc
