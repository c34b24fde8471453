/// @file point_coordinates.h
/// @brief How the filter stores a tracked point (FilterConfig::inverse_depth_points): as its
/// position (x, y, z) in the left optical frame (the seed's choice), or as inverse depth
/// (a, b, rho) = (x/z, y/z, 1/z) (Civera, Davison, Montiel, "Inverse Depth Parametrization
/// for Monocular SLAM", T-RO 2008). A new point's depth is +-100 % uncertain while x_camr's
/// rotation is (2 deg of prior is 20 px of disparity at 600 px focal length): its position
/// is then far from Gaussian, its inverse depth, linear in the disparity, is not. Every model
/// works on the homogeneous point [d; w] (position = d / w), which both kinds map to, so a far
/// point (rho -> 0) and a sigma point beyond infinity (rho < 0) stay well defined.
#pragma once

#include <Eigen/Core>

namespace osc {

/// [d (3); w]: the point d / w of the left optical frame; w = 1 for a position, rho for inverse
/// depth (then d = (a, b, 1)).
using HomogeneousPoint = Eigen::Vector4d;

/// One of the two ways of storing a point, with the conversions between them.
class PointCoordinates {
 public:
  explicit PointCoordinates(bool inverse_depth) : inverse_depth_(inverse_depth) {}

  bool inverseDepth() const { return inverse_depth_; }

  /// The homogeneous point of coordinates @p c.
  HomogeneousPoint homogeneous(const Eigen::Vector3d& c) const;
  /// The coordinates of @p h; false if it has none (inverse depth: not in front, d.z <= 0;
  /// position: w <= 0).
  bool fromHomogeneous(const HomogeneousPoint& h, Eigen::Vector3d* c) const;
  /// The coordinates of a position (m, left optical frame) with z > 0.
  Eigen::Vector3d fromPosition(const Eigen::Vector3d& position) const;
  /// The position (m) of @p c; an inverse depth below @p min_inverse_depth (1/m) is taken as
  /// that, so that a point at or beyond infinity gets a far position instead of none.
  Eigen::Vector3d position(const Eigen::Vector3d& c, double min_inverse_depth) const;
  /// The depth z (m) of @p c; +inf for an inverse depth <= 0.
  double depth(const Eigen::Vector3d& c) const;
  /// d c / d position at coordinates @p c (identity for positions); finite for any rho.
  Eigen::Matrix3d jacobianFromPosition(const Eigen::Vector3d& c) const;
  /// fromHomogeneous as a formula: c = N h / (n^T h), N = homogeneousNumerator() (the rows of
  /// h it picks), n = homogeneousDenominator() (w for positions, d.z for inverse depth).
  Eigen::Matrix<double, 3, 4> homogeneousNumerator() const;
  Eigen::Vector4d homogeneousDenominator() const;

 private:
  /// The element of a homogeneous point that divides (d.z for inverse depth: a = d.x / d.z,
  /// b = d.y / d.z, rho = w / d.z; w for positions), and the one that gives the third
  /// coordinate over it (w: rho; d.z: z).
  int denominatorIndex() const { return inverse_depth_ ? 2 : 3; }
  int thirdCoordinateIndex() const { return inverse_depth_ ? 3 : 2; }

  bool inverse_depth_;
};

}  // namespace osc
