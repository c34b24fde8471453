#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

#include <algorithm>
#include <cmath>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

Eigen::Matrix3d essentialMatrix(const Eigen::Isometry3d& T_lopt_ropt) {
  const Eigen::Isometry3d T_ropt_lopt = T_lopt_ropt.inverse();
  return skew(T_ropt_lopt.translation()) * T_ropt_lopt.linear();
}

Eigen::Matrix3d fundamentalMatrix(const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                                  const Eigen::Isometry3d& T_lopt_ropt) {
  return K_right.inverse().transpose() * essentialMatrix(T_lopt_ropt) * K_left.inverse();
}

Eigen::Vector3d epipolarLine(const Eigen::Matrix3d& F, const Eigen::Vector2d& left_pixel) {
  Eigen::Vector3d line = F * left_pixel.homogeneous();
  const double norm = line.head<2>().norm();
  if (norm > 0.0) line /= norm;
  return line;
}

double sampsonDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& left_pixel,
                       const Eigen::Vector2d& right_pixel) {
  const Eigen::Vector3d xl = left_pixel.homogeneous(), xr = right_pixel.homogeneous();
  const Eigen::Vector3d Fxl = F * xl, Ftxr = F.transpose() * xr;
  const double denominator = Fxl.head<2>().squaredNorm() + Ftxr.head<2>().squaredNorm();
  if (denominator <= 0.0) return 0.0;
  return std::abs(xr.dot(Fxl)) / std::sqrt(denominator);
}

std::optional<Triangulation> triangulateMidpoint(const Eigen::Vector3d& ray_left,
                                                 const Eigen::Vector3d& ray_right,
                                                 const Eigen::Isometry3d& T_lopt_ropt) {
  // Rays c_l + s*d_l and c_r + t*d_r in the left frame; closest points solve a 2x2 system.
  const Eigen::Vector3d d_l = ray_left.normalized();
  const Eigen::Vector3d d_r = (T_lopt_ropt.linear() * ray_right).normalized();
  const Eigen::Vector3d c_r = T_lopt_ropt.translation();
  const double b = d_l.dot(d_r);
  const double denominator = 1.0 - b * b;
  if (!(denominator > 1e-12)) return std::nullopt;  // parallel (or NaN) rays
  const double e = d_l.dot(c_r), f = d_r.dot(c_r);
  const double s = (e - b * f) / denominator;  // along the left ray
  const double t = (b * e - f) / denominator;  // along the right ray
  if (!(s > 0.0) || !(t > 0.0)) return std::nullopt;
  const Eigen::Vector3d on_left = s * d_l, on_right = c_r + t * d_r;
  Triangulation result;
  result.point_left = 0.5 * (on_left + on_right);
  result.ray_gap = (on_left - on_right).norm();
  result.parallax = std::acos(std::min(1.0, std::max(-1.0, b)));
  if (!(result.point_left.z() > 0.0)) return std::nullopt;
  return result;
}

DepthScaleRange baselineDepthScaleRange(const Eigen::Vector3d& baseline,
                                        const Eigen::Matrix3d& covariance, double sigmas) {
  DepthScaleRange range;
  const double length = baseline.norm();
  if (!(length > 0.0)) return range;
  const Eigen::Vector3d direction = baseline / length;
  const double spread =
      sigmas * std::sqrt(std::max(direction.dot(covariance * direction), 0.0)) / length;
  range.shortest = std::max(1.0 - spread, 0.0);
  range.longest = 1.0 + spread;
  return range;
}

}  // namespace osc
