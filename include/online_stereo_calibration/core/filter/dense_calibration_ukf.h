/// @file dense_calibration_ukf.h
/// @brief A plain UKF of the same model over the full state [x_caml, x_camr, p_1..p_N]
/// with a dense (12+3N)^2 covariance and 2n+1 full-length sigma points.
///
/// It exists as the reference the structured CalibrationFilter is checked against (tests)
/// and compared with (benchmark); the package itself runs the structured filter.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/motion_excitation.h"

namespace osc {

class DenseCalibrationUkf {
 public:
  DenseCalibrationUkf(const FilterConfig& config, const StereoIntrinsics& intrinsics);

  void reset(const StereoExtrinsics& guess, const Matrix12d& covariance);
  /// Adds a point with the mean, covariance and calibration cross-covariance the
  /// structured filter computes (same SUT initialisation, Sec. II-A).
  bool addPoint(const PointMeasurement& measurement);
  /// Predict (eq. 7-28) and correct (eq. 29-30) with every tracked point measured;
  /// measurements must cover exactly the tracked points, in any order. False if the
  /// input is unusable (state untouched).
  bool step(const MotionIncrement& motion, const std::vector<PointMeasurement>& measurements);

  const StereoExtrinsics& extrinsics() const { return extrinsics_; }
  const Eigen::MatrixXd& covariance() const { return covariance_; }
  /// Point means in insertion order.
  const std::vector<Eigen::Vector3d>& pointMeans() const { return means_; }
  const std::vector<PointId>& pointIds() const { return ids_; }

 private:
  FilterConfig config_;
  MotionExcitation excitation_;
  UnscentedParameters ut_;
  StereoIntrinsics intrinsics_;
  StereoExtrinsics extrinsics_;
  Eigen::MatrixXd covariance_;  ///< (12 + 3N)^2, calibration in tangent coordinates
  std::vector<Eigen::Vector3d> means_;
  std::vector<PointId> ids_;
};

}  // namespace osc
