/// @file right_rotation_seed.cpp
/// @brief rightRotationSeed: the whole-image fit's x_camr in the filter's frames.
#include "online_stereo_calibration/core/pipeline/right_rotation_seed.h"

#include <cmath>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

// T_lopt_ropt = T_body_opt^-1 T_caml_camr T_body_opt (pose.cpp): a right-multiplied rotation
// error e_opt of R_lopt_ropt is R_bo e_opt of R_caml_camr, and x_camr's translation t (left
// body frame) is R_bo times the optical one.

Eigen::Matrix3d baselineDirectionCovariance(const StereoExtrinsics& estimate,
                                            const Matrix12d& covariance) {
  using namespace layout;
  const Eigen::Vector3d t = estimate.T_caml_camr.translation();
  const double length = t.norm();
  if (!(length > 0.0)) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d c = t / length;
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - c * c.transpose();
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Matrix3d P_tt = covariance.block<3, 3>(kCamr + kTranslation, kCamr + kTranslation);
  return R_bo.transpose() * across * P_tt * across * R_bo / (length * length);
}

RightRotationSeed rightRotationSeed(const GlobalStereoFit& fit, const StereoExtrinsics& estimate,
                                    const Matrix12d& covariance, double min_sigma,
                                    double min_sigma_along_lines) {
  using namespace layout;
  RightRotationSeed seed;
  if (!fit.valid) return seed;
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Vector3d t = estimate.T_caml_camr.translation();
  const double length = t.norm();
  const Eigen::Vector3d c_old =
      length > 0.0 ? Eigen::Vector3d(t / length) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d c = R_bo * fit.baseline_direction.normalized();
  seed.T_caml_camr.linear() = R_bo * fit.R_lopt_ropt * R_bo.transpose();
  seed.T_caml_camr.translation() = length * c;
  // Translation: the direction's covariance times the length, and the length's variance (the
  // estimate's along its direction) along the new direction.
  const Eigen::Matrix3d P_tt = covariance.block<3, 3>(kCamr + kTranslation, kCamr + kTranslation);
  const double length_variance = c_old.dot(P_tt * c_old);
  seed.covariance.topLeftCorner<3, 3>() =
      fit.baseline_direction_covariance.isZero()  // held: the estimate's translation
          ? P_tt
          : Eigen::Matrix3d(length * length * R_bo * fit.baseline_direction_covariance *
                                R_bo.transpose() +
                            length_variance * c * c.transpose());
  // The rotation about the axis across the baseline and the view (optical y for a
  // horizontal rig) moves the points along their epipolar lines: one pair determines it only
  // through the perspective's second-order terms, which any model error (a lens residual, an
  // imperfect rectification) mimics. On KITTI's rectified pairs the fit's is 0.5 deg off
  // with a formal sigma of 0.01-0.06 deg.
  const Eigen::Vector3d along_lines =
      R_bo * fit.baseline_direction.cross(Eigen::Vector3d::UnitZ()).normalized();
  seed.covariance.bottomRightCorner<3, 3>() = R_bo * fit.rotation_covariance * R_bo.transpose() +
                                              min_sigma * min_sigma * Eigen::Matrix3d::Identity();
  if (along_lines.allFinite()) {
    seed.covariance.bottomRightCorner<3, 3>() +=
        min_sigma_along_lines * min_sigma_along_lines * along_lines * along_lines.transpose();
  }
  seed.covariance.bottomLeftCorner<3, 3>() =
      length * R_bo * fit.rotation_direction_covariance * R_bo.transpose();
  seed.covariance.topRightCorner<3, 3>() = seed.covariance.bottomLeftCorner<3, 3>().transpose();
  seed.covariance = 0.5 * (seed.covariance + seed.covariance.transpose());
  const Eigen::Vector3d difference =
      logSO3(estimate.T_caml_camr.linear().transpose() * seed.T_caml_camr.linear());
  const Eigen::Matrix3d S = seed.covariance.bottomRightCorner<3, 3>() +
                            covariance.block<3, 3>(kCamr + kRotation, kCamr + kRotation);
  seed.angle = difference.norm();
  const Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (S + S.transpose()));
  if (llt.info() != Eigen::Success ||
      Eigen::LLT<Matrix6d>(seed.covariance).info() != Eigen::Success) {
    return seed;
  }
  seed.distance = std::sqrt(difference.dot(llt.solve(difference)));
  seed.valid = std::isfinite(seed.distance) && seed.covariance.allFinite();
  return seed;
}

}  // namespace osc
