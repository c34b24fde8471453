#include "online_stereo_calibration/core/filter/dense_calibration_ukf.h"

#include <cmath>
#include <unordered_map>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"

namespace osc {

using Eigen::MatrixXd;
using Eigen::VectorXd;

DenseCalibrationUkf::DenseCalibrationUkf(const FilterConfig& config,
                                         const StereoIntrinsics& intrinsics)
    : config_(config), excitation_(config), intrinsics_(intrinsics) {
  ut_.alpha = config.ut_alpha;
  ut_.beta = config.ut_beta;
  ut_.kappa = config.ut_kappa;
  reset(StereoExtrinsics(), Matrix12d::Identity());
}

void DenseCalibrationUkf::reset(const StereoExtrinsics& guess, const Matrix12d& covariance) {
  extrinsics_ = guess;
  covariance_ = covariance;
  means_.clear();
  ids_.clear();
  excitation_.reset();
}

bool DenseCalibrationUkf::addPoint(const PointMeasurement& measurement) {
  // Same initialisation as the structured filter: run it on a filter holding only the
  // calibration, then embed the result (mean, B, D) into the dense covariance.
  CalibrationFilter single(config_, intrinsics_);
  single.reset(extrinsics_, covariance_.topLeftCorner<12, 12>());
  if (!single.addPoint(measurement)) return false;
  const MatrixXd joint = single.denseCovariance();  // 15 x 15: [calibration, point]
  const MatrixXd B = joint.block(12, 0, 3, 12) *
                     covariance_.topLeftCorner<12, 12>().inverse();  // regression on calibration
  const int n = static_cast<int>(covariance_.rows());
  MatrixXd grown = MatrixXd::Zero(n + 3, n + 3);
  grown.topLeftCorner(n, n) = covariance_;
  const MatrixXd cross = B * covariance_.topRows(12);  // Cov(p, everything)
  grown.block(n, 0, 3, n) = cross;
  grown.block(0, n, n, 3) = cross.transpose();
  grown.block(n, n, 3, 3) = joint.block(12, 12, 3, 3);
  covariance_ = grown;
  means_.push_back(single.points().front().position_lopt);
  ids_.push_back(measurement.id);
  return true;
}

bool DenseCalibrationUkf::step(const MotionIncrement& motion,
                               const std::vector<PointMeasurement>& measurements) {
  const int N = static_cast<int>(means_.size());
  const int n = 12 + 3 * N;
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  const int noise_dim = shared ? 6 : 0;
  excitation_.update(motion.T_prev_curr.linear(), motion.dt);
  const Eigen::Matrix3d R_excited = excitation_.excitedRotation(motion.T_prev_curr.linear());

  // ---- prediction: sigma points of [state, motion error] through eq. 7-8 ----
  MatrixXd Pa = MatrixXd::Zero(n + noise_dim, n + noise_dim);
  Pa.topLeftCorner(n, n) = covariance_;
  if (shared) Pa.bottomRightCorner<6, 6>() = motionNoiseCovariance(config_, motion.dt);
  const StereoExtrinsics base = extrinsics_;
  const std::vector<Eigen::Vector3d> means = means_;
  const VectorFunction predict = [&](const VectorXd& x, VectorXd* y) {
    y->resize(n);
    y->head<12>() = x.head<12>();  // calibration: constant (eq. 10-13 noise added below)
    const Eigen::Isometry3d T_veh_lopt =
        boxPlus(base.T_veh_caml, x.segment<6>(layout::kCaml)) * bodyFromOptical();
    const Eigen::Isometry3d T_prev_curr =
        shared ? boxPlus(motion.T_prev_curr, x.tail<6>()) : motion.T_prev_curr;
    for (int i = 0; i < N; ++i) {
      y->segment<3>(12 + 3 * i) =
          predictPoint(means[i] + x.segment<3>(12 + 3 * i), T_veh_lopt, T_prev_curr,
                       x.segment<3>(layout::kCaml + layout::kTranslation), R_excited);
    }
    return true;
  };
  UnscentedResult predicted;
  if (!unscentedTransform(VectorXd::Zero(n + noise_dim), Pa, predict, ut_, &predicted, false))
    return false;
  MatrixXd P = predicted.covariance;
  P.topLeftCorner<12, 12>() += calibrationDriftCovariance(config_, motion.dt);
  const double scale = noiseScale(config_, motion.dt);
  std::vector<Eigen::Vector3d> predicted_means(N);
  for (int i = 0; i < N; ++i) {
    predicted_means[i] = predicted.mean.segment<3>(12 + 3 * i);
    Eigen::Matrix3d Q = config_.point_position_noise * config_.point_position_noise * scale *
                        Eigen::Matrix3d::Identity();
    if (!shared) {
      Q = paperPointProcessNoise(means_[i], config_.motion_rotation_noise * std::sqrt(scale),
                                 config_.point_position_noise * std::sqrt(scale));
    }
    P.block<3, 3>(12 + 3 * i, 12 + 3 * i) += Q;
  }
  // The calibration mean is unchanged: its tangent mean over symmetric sigma points is 0.

  // ---- correction: sigma points of the predicted state through eq. 29-30 ----
  std::unordered_map<PointId, int> slot;
  for (int i = 0; i < N; ++i) slot[ids_[i]] = i;
  VectorXd z(4 * N), R(4 * N);
  for (const PointMeasurement& m : measurements) {
    const auto found = slot.find(m.id);
    if (found == slot.end()) return false;
    z.segment<4>(4 * found->second) = m.z;
    R.segment<4>(4 * found->second) = m.variance;
  }
  const VectorFunction observe = [&](const VectorXd& x, VectorXd* y) {
    y->resize(4 * N);
    const StereoExtrinsics e{base.T_veh_caml,
                             boxPlus(base.T_caml_camr, x.segment<6>(layout::kCamr))};
    const Eigen::Isometry3d T_ropt_lopt = e.leftToRightOptical().inverse();
    for (int i = 0; i < N; ++i) {
      Eigen::Vector4d zi;
      if (!projectStereo(predicted_means[i] + x.segment<3>(12 + 3 * i), T_ropt_lopt, intrinsics_,
                         1e-3, &zi)) {
        return false;
      }
      y->segment<4>(4 * i) = zi;
    }
    return true;
  };
  UnscentedResult measured;
  if (!unscentedTransform(VectorXd::Zero(n), P, observe, ut_, &measured, false)) return false;
  MatrixXd S = measured.covariance;
  S.diagonal() += R;
  const MatrixXd K = S.llt().solve(measured.cross).transpose();  // P_xz S^-1
  const VectorXd dx = K * (z - measured.mean);
  covariance_ = P - K * S * K.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose());

  extrinsics_.T_veh_caml = boxPlus(base.T_veh_caml, dx.segment<6>(layout::kCaml));
  extrinsics_.T_caml_camr = boxPlus(base.T_caml_camr, dx.segment<6>(layout::kCamr));
  for (int i = 0; i < N; ++i) means_[i] = predicted_means[i] + dx.segment<3>(12 + 3 * i);
  return true;
}

}  // namespace osc
