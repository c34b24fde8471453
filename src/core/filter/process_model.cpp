#include "online_stereo_calibration/core/filter/process_model.h"

#include <cmath>

#include "online_stereo_calibration/core/filter/state_layout.h"

namespace osc {

Eigen::Vector3d predictPoint(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_veh_lopt,
                             const Eigen::Isometry3d& T_prev_curr) {
  const Eigen::Vector3d in_vehicle_prev = T_veh_lopt * point_lopt;  // eq. 8, H^veh_caml
  const Eigen::Vector3d in_vehicle_curr =
      T_prev_curr.inverse() * in_vehicle_prev;    // H^veh_veh(k+1|k)
  return T_veh_lopt.inverse() * in_vehicle_curr;  // H^caml_veh
}

Eigen::Vector3d predictPoint(const Eigen::Vector3d& point_lopt, const Eigen::Isometry3d& T_veh_lopt,
                             const Eigen::Isometry3d& T_prev_curr,
                             const Eigen::Vector3d& position_error,
                             const Eigen::Matrix3d& R_excited) {
  // d p_k / d t_l = R_lopt^T (R_motion^T - I): swap R_motion for R_excited in that term only.
  const Eigen::Matrix3d lever_change = R_excited.transpose() - T_prev_curr.linear().transpose();
  return predictPoint(point_lopt, T_veh_lopt, T_prev_curr) +
         T_veh_lopt.linear().transpose() * (lever_change * position_error);
}

Eigen::Vector4d predictHomogeneousPoint(const Eigen::Vector4d& point_lopt,
                                        const Eigen::Isometry3d& T_veh_lopt,
                                        const Eigen::Isometry3d& T_prev_curr,
                                        const Eigen::Vector3d& position_error,
                                        const Eigen::Matrix3d& R_excited) {
  // p -> A p + c with A the rotation of eq. 7-8 and c = the image of the origin.
  const Eigen::Vector3d c =
      predictPoint(Eigen::Vector3d::Zero(), T_veh_lopt, T_prev_curr, position_error, R_excited);
  const Eigen::Matrix3d A =
      T_veh_lopt.linear().transpose() * T_prev_curr.linear().transpose() * T_veh_lopt.linear();
  Eigen::Vector4d moved;
  moved << A * point_lopt.head<3>() + c * point_lopt.w(), point_lopt.w();
  return moved;
}

MotionTwists twistsAtEnds(const std::vector<MotionIncrement>& earlier,
                          const MotionIncrement& current) {
  MotionTwists twists;
  if (current.has_twists) {
    twists.start = current.twist_start;
    twists.end = current.twist_end;
    return twists;
  }
  const int n = static_cast<int>(earlier.size());
  if (n < 2) {
    twists.start = twists.end = logSE3(current.T_prev_curr) / current.dt;
    return twists;
  }
  // Each mean twist belongs to the middle of its interval; time 0 = the start of `current`.
  std::vector<double> times(n);
  std::vector<Vector6d> means(n);
  double end = 0.0, time_mean = 0.0;
  Vector6d twist_mean = Vector6d::Zero();
  for (int k = n - 1; k >= 0; --k) {
    times[k] = end - 0.5 * earlier[k].dt;
    end -= earlier[k].dt;
    means[k] = logSE3(earlier[k].T_prev_curr) / earlier[k].dt;
    time_mean += times[k] / n;
    twist_mean += means[k] / n;
  }
  double sxx = 0.0;
  Vector6d sxy = Vector6d::Zero();
  for (int k = 0; k < n; ++k) {
    sxx += (times[k] - time_mean) * (times[k] - time_mean);
    sxy += (times[k] - time_mean) * (means[k] - twist_mean);
  }
  const Vector6d rate = sxy / sxx;
  twists.start = twist_mean - rate * time_mean;
  twists.end = twists.start + rate * current.dt;
  return twists;
}

Eigen::Isometry3d correctedMotion(const Eigen::Isometry3d& measured, double time_offset,
                                  const MotionTwists& twists) {
  return expSE3(twists.start * time_offset) * measured * expSE3(-twists.end * time_offset);
}

Matrix6d timeOffsetModelCovariance(const MotionTwists& twists, double dt,
                                   double offset_second_moment, double factor) {
  Matrix6d covariance = Matrix6d::Zero();
  if (!(dt > 0.0) || !(factor > 0.0) || !(offset_second_moment > 0.0)) return covariance;
  const Vector6d change = twists.end - twists.start;
  const double scale = factor * offset_second_moment / dt;
  const double translation_sigma = scale * change.head<3>().norm();
  const double rotation_sigma = scale * change.tail<3>().norm();
  covariance.topLeftCorner<3, 3>().diagonal().setConstant(translation_sigma * translation_sigma);
  covariance.bottomRightCorner<3, 3>().diagonal().setConstant(rotation_sigma * rotation_sigma);
  return covariance;
}

double noiseScale(const FilterConfig& config, double dt) { return dt / config.reference_period; }

Matrix12d calibrationDriftCovariance(const FilterConfig& config, double dt) {
  using namespace layout;
  const double s = noiseScale(config, dt);
  Vector12d sigma;
  sigma.segment<3>(kCaml + kTranslation).setConstant(config.caml_translation_drift);
  sigma.segment<3>(kCaml + kRotation).setConstant(config.caml_rotation_drift);
  sigma.segment<3>(kCamr + kTranslation).setConstant(config.camr_translation_drift);
  sigma.segment<3>(kCamr + kRotation).setConstant(config.camr_rotation_drift);
  return (sigma.array().square() * s).matrix().asDiagonal();
}

Matrix6d motionNoiseCovariance(const FilterConfig& config, double dt) {
  const double s = noiseScale(config, dt);
  Vector6d sigma;
  sigma.head<3>().setConstant(config.motion_translation_noise);
  sigma.tail<3>().setConstant(config.motion_rotation_noise);
  return (sigma.array().square() * s).matrix().asDiagonal();
}

Matrix12d odometryScaleCovariance(const FilterConfig& config, const StereoExtrinsics& extrinsics) {
  if (!(config.odometry_scale_sigma > 0.0)) return Matrix12d::Zero();
  // Scaling every translation by 1 + kappa explains the pixels as well (filter_config.h):
  // the translations' tangent errors share kappa * t. Translations are parameters as they
  // are (no Jacobian needed: their tangent and parameter coordinates agree).
  Vector12d t = Vector12d::Zero();
  t.segment<3>(layout::kCaml + layout::kTranslation) = extrinsics.T_veh_caml.translation();
  t.segment<3>(layout::kCamr + layout::kTranslation) = extrinsics.T_caml_camr.translation();
  return std::pow(config.odometry_scale_sigma, 2) * t * t.transpose();
}

Eigen::Matrix3d paperPointProcessNoise(const Eigen::Vector3d& point_lopt, double sigma_imu,
                                       double sigma_p) {
  const Eigen::Vector3d p = rotationBodyOptical() * point_lopt;  // body axes: x fwd, y left, z up
  const double x = p.x(), y = p.y(), z = p.z();
  // Half the chord swept by an angle error sigma in each rotation plane (eq. 16-24);
  // the angle of the point in the plane is atan2 of its two coordinates.
  const auto sweep_sin = [sigma_imu](double angle, double radius) {
    return radius * (std::sin(angle + sigma_imu) - std::sin(angle - sigma_imu)) / 2.0;
  };
  const auto sweep_cos = [sigma_imu](double angle, double radius) {
    return radius * (std::cos(angle + sigma_imu) - std::cos(angle - sigma_imu)) / 2.0;
  };
  const double phi = std::atan2(z, y), r_yz = std::hypot(y, z);                 // roll, eq. 16
  const double theta = std::atan2(z, x), r_xz = std::hypot(x, z);               // pitch, eq. 17
  const double psi = std::atan2(y, x), r_xy = std::hypot(x, y);                 // yaw, eq. 18
  const double s_phi_z = sweep_sin(phi, r_yz), s_phi_y = sweep_cos(phi, r_yz);  // eq. 19-20
  const double s_theta_z = sweep_sin(theta, r_xz), s_theta_x = sweep_cos(theta, r_xz);  // eq. 21-22
  const double s_psi_x = sweep_cos(psi, r_xy), s_psi_y = sweep_sin(psi, r_xy);          // eq. 23-24
  const double sp2 = sigma_p * sigma_p;
  const Eigen::Vector3d q_body(s_theta_x * s_theta_x + s_psi_x * s_psi_x + sp2,   // eq. 25
                               s_phi_y * s_phi_y + s_psi_y * s_psi_y + sp2,       // eq. 26
                               s_phi_z * s_phi_z + s_theta_z * s_theta_z + sp2);  // eq. 27
  const Eigen::Matrix3d& R = rotationBodyOptical();
  return R.transpose() * q_body.asDiagonal() * R;
}

}  // namespace osc
