/// @file stereo_geometry.h
/// @brief Two-view geometry of the stereo pair: fundamental matrix (seed eq. 5), epipolar
/// lines (eq. 6) and midpoint triangulation (Sec. II-A).
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace osc {

/// Essential matrix E = [t]x R with (R, t) = T_ropt_lopt, so x_r^T E x_l = 0 for normalized
/// homogeneous rays of the same point.
Eigen::Matrix3d essentialMatrix(const Eigen::Isometry3d& T_lopt_ropt);

/// Seed eq. 5: F = K_r^-T [t]x R K_l^-1, so that x_r^T F x_l = 0 for undistorted pixels.
Eigen::Matrix3d fundamentalMatrix(const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                                  const Eigen::Isometry3d& T_lopt_ropt);

/// Seed eq. 6: epipolar line l_r = F x_l in the right image, scaled so that
/// l.dot([u, v, 1]) is the signed distance in pixels.
Eigen::Vector3d epipolarLine(const Eigen::Matrix3d& F, const Eigen::Vector2d& left_pixel);

/// Sampson distance (pixels, first order geometric error) of a correspondence under F.
double sampsonDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& left_pixel,
                       const Eigen::Vector2d& right_pixel);

/// Result of midpoint triangulation.
struct Triangulation {
  Eigen::Vector3d point_left;  ///< midpoint of the shortest segment, left optical frame
  double ray_gap = 0.0;        ///< length of that segment (m)
  double parallax = 0.0;       ///< angle between the two rays (rad)
};

/// Midpoint of the shortest segment between the ray through the left camera centre along
/// ray_left (left optical frame) and the ray through the right camera centre along ray_right
/// (right optical frame). Empty if the rays are (nearly) parallel or the point is not in
/// front of both cameras.
std::optional<Triangulation> triangulateMidpoint(const Eigen::Vector3d& ray_left,
                                                 const Eigen::Vector3d& ray_right,
                                                 const Eigen::Isometry3d& T_lopt_ropt);

/// How far a stereo pair's triangulated depth can be from its value at the current baseline
/// while the baseline's length is uncertain: with the rays' directions fixed by the pixels,
/// the depth scales with the length, so over the length's +-`sigmas` interval it lies within
/// [shortest, longest] times its current value (shortest >= 0).
struct DepthScaleRange {
  double shortest = 1.0;
  double longest = 1.0;
};
/// @param baseline the right camera's position in the left camera's frame (m)
/// @param covariance its 3x3 covariance (m^2)
DepthScaleRange baselineDepthScaleRange(const Eigen::Vector3d& baseline,
                                        const Eigen::Matrix3d& covariance, double sigmas);

}  // namespace osc
