#include "online_stereo_calibration/core/filter/calibration_filter.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/filter/update_tempering.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

#include "calibration_filter_internal.h"

namespace osc {

using namespace calibration_filter_internal;

void CalibrationFilter::motionModel(const MotionIncrement& motion, Eigen::Isometry3d* corrected,
                                    MatrixXd* jacobian) const {
  const MotionTwists twists = twistsAtEnds(previous_motions_, motion);
  // The measured translation is t + b dt (b: velocity error), then the time offset.
  const auto model = [&](double time_offset, const Eigen::Vector3d& velocity_bias) {
    Eigen::Isometry3d unbiased = motion.T_prev_curr;
    unbiased.translation() -= velocity_bias * motion.dt;
    return correctedMotion(unbiased, time_offset - motion.time_shift, twists);
  };
  *corrected = model(time_offset_, velocity_bias_);
  jacobian->setZero(layout::kPoseDim, odometry_dim_);
  // Central differences over steps small against the states' sigmas; the model is smooth.
  if (time_offset_index_ >= 0) {
    const double h = 1e-4;
    jacobian->col(time_offset_index_ - layout::kOdometry) =
        (boxMinus(model(time_offset_ + h, velocity_bias_), *corrected) -
         boxMinus(model(time_offset_ - h, velocity_bias_), *corrected)) /
        (2.0 * h);
  }
  if (velocity_bias_index_ >= 0) {
    const double h = 1e-3;
    for (size_t k = 0; k < velocity_bias_axes_.size(); ++k) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(velocity_bias_axes_[k]);
      jacobian->col(velocity_bias_index_ - layout::kOdometry + static_cast<int>(k)) =
          (boxMinus(model(time_offset_, velocity_bias_ + step), *corrected) -
           boxMinus(model(time_offset_, velocity_bias_ - step), *corrected)) /
          (2.0 * h);
    }
  }
}

void CalibrationFilter::applyCalibrationDrift(double dt) {
  // g' = F g + w (eq. 10-13; F = I but for the velocity error's Gauss-Markov decay). Each
  // point is re-regressed on g' so that its marginal and its cross-covariance with g' stay
  // exact: B' = B P F^T P'^-1, D' = D + B (P - P F^T P'^-1 F P) B^T. The consistency
  // monitor's factor per block (1 unless the block's measurements disagree).
  MatrixXd drift = MatrixXd::Zero(persistentDim(), persistentDim());
  drift.topLeftCorner<12, 12>() = calibrationDriftCovariance(config_, dt);
  drift.block<6, 6>(layout::kCaml, layout::kCaml) *= drift_inflation_.caml;
  drift.block<6, 6>(layout::kCamr, layout::kCamr) *= drift_inflation_.camr;
  if (time_offset_index_ >= 0)
    drift(time_offset_index_, time_offset_index_) =
        std::pow(config_.time_offset_drift, 2) * noiseScale(config_, dt);
  MatrixXd F = MatrixXd::Identity(persistentDim(), persistentDim());
  if (velocity_bias_index_ >= 0) {
    const double decay = std::exp(-dt / config_.odometry_bias_correlation_time);
    for (size_t k = 0; k < velocity_bias_axes_.size(); ++k) {
      const int i = velocity_bias_index_ + static_cast<int>(k);
      F(i, i) = decay;
      drift(i, i) = std::pow(velocityBiasPriorSigma(config_, velocity_bias_axes_[k]), 2) *
                    (1.0 - decay * decay);
    }
    velocity_bias_ *= decay;
  }
  if (drift_rate_index_ >= 0) {
    // x_camr's rotation integrates its drift rate: the nominal turns by w dt, the error by
    // dw dt (to first order in w dt, boxPlus tangent); the rate is Gauss-Markov.
    const double decay = std::exp(-dt / config_.camr_drift_rate_correlation_time);
    const int rotation = layout::kCamr + layout::kRotation;
    for (int k = 0; k < drift_rate_dim_; ++k) {
      const int i = drift_rate_index_ + k;
      F(rotation + k, i) = dt;
      F(i, i) = decay;
      drift(i, i) = std::pow(config_.camr_rotation_drift_rate_sigma, 2) * (1.0 - decay * decay);
    }
    Vector6d turn = Vector6d::Zero();
    turn.segment<3>(layout::kRotation) = drift_rate_ * dt;
    extrinsics_.T_caml_camr = boxPlus(extrinsics_.T_caml_camr, turn);
    drift_rate_ *= decay;
  }
  const MatrixXd FP = F * covariance_;
  const MatrixXd P_next = FP * F.transpose() + drift;
  const MatrixXd M = P_next.llt().solve(FP).transpose();  // P F^T P'^-1
  const MatrixXd forgotten = covariance_ - M * FP;
  for (TrackedPoint& point : points_) {
    point.D += point.B * forgotten * point.B.transpose();
    point.B = point.B * M;
  }
  covariance_ = P_next;
}

void CalibrationFilter::predictPoints(const MotionIncrement& motion, const MatrixXd& P,
                                      std::vector<bool>* failed) {
  // Seed eq. 7-8 through a UT on [x_caml, (odometry states), (motion error), p] per point
  // (eq. 28). The odometry states act through the corrected motion, linearised once per
  // step (motionModel: smooth, and their errors are small against the motion's).
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  std::vector<int> selected = range(layout::kCaml, layout::kPoseDim);
  const std::vector<int> odometry = range(layout::kOdometry, odometry_dim_);
  selected.insert(selected.end(), odometry.begin(), odometry.end());
  if (shared) {
    const std::vector<int> motion_block = range(persistentDim(), layout::kPoseDim);
    selected.insert(selected.end(), motion_block.begin(), motion_block.end());
  }
  // Points in units of the baseline: the camera's metric motion moves them by translation /
  // |t_r|, so x_camr's translation is an input of the prediction.
  const bool scaled = config_.baseline_scaled_points != 0;
  const int baseline_offset = static_cast<int>(selected.size());
  if (scaled) {
    const std::vector<int> baseline = range(layout::kCamr + layout::kTranslation, 3);
    selected.insert(selected.end(), baseline.begin(), baseline.end());
  }
  const int s = static_cast<int>(selected.size());
  Eigen::Isometry3d T_motion;
  MatrixXd motion_jacobian;
  motionModel(motion, &T_motion, &motion_jacobian);
  const int o = odometry_dim_;
  const double sigma_p2 =
      config_.point_position_noise * config_.point_position_noise * noiseScale(config_, motion.dt);
  const double sigma_imu =
      config_.motion_rotation_noise * std::sqrt(noiseScale(config_, motion.dt));
  const Eigen::Matrix3d R_excited = excitation_.excitedRotation(T_motion.linear());
  const double point_scale = pointScale();
  const Eigen::Vector3d baseline_direction =
      scaled ? Eigen::Vector3d(extrinsics_.T_caml_camr.translation() / point_scale)
             : Eigen::Vector3d::Zero();

  // The step on a homogeneous point, for the errors x of its s inputs.
  const auto step = [&](const VectorXd& x, HomogeneousPoint point_h) {
    const Eigen::Isometry3d T_veh_lopt =
        boxPlus(extrinsics_.T_veh_caml, x.head<6>()) * bodyFromOptical();
    Vector6d motion_error = Vector6d::Zero();
    if (o > 0) motion_error = motion_jacobian * x.segment(6, o);
    if (shared) motion_error += x.segment<6>(6 + o);
    const Eigen::Isometry3d T_prev_curr = boxPlus(T_motion, motion_error);
    // [d; w] in units of the baseline s moves as [A d + c w / s; w] (c: the metric image
    // of the origin, predictHomogeneousPoint). 1 / s to first order in the baseline's
    // error: exact at the estimate, and finite for a sigma point of a baseline prior as
    // wide as the baseline itself (where 1 / s has no useful Gaussian approximation).
    const double w = point_h.w();
    if (scaled) {
      const double ds = baseline_direction.dot(x.segment<3>(baseline_offset));
      point_h.w() *= (1.0 - ds / point_scale) / point_scale;
    }
    HomogeneousPoint moved =
        predictHomogeneousPoint(point_h, T_veh_lopt, T_prev_curr, x.head<3>(), R_excited);
    moved.w() = w;
    return moved;
  };

  for (size_t i = 0; i < points_.size(); ++i) {
    TrackedPoint& point = points_[i];
    const Eigen::Vector3d mean = point.mean;
    const VectorFunction predict = [&](const VectorXd& x, VectorXd* y) {
      Eigen::Vector3d coordinates;
      if (!coordinates_.fromHomogeneous(
              step(x.head(s), coordinates_.homogeneous(mean + x.tail<3>())), &coordinates))
        return false;
      *y = coordinates;
      return true;
    };
    UnscentedResult ut;
    if (!unscentedTransform(VectorXd::Zero(s + 3), jointCovariance(P, selected, point.B, point.D),
                            predict, ut_, &ut)) {
      (*failed)[i] = true;
      continue;
    }
    const Eigen::Matrix3d F_p = ut.jacobian.rightCols<3>();
    MatrixXd B = F_p * point.B;
    for (int a = 0; a < s; ++a) B.col(selected[a]) += ut.jacobian.col(a);
    Eigen::Matrix3d Q = sigma_p2 * Eigen::Matrix3d::Identity();  // of the position (m^2)
    if (!shared)
      Q = paperPointProcessNoise(
          point_scale * coordinates_.position(mean, minInverseDepth() * point_scale), sigma_imu,
          config_.point_position_noise * std::sqrt(noiseScale(config_, motion.dt)));
    const Eigen::Matrix3d J = coordinates_.jacobianFromPosition(ut.mean) / point_scale;
    Q = J * Q * J.transpose();
    point.D = F_p * point.D * F_p.transpose() + ut.residual + Q;
    point.D = 0.5 * (point.D + point.D.transpose());
    point.B = B;
    point.mean = ut.mean;
  }
}

MatrixXd CalibrationFilter::predict(const MotionIncrement& motion, std::vector<bool>* failed,
                                    bool remember) {
  const Eigen::Matrix3d R_excited = excitation_.excitedRotation(motion.T_prev_curr.linear());
  if (const std::shared_ptr<const Prediction> last = std::move(last_prediction_)) {
    if (last->motion.dt == motion.dt &&
        last->motion.T_prev_curr.matrix() == motion.T_prev_curr.matrix() &&
        last->motion.has_covariance == motion.has_covariance &&
        last->motion.covariance == motion.covariance &&
        last->motion.has_twists == motion.has_twists &&
        last->motion.twist_start == motion.twist_start &&
        last->motion.twist_end == motion.twist_end &&
        last->motion.time_shift == motion.time_shift && last->R_excited == R_excited &&
        last->extrinsics.T_veh_caml.matrix() == extrinsics_.T_veh_caml.matrix() &&
        last->extrinsics.T_caml_camr.matrix() == extrinsics_.T_caml_camr.matrix() &&
        last->covariance == covariance_ && last->time_offset == time_offset_ &&
        last->velocity_bias == velocity_bias_ && last->drift_rate == drift_rate_ &&
        samePreviousMotions(last->previous_motions, previous_motions_) &&
        samePoints(last->points, points_)) {
      covariance_ = last->predicted_covariance;
      velocity_bias_ = last->predicted_velocity_bias;
      drift_rate_ = last->predicted_drift_rate;
      extrinsics_.T_caml_camr = last->predicted_T_caml_camr;
      points_ = last->predicted_points;
      *failed = last->failed;
      last_prediction_ = last;  // its measurement UTs, for linearizeMeasurement
      return last->P;
    }
  }
  if (!remember) return predictAnew(motion, failed);
  auto prediction = std::make_shared<Prediction>();
  prediction->motion = motion;
  prediction->R_excited = R_excited;
  prediction->extrinsics = extrinsics_;
  prediction->covariance = covariance_;
  prediction->time_offset = time_offset_;
  prediction->velocity_bias = velocity_bias_;
  prediction->drift_rate = drift_rate_;
  prediction->previous_motions = previous_motions_;
  prediction->points = points_;
  const MatrixXd P = predictAnew(motion, failed);
  prediction->predicted_covariance = covariance_;
  prediction->predicted_velocity_bias = velocity_bias_;
  prediction->predicted_drift_rate = drift_rate_;
  prediction->predicted_T_caml_camr = extrinsics_.T_caml_camr;
  prediction->predicted_points = points_;
  prediction->P = P;
  prediction->failed = *failed;
  last_prediction_ = std::move(prediction);
  return P;
}

Matrix6d CalibrationFilter::configuredMotionNoise(const MotionIncrement& motion) const {
  return motion.has_covariance ? motion.covariance : motionNoiseCovariance(config_, motion.dt);
}

MatrixXd CalibrationFilter::predictAnew(const MotionIncrement& motion, std::vector<bool>* failed) {
  applyCalibrationDrift(motion.dt);
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  const int G = persistentDim() + (shared ? layout::kPoseDim : 0);
  MatrixXd P = MatrixXd::Zero(G, G);
  P.topLeftCorner(persistentDim(), persistentDim()) = covariance_;
  if (shared) {
    // Times what the odometry noise matcher learned, per part (translation, rotation).
    Eigen::Matrix<double, 6, 1> scale;
    scale << Eigen::Vector3d::Constant(std::sqrt(motion_noise_factors_[0])),
        Eigen::Vector3d::Constant(std::sqrt(motion_noise_factors_[1]));
    P.bottomRightCorner<6, 6>() =
        scale.asDiagonal() * configuredMotionNoise(motion) * scale.asDiagonal();
    // ... plus what the first-order time-offset correction leaves out (process_model.h).
    const double offset_variance =
        time_offset_index_ >= 0 ? covariance_(time_offset_index_, time_offset_index_) : 0.0;
    const double residual_offset = time_offset_ - motion.time_shift;
    P.bottomRightCorner<6, 6>() += timeOffsetModelCovariance(
        twistsAtEnds(previous_motions_, motion), motion.dt,
        residual_offset * residual_offset + offset_variance, config_.time_offset_model_noise);
    for (TrackedPoint& point : points_) {
      point.B.conservativeResize(3, G);
      point.B.rightCols<6>().setZero();
    }
  }
  failed->assign(points_.size(), false);
  predictPoints(motion, P, failed);
  return P;
}

bool CalibrationFilter::linearizeMeasurement(size_t i, const MatrixXd& P, const Eigen::Vector4d& z,
                                             const Eigen::Vector4d& variance, PointInnovation* inn,
                                             bool remember) const {
  // Seed eq. 29-30 through a UT on [x_camr, p], as a regression on the global error.
  const TrackedPoint& point = points_[i];
  const std::vector<int> camr = range(layout::kCamr, layout::kPoseDim);
  const VectorFunction observe = [&](const VectorXd& x, VectorXd* y) {
    const Eigen::Isometry3d T_caml_camr = boxPlus(extrinsics_.T_caml_camr, x.head<6>());
    const Eigen::Isometry3d T_ropt_lopt = leftToRightOptical(T_caml_camr).inverse();
    const double scale = pointScale(T_caml_camr);
    if (!(scale > 0.0)) return false;
    Eigen::Vector4d projected;
    if (!projectHomogeneousStereo(
            metricFromScaled(coordinates_.homogeneous(point.mean + x.tail<3>()), scale),
            T_ropt_lopt, intrinsics_, 1e-3, &projected))
      return false;
    *y = projected;
    return true;
  };
  const MatrixXd joint = jointCovariance(P, camr, point.B, point.D);
  // The UT of the same inputs computed by predictObservations (exactly equal inputs, so
  // exactly the same result), else anew.
  std::shared_ptr<const Prediction::MeasurementUt> reused;
  if (last_prediction_ && i < last_prediction_->measurement_uts.size()) {
    reused = last_prediction_->measurement_uts[i];
    if (reused &&
        !(reused->mean == point.mean && reused->T_caml_camr == extrinsics_.T_caml_camr.matrix() &&
          reused->joint_covariance == joint)) {
      reused.reset();
    }
  }
  if (!reused) {
    auto computed = std::make_shared<Prediction::MeasurementUt>();
    if (!unscentedTransformWithFallback(VectorXd::Zero(9), joint, observe, ut_, &computed->ut)) {
      return false;
    }
    computed->joint_covariance = joint;
    computed->mean = point.mean;
    computed->T_caml_camr = extrinsics_.T_caml_camr.matrix();
    if (remember && last_prediction_) {
      last_prediction_->measurement_uts.resize(points_.size());
      last_prediction_->measurement_uts[i] = computed;
    }
    reused = computed;
  }
  const UnscentedResult& ut = reused->ut;
  inn->point = i;
  inn->predicted = ut.mean;
  inn->residual = z - ut.mean;
  inn->H_p = ut.jacobian.rightCols<3>();
  inn->J = inn->H_p * point.B;
  for (int a = 0; a < 6; ++a) inn->J.col(camr[a]) += ut.jacobian.col(a);
  inn->S0 = inn->H_p * point.D * inn->H_p.transpose() + ut.residual;
  inn->S0.diagonal() += variance;
  inn->S = inn->J * P * inn->J.transpose() + inn->S0;
  if (z.allFinite()) {
    inn->nis = inn->residual.dot(inn->S.llt().solve(inn->residual));
    inn->nis_left = inn->residual.head<2>().dot(
        inn->S.topLeftCorner<2, 2>().llt().solve(inn->residual.head<2>()));
  }
  return true;
}

std::vector<PredictedObservation> CalibrationFilter::predictObservations(
    const MotionIncrement& motion) const {
  std::vector<PredictedObservation> predictions;
  if (!checkMotion(motion).empty()) return predictions;
  CalibrationFilter scratch = *this;  // the prediction must not touch this filter
  scratch.excitation_.update(motion.T_prev_curr.linear(), motion.dt);
  std::vector<bool> failed;
  const MatrixXd P = scratch.predict(motion, &failed, /*remember=*/true);
  last_prediction_ = scratch.last_prediction_;  // for the step with this motion
  const double v = config_.pixel_noise * config_.pixel_noise;
  const Eigen::Vector4d variance(v, v, v, v);
  const Eigen::Vector4d unknown = Eigen::Vector4d::Constant(std::nan(""));
  for (size_t i = 0; i < scratch.points_.size(); ++i) {
    PointInnovation inn;
    if (failed[i] || !scratch.linearizeMeasurement(i, P, unknown, variance, &inn, true)) continue;
    PredictedObservation prediction;
    prediction.id = scratch.points_[i].id;
    prediction.z = inn.predicted;
    prediction.S = inn.S;
    const double depth_before = coordinates_.depth(points_[i].mean);
    const double depth_after = coordinates_.depth(scratch.points_[i].mean);
    if (depth_before > 0.0 && depth_after > 0.0 && std::isfinite(depth_before) &&
        std::isfinite(depth_after))
      prediction.depth_ratio = depth_before / depth_after;
    predictions.push_back(prediction);
  }
  return predictions;
}

void CalibrationFilter::marginalizeMotionError(const MatrixXd& P) {
  // Regress every point on the calibration alone: B = B_c + B_m P_mc P_cc^-1 and
  // D += B_m (P_mm - P_mc P_cc^-1 P_cm) B_m^T. Exact per point; the small common part left
  // by the step's motion error is not kept between points.
  const int n = persistentDim();
  const MatrixXd P_cc = P.topLeftCorner(n, n);
  const MatrixXd P_mc = P.bottomLeftCorner(6, n);
  const MatrixXd regression = P_cc.llt().solve(P_mc.transpose()).transpose();
  const Matrix6d conditional = P.bottomRightCorner<6, 6>() - regression * P_mc.transpose();
  for (TrackedPoint& point : points_) {
    if (point.B.cols() != n + layout::kPoseDim) continue;
    const Eigen::Matrix<double, 3, 6> B_m = point.B.rightCols<6>();
    const MatrixXd B_c = point.B.leftCols(n) + B_m * regression;
    point.D += B_m * conditional * B_m.transpose();
    point.B = B_c;
  }
  covariance_ = P_cc;
}

}  // namespace osc
