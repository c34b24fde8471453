#include "online_stereo_calibration/core/filter/point_coordinates.h"

#include <algorithm>
#include <limits>

namespace osc {

HomogeneousPoint PointCoordinates::homogeneous(const Eigen::Vector3d& c) const {
  if (!inverse_depth_) return HomogeneousPoint(c.x(), c.y(), c.z(), 1.0);
  return HomogeneousPoint(c.x(), c.y(), 1.0, c.z());
}

bool PointCoordinates::fromHomogeneous(const HomogeneousPoint& h, Eigen::Vector3d* c) const {
  const double denominator = h(denominatorIndex());
  if (!(denominator > 0.0)) return false;
  *c = Eigen::Vector3d(h.x(), h.y(), h(thirdCoordinateIndex())) / denominator;
  return true;
}

Eigen::Vector3d PointCoordinates::fromPosition(const Eigen::Vector3d& position) const {
  if (!inverse_depth_) return position;
  return Eigen::Vector3d(position.x(), position.y(), 1.0) / position.z();
}

Eigen::Vector3d PointCoordinates::position(const Eigen::Vector3d& c,
                                           double min_inverse_depth) const {
  if (!inverse_depth_) return c;
  return Eigen::Vector3d(c.x(), c.y(), 1.0) / std::max(c.z(), min_inverse_depth);
}

double PointCoordinates::depth(const Eigen::Vector3d& c) const {
  if (!inverse_depth_) return c.z();
  return c.z() > 0.0 ? 1.0 / c.z() : std::numeric_limits<double>::infinity();
}

Eigen::Matrix3d PointCoordinates::jacobianFromPosition(const Eigen::Vector3d& c) const {
  if (!inverse_depth_) return Eigen::Matrix3d::Identity();
  // (x/z, y/z, 1/z) differentiated, written in (a, b, rho) = (x/z, y/z, 1/z).
  const double a = c.x(), b = c.y(), rho = c.z();
  Eigen::Matrix3d J;
  J << rho, 0.0, -a * rho,  //
      0.0, rho, -b * rho,   //
      0.0, 0.0, -rho * rho;
  return J;
}

Eigen::Matrix<double, 3, 4> PointCoordinates::homogeneousNumerator() const {
  Eigen::Matrix<double, 3, 4> N = Eigen::Matrix<double, 3, 4>::Zero();
  N(0, 0) = N(1, 1) = 1.0;
  N(2, thirdCoordinateIndex()) = 1.0;
  return N;
}

Eigen::Vector4d PointCoordinates::homogeneousDenominator() const {
  return HomogeneousPoint::Unit(denominatorIndex());
}

}  // namespace osc
