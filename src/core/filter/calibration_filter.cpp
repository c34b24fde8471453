#include "online_stereo_calibration/core/filter/calibration_filter.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/filter/update_tempering.h"
#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Steady-state 1 sigma of the odometry's velocity error along a vehicle axis (0 x forward).
/// The forward axis has its own (FilterConfig::odometry_forward_velocity_bias_sigma): with
/// metric points a forward state took spurious information from linearisation and moved the
/// baseline with it (clean drives 25 -> 20 of 50 honest, yr); with points in units of the
/// baseline the baseline enters only through the motion, and at half the lateral sigma it
/// helps (docs/RESULTS.md "Session 12"). The vertical one matters most (lateral only:
/// campaign C_odometry 17 -> 4 of 50 honest).
double velocityBiasPriorSigma(const FilterConfig& config, int axis) {
  return axis == 0 ? config.odometry_forward_velocity_bias_sigma
                   : config.odometry_velocity_bias_sigma;
}

/// chi-square(2) at 99.9 %: the left image's share of a stereo innovation.
constexpr double kLeftGate = 13.82;

/// 0 for x_caml, 1 for x_camr (JumpBlock::kNone is not a block).
size_t blockIndex(JumpBlock block) { return block == JumpBlock::kVehicleToLeft ? 0 : 1; }

Matrix12d initialCovariance(const FilterConfig& c) {
  using namespace layout;
  Vector12d sigma;
  sigma.segment<3>(kCaml + kTranslation).setConstant(c.initial_caml_translation_sigma);
  sigma.segment<3>(kCaml + kRotation).setConstant(c.initial_caml_rotation_sigma);
  sigma.segment<3>(kCamr + kTranslation).setConstant(c.initial_camr_translation_sigma);
  sigma.segment<3>(kCamr + kRotation).setConstant(c.initial_camr_rotation_sigma);
  return sigma.array().square().matrix().asDiagonal();
}

Eigen::Isometry3d leftToRightOptical(const Eigen::Isometry3d& T_caml_camr) {
  StereoExtrinsics e;
  e.T_caml_camr = T_caml_camr;
  return e.leftToRightOptical();
}

/// Joint covariance of [g(selected), p] for a point p = mean + B dg + e.
MatrixXd jointCovariance(const MatrixXd& P, const std::vector<int>& selected, const MatrixXd& B,
                         const Eigen::Matrix3d& D) {
  const int s = static_cast<int>(selected.size());
  MatrixXd C(s + 3, s + 3);
  const MatrixXd BP = B * P;  // Cov(p, g)
  for (int a = 0; a < s; ++a) {
    for (int b = 0; b < s; ++b) C(a, b) = P(selected[a], selected[b]);
    C.block<3, 1>(s, a) = BP.col(selected[a]);
    C.block<1, 3>(a, s) = BP.col(selected[a]).transpose();
  }
  C.block<3, 3>(s, s) = BP * B.transpose() + D;
  return C;
}

/// The scaled UT with the configured spread; where f is undefined at some sigma point (a
/// ray pair that does not meet, a point behind a camera), retried with the sigma points
/// pulled in (alpha / 4, / 16): the scaling Julier introduced for exactly such non-local
/// effects, tending to the linearised transform.
bool unscentedTransformWithFallback(const VectorXd& mean, const MatrixXd& covariance,
                                    const VectorFunction& f, UnscentedParameters parameters,
                                    UnscentedResult* result) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    if (unscentedTransform(mean, covariance, f, parameters, result)) return true;
    parameters.alpha /= 4.0;
  }
  return false;
}

/// A homogeneous point [d; w] stored in units of a length @p scale (the point p / scale) as
/// one in metres ([d; w / scale]), and back (FilterConfig::baseline_scaled_points).
HomogeneousPoint metricFromScaled(const HomogeneousPoint& h, double scale) {
  return HomogeneousPoint(h.x(), h.y(), h.z(), h.w() / scale);
}
HomogeneousPoint scaledFromMetric(const HomogeneousPoint& h, double scale) {
  return HomogeneousPoint(h.x(), h.y(), h.z(), h.w() * scale);
}

std::vector<int> range(int first, int count) {
  std::vector<int> r(count);
  for (int k = 0; k < count; ++k) r[k] = first + k;
  return r;
}

}  // namespace

/// A point's linearised measurement (regression of the UT on [x_camr, p]).
struct CalibrationFilter::PointInnovation {
  size_t point = 0;
  Eigen::Vector4d predicted;  ///< predicted measurement z_hat
  Eigen::Vector4d residual;
  Eigen::Matrix4d S;                ///< full innovation covariance J P J^T + S0
  MatrixXd J;                       ///< 4 x G: d residual / d global error (through x_camr and B)
  Eigen::Matrix<double, 4, 3> H_p;  ///< d z / d point
  Eigen::Matrix4d S0;               ///< covariance of the residual given the global error
  double nis = 0.0;                 ///< full normalised innovation squared
  double nis_left = 0.0;            ///< left image only
};

/// predict()'s inputs (the state it starts from, after the excitation update) and outputs.
struct CalibrationFilter::Prediction {
  // Inputs.
  MotionIncrement motion;
  Eigen::Matrix3d R_excited;
  StereoExtrinsics extrinsics;
  MatrixXd covariance;
  double time_offset = 0.0;
  Eigen::Vector3d velocity_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d drift_rate = Eigen::Vector3d::Zero();
  std::vector<MotionIncrement> previous_motions;
  std::vector<TrackedPoint> points;
  // Outputs.
  MatrixXd predicted_covariance;
  Eigen::Vector3d predicted_velocity_bias = Eigen::Vector3d::Zero();
  Eigen::Isometry3d predicted_T_caml_camr;  ///< moved by the drift rate
  Eigen::Vector3d predicted_drift_rate = Eigen::Vector3d::Zero();
  std::vector<TrackedPoint> predicted_points;
  MatrixXd P;
  std::vector<bool> failed;
  /// The measurement UT of each predicted point (by index), filled by linearizeMeasurement
  /// on the predicted state: the step linearises the same points from the same state.
  struct MeasurementUt {
    MatrixXd joint_covariance;  ///< the UT's input covariance
    Eigen::Vector3d mean;       ///< the point's mean (the function's argument)
    Eigen::Matrix4d T_caml_camr;
    UnscentedResult ut;
  };
  mutable std::vector<std::shared_ptr<const MeasurementUt>> measurement_uts;
};

namespace {

/// Exactly equal (so that a reused prediction is bit for bit the one computed).
template <typename Point>
bool samePoints(const std::vector<Point>& a, const std::vector<Point>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].id != b[i].id || a[i].mean != b[i].mean || a[i].D != b[i].D ||
        a[i].B.rows() != b[i].B.rows() || a[i].B.cols() != b[i].B.cols() || a[i].B != b[i].B) {
      return false;
    }
  }
  return true;
}

bool motionCovarianceIsValid(const Matrix6d& covariance) {
  if (!covariance.allFinite()) return false;
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() >
      1e-9 * std::max(covariance.cwiseAbs().maxCoeff(), 1e-300)) {
    return false;
  }
  return Eigen::SelfAdjointEigenSolver<Matrix6d>(covariance).eigenvalues().minCoeff() >=
         -1e-12 * covariance.cwiseAbs().maxCoeff();
}

bool samePreviousMotions(const std::vector<MotionIncrement>& a,
                         const std::vector<MotionIncrement>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].dt != b[k].dt || a[k].T_prev_curr.matrix() != b[k].T_prev_curr.matrix()) return false;
  }
  return true;
}

}  // namespace

CalibrationFilter::CalibrationFilter(const FilterConfig& config, const StereoIntrinsics& intrinsics)
    : config_(config),
      excitation_(config),
      coordinates_(config.inverse_depth_points != 0),
      intrinsics_(intrinsics),
      monitor_(config) {
  const std::vector<std::string> problems = config.validate();
  if (!problems.empty()) {
    std::string message = "invalid filter configuration:";
    for (const auto& p : problems) message += "\n  " + p;
    throw std::invalid_argument(message);
  }
  if (!intrinsics.K_left.allFinite() || !intrinsics.K_right.allFinite() ||
      !(intrinsics.K_left(0, 0) > 0) || !(intrinsics.K_right(0, 0) > 0)) {
    throw std::invalid_argument(
        "camera matrices K_left/K_right must be finite with positive focal length");
  }
  ut_.alpha = config.ut_alpha;
  ut_.beta = config.ut_beta;
  ut_.kappa = config.ut_kappa;
  if (config.initial_time_offset_sigma > 0.0)
    time_offset_index_ = layout::kOdometry + odometry_dim_++;
  for (int axis = 0; axis < 3; ++axis)
    if (velocityBiasPriorSigma(config, axis) > 0.0) velocity_bias_axes_.push_back(axis);
  if (!velocity_bias_axes_.empty()) {
    velocity_bias_index_ = layout::kOdometry + odometry_dim_;
    odometry_dim_ += static_cast<int>(velocity_bias_axes_.size());
  }
  if (config.camr_rotation_drift_rate_sigma > 0.0) {
    drift_rate_index_ = layout::kOdometry + odometry_dim_;
    drift_rate_dim_ = 3;
  }
  reset(StereoExtrinsics());
}

MatrixXd CalibrationFilter::startCovariance(const Matrix12d& calibration) const {
  MatrixXd P = MatrixXd::Zero(persistentDim(), persistentDim());
  P.topLeftCorner<12, 12>() = calibration;
  if (time_offset_index_ >= 0)
    P(time_offset_index_, time_offset_index_) = std::pow(config_.initial_time_offset_sigma, 2);
  for (size_t k = 0; k < velocity_bias_axes_.size(); ++k) {
    const int i = velocity_bias_index_ + static_cast<int>(k);
    P(i, i) = std::pow(velocityBiasPriorSigma(config_, velocity_bias_axes_[k]), 2);
  }
  for (int k = 0; k < drift_rate_dim_; ++k)
    P(drift_rate_index_ + k, drift_rate_index_ + k) =
        std::pow(config_.camr_rotation_drift_rate_sigma, 2);
  return P;
}

Eigen::Vector3d CalibrationFilter::velocityBiasSigma() const {
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < velocity_bias_axes_.size(); ++k) {
    const int i = velocity_bias_index_ + static_cast<int>(k);
    sigma(velocity_bias_axes_[k]) = std::sqrt(std::max(covariance_(i, i), 0.0));
  }
  return sigma;
}

Eigen::Vector3d CalibrationFilter::camrDriftRateSigma() const {
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  for (int k = 0; k < drift_rate_dim_; ++k) sigma(k) = stateSigma(drift_rate_index_ + k);
  return sigma;
}

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

void CalibrationFilter::reset(const StereoExtrinsics& guess) {
  reset(guess, initialCovariance(config_));
}

void CalibrationFilter::reset(const StereoExtrinsics& guess, const Matrix12d& covariance) {
  requireValidStartCovariance(covariance);
  covariance_ = startCovariance(covariance);
  time_offset_ = config_.initial_time_offset;
  velocity_bias_.setZero();
  drift_rate_.setZero();
  startCalibration(guess);
}

void CalibrationFilter::restartCalibration(const Matrix12d& covariance) {
  requireValidStartCovariance(covariance);
  // The odometry states keep their means and covariance; the calibration is uncorrelated
  // with them, as at a start.
  constexpr int n = layout::kCalibrationDim;
  const int rest = persistentDim() - n;
  covariance_.topLeftCorner<n, n>() = covariance;
  covariance_.topRightCorner(n, rest).setZero();
  covariance_.bottomLeftCorner(rest, n).setZero();
  startCalibration(extrinsics_);
}

void CalibrationFilter::requireValidStartCovariance(const Matrix12d& covariance) {
  if (!covariance.allFinite() ||
      (covariance - covariance.transpose()).cwiseAbs().maxCoeff() >
          1e-9 * covariance.cwiseAbs().maxCoeff() ||
      covariance.llt().info() != Eigen::Success) {
    throw std::invalid_argument(
        "initial calibration covariance must be finite, symmetric and positive definite");
  }
}

void CalibrationFilter::startCalibration(const StereoExtrinsics& guess) {
  last_prediction_.reset();
  extrinsics_ = guess;
  previous_motions_.clear();
  excitation_.reset();
  monitor_.reset();
  time_since_opened_ = {0.0, 0.0};
  rejection_streak_ = 0;
  ++starts_;
  points_.clear();
  index_.clear();
}

std::string CalibrationFilter::checkMotion(const MotionIncrement& m) const {
  std::ostringstream why;
  const Eigen::Matrix3d R = m.T_prev_curr.linear();
  if (!std::isfinite(m.dt) || !(m.dt > 0.0)) {
    why << "motion dt = " << m.dt << " s is not a positive number";
  } else if (m.dt > config_.max_frame_interval) {
    why << "motion dt = " << m.dt
        << " s exceeds max_frame_interval_s = " << config_.max_frame_interval;
  } else if (!m.T_prev_curr.matrix().allFinite()) {
    why << "motion increment contains NaN or Inf";
  } else if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
             R.determinant() < 0.0) {
    why << "motion rotation is not a rotation matrix";
  } else if (m.T_prev_curr.translation().norm() > config_.max_speed * m.dt) {
    why << "motion of " << m.T_prev_curr.translation().norm() << " m in " << m.dt
        << " s exceeds max_speed_mps = " << config_.max_speed;
  } else if (m.has_covariance && !motionCovarianceIsValid(m.covariance)) {
    why << "motion covariance is not finite, symmetric and positive semi-definite";
  } else if (logSO3(R).norm() > config_.max_angular_rate * m.dt) {
    why << "rotation of " << logSO3(R).norm() * 180.0 / M_PI << " deg in " << m.dt
        << " s exceeds max_angular_rate_dps = " << config_.max_angular_rate * 180.0 / M_PI;
  }
  return why.str();
}

void CalibrationFilter::applyCalibrationDrift(double dt) {
  // g' = F g + w (eq. 10-13; F = I but for the velocity error's Gauss-Markov decay). Each
  // point is re-regressed on g' so that its marginal and its cross-covariance with g' stay
  // exact: B' = B P F^T P'^-1, D' = D + B (P - P F^T P'^-1 F P) B^T. The consistency
  // monitor's factor per block (1 unless the block's measurements disagree).
  MatrixXd drift = MatrixXd::Zero(persistentDim(), persistentDim());
  drift.topLeftCorner<12, 12>() = calibrationDriftCovariance(config_, dt);
  drift.block<6, 6>(layout::kCaml, layout::kCaml) *=
      monitor_.inflation(ConsistencyBlock::kVehicleToLeft);
  drift.block<6, 6>(layout::kCamr, layout::kCamr) *=
      monitor_.inflation(ConsistencyBlock::kLeftToRight);
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

StepReport CalibrationFilter::step(const MotionIncrement& motion,
                                   const std::vector<PointMeasurement>& measurements) {
  StepReport report;
  report.message = checkMotion(motion);
  if (!report.message.empty()) return report;  // untouched
  excitation_.update(motion.T_prev_curr.linear(), motion.dt);
  for (double& age : time_since_opened_) age += motion.dt;

  // The prediction is linearised at the measured motion. With the shared motion-noise model
  // the step's motion error is estimated with the calibration; the step is then repeated,
  // linearised at the corrected motion (an iterated UKF in the motion error), so the noise of
  // the measured motion is not mistaken for excitation (e.g. roll noise making zl look
  // observable on a flat road, seed Sec. II-D).
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  const int passes =
      shared && wantsMotionRelinearized(motion) ? 1 + config_.motion_relinearizations : 1;
  const std::vector<TrackedPoint> saved_points = passes > 1 ? points_ : std::vector<TrackedPoint>();
  const MatrixXd saved_covariance = covariance_;
  const Eigen::Vector3d saved_velocity_bias = velocity_bias_;
  const Eigen::Vector3d saved_drift_rate = drift_rate_;
  const Eigen::Isometry3d saved_T_caml_camr = extrinsics_.T_caml_camr;
  MotionIncrement linearization = motion;
  Vector6d prior_motion_error = Vector6d::Zero();
  for (int pass = 0; pass < passes; ++pass) {
    if (pass > 0) {
      points_ = saved_points;
      covariance_ = saved_covariance;
      velocity_bias_ = saved_velocity_bias;
      drift_rate_ = saved_drift_rate;
      extrinsics_.T_caml_camr = saved_T_caml_camr;
      report = StepReport();
    }
    Vector6d estimated_motion_error;
    const bool final_pass = pass + 1 == passes;
    const bool completed = runPass(linearization, prior_motion_error, measurements, final_pass,
                                   pass == 0, &report, &estimated_motion_error);
    if (!completed || final_pass) break;  // a detected jump ends the step
    // Re-linearise at the corrected motion; the measured motion becomes a prior there.
    linearization.T_prev_curr = boxPlus(linearization.T_prev_curr, estimated_motion_error);
    prior_motion_error = boxMinus(motion.T_prev_curr, linearization.T_prev_curr);
  }
  previous_motions_.push_back(motion);
  if (static_cast<int>(previous_motions_.size()) > kTwistTrendIncrements)
    previous_motions_.erase(previous_motions_.begin());
  if (report.jump != JumpBlock::kNone) monitor_.clearWindow();  // the evidence was the jump's
  monitor_.addUpdate(motion.dt, has_scores_ ? &scores_ : nullptr);
  report.consistency = monitor_.status();
  report.accepted = true;
  return report;
}

bool CalibrationFilter::wantsMotionRelinearized(const MotionIncrement& motion) const {
  // Where the measured motion is a poor linearisation point: a slow or standing vehicle,
  // whose translation per step is mostly the odometry's noise (depth times that noise fakes
  // a metric parallax, hence a baseline: the hovering rig, cars at their stops; there the
  // first pass's motion correction was 20-30 % of the measured translation). At speed the
  // second pass moved the estimate by < 0.1 sigma per step (default campaign runs 5, 91,
  // 106, 143) and costs as much as the first. (Repeating also while a block settles after
  // its start or re-opening was measured too: 157 instead of 156 honest campaign runs, but
  // paper_offroad's yaw_r +18 % and a sideways hand-eye start's zl at 3.3 sigma.)
  constexpr double kSlowSpeed = 2.0;  // m/s
  const double speed = motion.dt > 0.0 ? motion.T_prev_curr.translation().norm() / motion.dt : 0.0;
  return speed < kSlowSpeed;
}

bool CalibrationFilter::runPass(const MotionIncrement& motion, const Vector6d& prior_motion_error,
                                const std::vector<PointMeasurement>& measurements, bool final_pass,
                                bool detect_jump, StepReport* out, Vector6d* motion_error) {
  StepReport& report = *out;
  has_scores_ = false;
  // ---- prediction (Sec. II-B) ----
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  std::vector<bool> remove;
  MatrixXd P = predict(motion, &remove);
  const int G = static_cast<int>(P.rows());

  // ---- linearised measurements of every measured point (Sec. II-C) ----
  std::vector<PointInnovation> innovations;
  std::vector<bool> measured(points_.size(), false);
  for (const PointMeasurement& m : measurements) {
    if (!m.z.allFinite() || !m.variance.allFinite() || !(m.variance.minCoeff() > 0.0)) {
      ++report.invalid_measurements;
      continue;
    }
    const auto found = index_.find(m.id);
    if (found == index_.end() || remove[found->second]) continue;
    const size_t i = found->second;
    PointInnovation inn;
    if (!linearizeMeasurement(i, P, m.z, m.variance, &inn)) {
      continue;  // behind a camera for some sigma point: not measurable, dropped below
    }
    measured[i] = true;
    innovations.push_back(inn);
  }

  // With a prior motion error (a re-linearised pass) the innovation is r - J * prior.
  if (shared && !prior_motion_error.isZero()) {
    VectorXd prior = VectorXd::Zero(G);
    prior.tail<6>() = prior_motion_error;
    for (PointInnovation& inn : innovations) {
      const Eigen::Vector4d v = inn.residual - inn.J * prior;
      inn.nis = v.dot(inn.S.llt().solve(v));
      inn.nis_left = v.head<2>().dot(inn.S.topLeftCorner<2, 2>().llt().solve(v.head<2>()));
    }
  }

  // ---- gate outliers; many at once means the calibration itself jumped ----
  std::vector<const PointInnovation*> used;
  int left_failures = 0;
  for (const PointInnovation& inn : innovations) {
    if (inn.nis <= config_.outlier_gate) {
      used.push_back(&inn);
    } else {
      report.outliers.push_back(points_[inn.point].id);
      remove[inn.point] = true;
      if (inn.nis_left > kLeftGate) ++left_failures;
    }
  }
  const int tested = static_cast<int>(innovations.size());
  // The left image does not see x_camr: if it fails too, x_caml moved (via eq. 8).
  const JumpBlock suspect = 2 * left_failures >= static_cast<int>(report.outliers.size())
                                ? JumpBlock::kVehicleToLeft
                                : JumpBlock::kLeftToRight;
  const double rejected = static_cast<double>(report.outliers.size());
  const bool enough_tested = tested >= config_.jump_min_points;
  if (detect_jump) {
    const bool partly =
        enough_tested && rejected >= config_.jump_sustained_rejected_fraction * tested;
    rejection_streak_ = partly ? rejection_streak_ + 1 : 0;
  }
  // Not while the suspect block is still settling: a start-up transient gates out many
  // points for some frames too (default campaign run 180 re-opened x_camr at frame 32).
  const bool sustained = config_.jump_sustained_frames > 0 &&
                         rejection_streak_ >= config_.jump_sustained_frames &&
                         time_since_opened_[blockIndex(suspect)] >= config_.jump_settle_time;
  const bool at_once = rejected >= config_.jump_rejected_fraction * tested;
  if (detect_jump && enough_tested && (at_once || sustained) && canReopen(suspect)) {
    report.jump = suspect;
    rejection_streak_ = 0;
    if (shared) marginalizeMotionError(P);
    report.message = "sudden calibration change detected";
    // Only a jump found at once has all its tracked points measured across it; after a
    // sustained test most were initialised after it.
    const bool fitted = at_once && suspect == JumpBlock::kVehicleToLeft &&
                        reopenLeftCameraAtFittedRotation(innovations, &report);
    if (!fitted) reopenBlock(report.jump, &report);
    report.lost.reserve(points_.size());
    for (const TrackedPoint& point : points_) report.lost.push_back(point.id);
    report.outliers.clear();
    points_.clear();
    index_.clear();
    report.message += "; points re-initialised";
    return false;
  }

  // ---- Kalman update of the global block with the points marginalised ----
  // Each residual r_i = J_i dg + n_i, n_i ~ N(0, S0_i) independent given g, so the update
  // is a sequence of small exact updates: P -= K S K^T (O(G^2) each; P is symmetrised and
  // checked for positive definiteness once at the end, see repairCovariance()).
  VectorXd dg = VectorXd::Zero(G);  // prior mean of the global error
  if (shared) dg.tail<6>() = prior_motion_error;
  double nis_sum = 0.0;
  // From a start or a re-opening far from the truth one update may not shrink a
  // calibration sigma by more than max_sigma_shrink_per_update (update_tempering.h).
  std::vector<LinearizedMeasurement> linearized;
  linearized.reserve(used.size());
  for (const PointInnovation* inn : used) linearized.push_back({&inn->J, &inn->S0});
  const double tempering =
      updateTempering(P, linearized, layout::kCalibrationDim, config_.max_sigma_shrink_per_update);
  report.tempering = tempering;
  // The update's information for the consistency monitor (consistency_monitor.h):
  // A = sum J^T S0^-1 J, b = sum J^T S0^-1 v, c = sum v^T S0^-1 v with v = r - J dg_prior.
  // A tempered update is linearised far from the truth: its innovations say so, not that
  // the calibration drifts. Fed to the consistency monitor they raised x_camr's process
  // noise for tens of seconds (x_camr RMSE +15-30 % over the default campaign).
  const bool monitored =
      final_pass && config_.consistency_window > 0.0 && !used.empty() && tempering == 1.0;
  const VectorXd dg_prior = dg;
  MatrixXd information = monitored ? MatrixXd::Zero(G, G) : MatrixXd();
  VectorXd score = monitored ? VectorXd::Zero(G) : VectorXd();
  double residual_norm = 0.0;
  MatrixXd PJt, gain;
  for (size_t k = 0; k < used.size(); ++k) {
    const PointInnovation* inn = used[k];
    // A point whose S is indefinite is skipped here; its own update below uses S0 only.
    if (!sequentialGain(P, linearized[k], tempering, &PJt, &gain)) continue;
    dg += gain * (inn->residual - inn->J * dg);
    P.noalias() -= gain * PJt.transpose();
    nis_sum += inn->nis;
    if (monitored) {
      const Eigen::Matrix4d S0_inverse = inn->S0.inverse();
      const Eigen::Vector4d v = inn->residual - inn->J * dg_prior;
      const MatrixXd JtS0i = inn->J.transpose() * S0_inverse;
      information.noalias() += JtS0i * inn->J;
      score.noalias() += JtS0i * v;
      residual_norm += v.dot(S0_inverse * v);
    }
  }
  P = 0.5 * (P + P.transpose());
  if (monitored) {
    scores_ = computeUpdateScores(information, score, residual_norm, P,
                                  layout::kMeasurementDim * static_cast<int>(used.size()));
    has_scores_ = true;
  }
  *motion_error = shared ? Vector6d(dg.tail<6>()) : Vector6d::Zero();
  if (!final_pass) return true;
  report.measurements_used = static_cast<int>(used.size());
  report.mean_nis = used.empty() ? 0.0 : nis_sum / used.size();

  // ---- each point given the global error: e_i | z_i, then re-expressed on the new g ----
  for (const PointInnovation* inn : used) {
    TrackedPoint& point = points_[inn->point];
    const Eigen::Matrix<double, 3, 4> K = point.D * inn->H_p.transpose() * inn->S0.inverse();
    point.mean += K * inn->residual + (point.B - K * inn->J) * dg;
    point.B -= K * inn->J;
    point.updated = true;
    const Eigen::Matrix3d IKH = Eigen::Matrix3d::Identity() - K * inn->H_p;
    point.D = IKH * point.D * IKH.transpose() +
              K * (inn->S0 - inn->H_p * point.D * inn->H_p.transpose()) * K.transpose();
  }

  // ---- apply the correction on the manifold; drop the step's motion error ----
  extrinsics_.T_veh_caml = boxPlus(extrinsics_.T_veh_caml, dg.segment<6>(layout::kCaml));
  extrinsics_.T_caml_camr = boxPlus(extrinsics_.T_caml_camr, dg.segment<6>(layout::kCamr));
  if (time_offset_index_ >= 0) {
    time_offset_ = std::clamp(time_offset_ + dg(time_offset_index_), -config_.max_time_offset,
                              config_.max_time_offset);
  }
  for (size_t k = 0; k < velocity_bias_axes_.size(); ++k)
    velocity_bias_(velocity_bias_axes_[k]) += dg(velocity_bias_index_ + static_cast<int>(k));
  if (drift_rate_index_ >= 0) drift_rate_ += dg.segment<3>(drift_rate_index_);
  if (shared) {
    marginalizeMotionError(P);
  } else {
    covariance_ = P;
  }
  report.covariance_repaired = repairCovariance();

  for (size_t i = 0; i < points_.size(); ++i) {
    if (!measured[i]) {  // not found in both images, or not predictable: Sec. II-C deletion
      report.lost.push_back(points_[i].id);
      remove[i] = true;
    }
  }
  removeIndices(remove);
  if (innovations.empty()) report.message = "no usable measurements: prediction only";
  return true;
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

MatrixXd CalibrationFilter::predictAnew(const MotionIncrement& motion, std::vector<bool>* failed) {
  applyCalibrationDrift(motion.dt);
  const bool shared = config_.motion_noise_model == MotionNoiseModel::kShared;
  const int G = persistentDim() + (shared ? layout::kPoseDim : 0);
  MatrixXd P = MatrixXd::Zero(G, G);
  P.topLeftCorner(persistentDim(), persistentDim()) = covariance_;
  if (shared) {
    // The odometry's own covariance of this increment when it gives one, else the model.
    P.bottomRightCorner<6, 6>() =
        motion.has_covariance ? motion.covariance : motionNoiseCovariance(config_, motion.dt);
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

void CalibrationFilter::widenRotationVariance(JumpBlock block, const Eigen::Vector3d& added) {
  if (block == JumpBlock::kNone) return;
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  covariance_.diagonal().segment<3>(first + layout::kRotation) += added;
}

bool CalibrationFilter::canReopen(JumpBlock block) const {
  // While a block is still as uncertain as a re-opened one (start-up), many gated-out points
  // are the ordinary transient, not a sudden change.
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  const Vector6d variance = covariance_.diagonal().segment<6>(first);
  if (!(variance.segment<3>(layout::kRotation).maxCoeff() <
        std::pow(config_.jump_rotation_sigma, 2)))
    return false;
  // A translation the motion cannot determine (zl on a flat road) never gets below the
  // re-opened sigma; once the block has had time to settle its rotation alone decides
  // (an x_caml yaw step on an urban drive went undetected for 150 frames).
  return variance.segment<3>(layout::kTranslation).maxCoeff() <
             std::pow(config_.jump_translation_sigma, 2) ||
         time_since_opened_[blockIndex(block)] >= config_.jump_settle_time;
}

void CalibrationFilter::reopenBlock(JumpBlock block, StepReport* report) {
  report->jump_sigma =
      uniformBlockSigmas(config_.jump_translation_sigma, config_.jump_rotation_sigma);
  widenBlock(block, report->jump_sigma);
}

bool CalibrationFilter::reopenLeftCameraAtFittedRotation(
    const std::vector<PointInnovation>& innovations, StepReport* report) {
  if (!(config_.jump_fit_rotation_sigma > 0.0)) return false;
  // The points are stored in the left optical frame, so their predictions carry the old
  // mounting: a camera turned by Q (R_veh_caml -> R_veh_caml Q) sees them at Q^T times
  // their predicted bearings.
  const Eigen::Matrix3d K_inverse = intrinsics_.K_left.inverse();
  std::vector<Eigen::Vector3d> predicted, measured;
  for (const PointInnovation& inn : innovations) {
    const Eigen::Vector2d left = inn.predicted.head<2>();
    predicted.push_back(K_inverse * left.homogeneous());
    measured.push_back(K_inverse * (left + inn.residual.head<2>()).homogeneous());
  }
  // Trimmed beyond 3 median angles, but never below ~5 pixels' worth of angle.
  const double min_trim_angle = 5.0 / intrinsics_.K_left(0, 0);
  BearingRotationFit fit;
  if (!fitBearingRotation(predicted, measured, min_trim_angle, config_.jump_min_points, &fit)) {
    return false;
  }
  // The turn must explain the points to their own predicted accuracy: a filter that is
  // merely off (its points initialised with a wrong mounting after a stretch without
  // points) gates many out at once too, and no single turn fits those.
  int explained = 0;
  for (size_t i = 0; i < innovations.size(); ++i) {
    const PointInnovation& inn = innovations[i];
    const Eigen::Vector2d turned_pixel =
        (intrinsics_.K_left * fit.rotation * predicted[i]).hnormalized();
    const Eigen::Vector2d r = inn.predicted.head<2>() + inn.residual.head<2>() - turned_pixel;
    if (r.dot(inn.S.topLeftCorner<2, 2>().llt().solve(r)) <= kLeftGate) ++explained;
  }
  if (explained < config_.jump_rejected_fraction * static_cast<double>(innovations.size())) {
    return false;
  }
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Matrix3d Q_body = R_bo * fit.rotation.transpose() * R_bo.transpose();
  const Eigen::Vector3d turned = logSO3(Q_body);  // dtheta of x_caml (pose.h boxPlus)
  extrinsics_.T_veh_caml.linear() = extrinsics_.T_veh_caml.linear() * Q_body;
  // Each axis is re-opened by what it turned, at least the floor: those that did not turn
  // keep nearly what they knew (a yaw step of a sideways camera re-opened to 10 deg on every
  // axis left pitch_l, told only by turns, 3 sigma off at sigma 1 deg; default campaign run
  // 144).
  Vector6d sigma;
  sigma.head<3>().setConstant(config_.jump_translation_sigma);
  for (int k = 0; k < 3; ++k) {
    sigma(3 + k) = std::min(config_.jump_rotation_sigma,
                            std::max(config_.jump_fit_rotation_sigma, std::abs(turned(k))));
  }
  report->jump_sigma = sigma;
  widenBlock(JumpBlock::kVehicleToLeft, sigma);
  std::ostringstream message;
  message << " (x_caml: its rotation fitted to " << fit.inliers << " of " << innovations.size()
          << " points, explaining " << explained << ", turned it by "
          << turned.norm() * 180.0 / M_PI << " deg, rms " << fit.rms_angle * 180.0 / M_PI
          << " deg; re-opened to 1 sigma " << sigma.tail<3>().transpose() * 180.0 / M_PI
          << " deg about its x/y/z)";
  report->message += message.str();
  return true;
}

std::vector<PointId> CalibrationFilter::reopen(JumpBlock block, const Vector6d& sigma) {
  std::vector<PointId> removed;
  if (block == JumpBlock::kNone) return removed;
  for (const TrackedPoint& point : points_) removed.push_back(point.id);
  points_.clear();
  index_.clear();
  last_prediction_.reset();
  monitor_.clearWindow();
  widenBlock(block, sigma);
  return removed;
}

void CalibrationFilter::widenBlock(JumpBlock block, const Vector6d& sigma) {
  if (block == JumpBlock::kNone) return;
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  const Vector6d variance =
      covariance_.diagonal().segment<6>(first).cwiseMax(sigma.cwiseProduct(sigma));
  // Decorrelate the re-opened block from the rest: its old correlations no longer hold.
  covariance_.middleRows<6>(first).setZero();
  covariance_.middleCols<6>(first).setZero();
  covariance_.block<6, 6>(first, first) = variance.asDiagonal();
  time_since_opened_[blockIndex(block)] = 0.0;
}

bool CalibrationFilter::repairCovariance() {
  // Keep P symmetric; if rounding made it indefinite, clamp its spectrum (reported).
  MatrixXd P = covariance_;
  const double floor = 1e-18;
  const bool repaired = makeSymmetricPsd(&P, 0.0);
  if (Eigen::LLT<MatrixXd>(P).info() != Eigen::Success) {
    makeSymmetricPsd(&P, floor);
    covariance_ = P;
    return true;
  }
  covariance_ = P;
  for (TrackedPoint& point : points_) {
    MatrixXd D = point.D;
    if (makeSymmetricPsd(&D, 1e-12)) point.D = D;
  }
  return repaired;
}

void CalibrationFilter::removeIndices(const std::vector<bool>& remove) {
  size_t kept = 0;
  for (size_t i = 0; i < points_.size(); ++i) {
    if (!remove[i]) points_[kept++] = std::move(points_[i]);
  }
  points_.resize(kept);
  rebuildIndex();
}

void CalibrationFilter::rebuildIndex() {
  index_.clear();
  for (size_t i = 0; i < points_.size(); ++i) index_[points_[i].id] = i;
}

bool CalibrationFilter::addPoint(const PointMeasurement& m) {
  if (hasPoint(m.id) || !m.z.allFinite() || !m.variance.allFinite() ||
      !(m.variance.minCoeff() > 0.0)) {
    return false;
  }
  // Scaled UT over [x_camr (6), left pixel noise (2), right pixel noise (2)] (Sec. II-A).
  MatrixXd C = MatrixXd::Zero(10, 10);
  C.topLeftCorner<6, 6>() = covariance_.block<6, 6>(layout::kCamr, layout::kCamr);
  C.bottomRightCorner<4, 4>() = m.variance.asDiagonal();
  const double min_depth = config_.min_point_depth, max_depth = config_.max_point_depth;
  const bool scaled = config_.baseline_scaled_points != 0;
  const VectorFunction triangulate = [&](const VectorXd& x, VectorXd* y) {
    const Eigen::Isometry3d T_caml_camr = boxPlus(extrinsics_.T_caml_camr, x.head<6>());
    const Eigen::Isometry3d T_lopt_ropt = leftToRightOptical(T_caml_camr);
    const double scale = pointScale(T_caml_camr);
    if (!(scale > 0.0)) return false;
    Eigen::Vector3d metric;
    if (coordinates_.inverseDepth()) {
      // Any disparity has an inverse depth: a sigma point beyond infinity is still one.
      const auto c = triangulateInverseDepth(m.z + x.tail<4>(), T_lopt_ropt, intrinsics_);
      if (!c || c->z() > 2.0 / min_depth) return false;
      metric = *c;
    } else {
      const auto p = triangulateStereo(m.z + x.tail<4>(), T_lopt_ropt, intrinsics_);
      if (!p || p->z() < 0.5 * min_depth || p->z() > 2.0 * max_depth) return false;
      metric = *p;
    }
    // In units of this sigma point's baseline: a function of the pixels and x_camr's
    // rotation and direction only (the disparity), not of the baseline's length.
    Eigen::Vector3d stored;
    if (!coordinates_.fromHomogeneous(scaledFromMetric(coordinates_.homogeneous(metric), scale),
                                      &stored))
      return false;
    if (scaled) {
      // ... and the metric point as well, for the depth check below.
      y->resize(6);
      *y << stored, metric;
    } else {
      *y = stored;
    }
    return true;
  };
  UnscentedResult ut;
  if (!unscentedTransformWithFallback(VectorXd::Zero(10), C, triangulate, ut_, &ut)) return false;
  // The depth is judged in metres over the baseline's uncertainty: the mean of the metric
  // point over the sigma points, as with metric points. (The stored point's mean in units
  // of the baseline times the mean baseline would not see that baseline: a small rig with a
  // baseline prior as wide as the baseline would accept points whose metric depth is
  // unknown to a factor of two or more, and some such runs ended 40-200 sigma off.)
  const double depth = coordinates_.depth(scaled ? Eigen::Vector3d(ut.mean.tail<3>())
                                                 : Eigen::Vector3d(ut.mean.head<3>()));
  if (!(depth >= min_depth && depth <= max_depth)) return false;
  TrackedPoint point;
  point.id = m.id;
  point.mean = ut.mean.head<3>();
  point.B = MatrixXd::Zero(3, persistentDim());
  point.B.middleCols<6>(layout::kCamr) = ut.jacobian.topLeftCorner<3, 6>();
  // D = Cov(p) - B P B^T: what the calibration does not explain (pixel noise, nonlinearity).
  MatrixXd D = ut.covariance.topLeftCorner<3, 3>() - point.B * covariance_ * point.B.transpose();
  makeSymmetricPsd(&D, 1e-12);
  point.D = D;
  index_[point.id] = points_.size();
  points_.push_back(std::move(point));
  return true;
}

void CalibrationFilter::removePoint(PointId id) {
  const auto found = index_.find(id);
  if (found == index_.end()) return;
  std::vector<bool> remove(points_.size(), false);
  remove[found->second] = true;
  removeIndices(remove);
}

Matrix12d CalibrationFilter::parameterCovariance() const {
  const Matrix12d J = parameterJacobian(extrinsics_);
  return J * covariance() * J.transpose();
}

std::vector<PointEstimate> CalibrationFilter::points() const {
  std::vector<PointEstimate> result;
  result.reserve(points_.size());
  // Metres = scale * stored position; the scale (the baseline's length) is uncertain too:
  // d scale = u^T dt_r (u: the baseline's direction; boxPlus adds translations).
  const double scale = pointScale();
  const double min_inverse_depth = minInverseDepth() * scale;
  MatrixXd scale_row = MatrixXd::Zero(1, covariance_.rows());
  if (config_.baseline_scaled_points != 0 && scale > 0.0) {
    scale_row.middleCols<3>(layout::kCamr + layout::kTranslation) =
        extrinsics_.T_caml_camr.translation().transpose() / scale;
  }
  for (const TrackedPoint& point : points_) {
    PointEstimate e;
    e.id = point.id;
    const Eigen::Vector3d stored = coordinates_.position(point.mean, min_inverse_depth);
    e.position_lopt = scale * stored;
    // Cov(position) = J^-1 Cov(c) J^-T, J = d c / d position (a far point: clamped as above),
    // plus the scale's share.
    Eigen::Matrix3d J_inverse = Eigen::Matrix3d::Identity();
    if (coordinates_.inverseDepth()) {
      Eigen::Vector3d clamped = point.mean;
      clamped.z() = std::max(clamped.z(), min_inverse_depth);
      J_inverse = coordinates_.jacobianFromPosition(clamped).inverse();
    }
    const MatrixXd M =
        scale * J_inverse * point.B.leftCols(covariance_.cols()) + stored * scale_row;
    e.covariance = M * covariance_ * M.transpose() +
                   scale * scale * J_inverse * point.D * J_inverse.transpose();
    result.push_back(e);
  }
  return result;
}

MatrixXd CalibrationFilter::denseCovariance() const {
  const int g = persistentDim();
  const int n = g + 3 * static_cast<int>(points_.size());
  MatrixXd full = MatrixXd::Zero(n, n);
  full.topLeftCorner(g, g) = covariance_;
  for (size_t i = 0; i < points_.size(); ++i) {
    const int a = g + 3 * static_cast<int>(i);
    const MatrixXd BP = points_[i].B * covariance_;
    full.block(a, 0, 3, g) = BP;
    full.block(0, a, g, 3) = BP.transpose();
    for (size_t j = 0; j < points_.size(); ++j) {
      const int b = g + 3 * static_cast<int>(j);
      full.block(a, b, 3, 3) = BP * points_[j].B.transpose();
    }
    full.block(a, a, 3, 3) += points_[i].D;
  }
  return full;
}

}  // namespace osc
