#include "online_stereo_calibration/core/filter/measurement_model.h"

#include <algorithm>

#include <Eigen/LU>

#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {

bool projectStereo(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_ropt_lopt,
                   const StereoIntrinsics& intrinsics, double min_depth, Eigen::Vector4d* z) {
  return projectHomogeneousStereo(
      Eigen::Vector4d(point_lopt.x(), point_lopt.y(), point_lopt.z(), 1.0), T_ropt_lopt, intrinsics,
      min_depth, z);
}

bool projectHomogeneousStereo(const Eigen::Vector4d& point_lopt,
                              const Eigen::Isometry3d& T_ropt_lopt,
                              const StereoIntrinsics& intrinsics, double min_depth,
                              Eigen::Vector4d* z) {
  const Eigen::Vector3d d_left = point_lopt.head<3>();
  const double w = point_lopt.w();
  const Eigen::Vector3d d_right = T_ropt_lopt.linear() * d_left + T_ropt_lopt.translation() * w;
  // depth = d.z / w >= min_depth for w > 0; in front (d.z > 0) for w <= 0.
  const double floor = std::max(w, 0.0) * min_depth;
  if (!(d_left.z() >= floor && d_left.z() > 0.0) || !(d_right.z() >= floor && d_right.z() > 0.0))
    return false;
  const Eigen::Vector3d left = intrinsics.K_left * d_left;     // eq. 29
  const Eigen::Vector3d right = intrinsics.K_right * d_right;  // eq. 30
  *z << left.x() / left.z(), left.y() / left.z(), right.x() / right.z(), right.y() / right.z();
  return true;
}

std::optional<Eigen::Vector3d> triangulateInverseDepth(const Eigen::Vector4d& z,
                                                       const Eigen::Isometry3d& T_lopt_ropt,
                                                       const StereoIntrinsics& intrinsics) {
  const Eigen::Vector3d m = intrinsics.K_left.inverse() * z.head<2>().homogeneous();
  const Eigen::Vector3d ray_right = intrinsics.K_right.inverse() * z.tail<2>().homogeneous();
  const Eigen::Vector2d n = ray_right.head<2>() / ray_right.z();
  const Eigen::Isometry3d T_ropt_lopt = T_lopt_ropt.inverse();
  // In the right frame the point is h = R m / z_l + t, i.e. R m + rho t up to scale; its
  // image n satisfies n_i (R m + rho t)_z = (R m + rho t)_i for i = x, y: linear in rho.
  const Eigen::Vector3d Rm = T_ropt_lopt.linear() * (m / m.z());
  const Eigen::Vector3d& t = T_ropt_lopt.translation();
  double normal = 0.0, right_side = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double a = n(i) * t.z() - t(i), b = Rm(i) - n(i) * Rm.z();
    normal += a * a;
    right_side += a * b;
  }
  if (!(normal > 1e-24)) return std::nullopt;
  return Eigen::Vector3d(m.x() / m.z(), m.y() / m.z(), right_side / normal);
}

std::optional<Eigen::Vector3d> triangulateStereo(const Eigen::Vector4d& z,
                                                 const Eigen::Isometry3d& T_lopt_ropt,
                                                 const StereoIntrinsics& intrinsics) {
  const Eigen::Vector3d ray_left = intrinsics.K_left.inverse() * z.head<2>().homogeneous();
  const Eigen::Vector3d ray_right = intrinsics.K_right.inverse() * z.tail<2>().homogeneous();
  const auto result = triangulateMidpoint(ray_left, ray_right, T_lopt_ropt);
  if (!result) return std::nullopt;
  return result->point_left;
}

}  // namespace osc
