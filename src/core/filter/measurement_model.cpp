#include "online_stereo_calibration/core/filter/measurement_model.h"

#include <Eigen/LU>

#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {

bool projectStereo(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_ropt_lopt,
                   const StereoIntrinsics& intrinsics, double min_depth, Eigen::Vector4d* z) {
  const Eigen::Vector3d point_ropt = T_ropt_lopt * point_lopt;
  if (!(point_lopt.z() >= min_depth) || !(point_ropt.z() >= min_depth)) return false;
  const Eigen::Vector3d left = intrinsics.K_left * point_lopt;    // eq. 29
  const Eigen::Vector3d right = intrinsics.K_right * point_ropt;  // eq. 30
  *z << left.x() / left.z(), left.y() / left.z(), right.x() / right.z(), right.y() / right.z();
  return true;
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
