/// @file calibration_filter_internal.h
/// @brief Private to CalibrationFilter's source files (calibration_filter*.cpp): the helpers
/// they share and the definitions of its nested PointInnovation and Prediction.
#pragma once

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

#include "online_stereo_calibration/core/filter/calibration_filter.h"

namespace osc {
namespace calibration_filter_internal {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// Steady-state 1 sigma of the odometry's velocity error along a vehicle axis (0 x forward).
/// The forward axis has its own (FilterConfig::odometry_forward_velocity_bias_sigma): with
/// metric points a forward state took spurious information from linearisation and moved the
/// baseline with it (clean drives 25 -> 20 of 50 honest, yr); with points in units of the
/// baseline the baseline enters only through the motion, and at half the lateral sigma it
/// helps (docs/RESULTS.md "Session 12"). The vertical one matters most (lateral only:
/// campaign C_odometry 17 -> 4 of 50 honest).
inline double velocityBiasPriorSigma(const FilterConfig& config, int axis) {
  return axis == 0 ? config.odometry_forward_velocity_bias_sigma
                   : config.odometry_velocity_bias_sigma;
}

/// 0 for x_caml, 1 for x_camr (JumpBlock::kNone is not a block).
inline size_t blockIndex(JumpBlock block) { return block == JumpBlock::kVehicleToLeft ? 0 : 1; }

inline Matrix12d initialCovariance(const FilterConfig& c) {
  using namespace layout;
  Vector12d sigma;
  sigma.segment<3>(kCaml + kTranslation).setConstant(c.initial_caml_translation_sigma);
  sigma.segment<3>(kCaml + kRotation).setConstant(c.initial_caml_rotation_sigma);
  sigma.segment<3>(kCamr + kTranslation).setConstant(c.initial_camr_translation_sigma);
  sigma.segment<3>(kCamr + kRotation).setConstant(c.initial_camr_rotation_sigma);
  return sigma.array().square().matrix().asDiagonal();
}

inline Eigen::Isometry3d leftToRightOptical(const Eigen::Isometry3d& T_caml_camr) {
  StereoExtrinsics e;
  e.T_caml_camr = T_caml_camr;
  return e.leftToRightOptical();
}

/// Joint covariance of [g(selected), p] for a point p = mean + B dg + e.
inline MatrixXd jointCovariance(const MatrixXd& P, const std::vector<int>& selected,
                                const MatrixXd& B, const Eigen::Matrix3d& D) {
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
inline bool unscentedTransformWithFallback(const VectorXd& mean, const MatrixXd& covariance,
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
inline HomogeneousPoint metricFromScaled(const HomogeneousPoint& h, double scale) {
  return HomogeneousPoint(h.x(), h.y(), h.z(), h.w() / scale);
}
inline HomogeneousPoint scaledFromMetric(const HomogeneousPoint& h, double scale) {
  return HomogeneousPoint(h.x(), h.y(), h.z(), h.w() * scale);
}

inline std::vector<int> range(int first, int count) {
  std::vector<int> r(count);
  for (int k = 0; k < count; ++k) r[k] = first + k;
  return r;
}

/// Exactly equal (so that a reused prediction is bit for bit the one computed).
template <typename Point>
inline bool samePoints(const std::vector<Point>& a, const std::vector<Point>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].id != b[i].id || a[i].mean != b[i].mean || a[i].D != b[i].D ||
        a[i].B.rows() != b[i].B.rows() || a[i].B.cols() != b[i].B.cols() || a[i].B != b[i].B) {
      return false;
    }
  }
  return true;
}

inline bool motionCovarianceIsValid(const Matrix6d& covariance) {
  if (!covariance.allFinite()) return false;
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() >
      1e-9 * std::max(covariance.cwiseAbs().maxCoeff(), 1e-300)) {
    return false;
  }
  return Eigen::SelfAdjointEigenSolver<Matrix6d>(covariance).eigenvalues().minCoeff() >=
         -1e-12 * covariance.cwiseAbs().maxCoeff();
}

inline bool samePreviousMotions(const std::vector<MotionIncrement>& a,
                                const std::vector<MotionIncrement>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].dt != b[k].dt || a[k].T_prev_curr.matrix() != b[k].T_prev_curr.matrix()) return false;
  }
  return true;
}

}  // namespace calibration_filter_internal

using calibration_filter_internal::MatrixXd;
using calibration_filter_internal::VectorXd;

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

}  // namespace osc
