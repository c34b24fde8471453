/// @file stereo_calibration_estimator.h
/// @brief The facade every front end calls (simulators, the offline evaluator, the ROS
/// nodelet): raw stereo observations + measured motion in, calibration out.
///
/// It converts raw pixels to the filter's undistorted measurements with the camera models,
/// routes tracked points to the filter's update and unknown ones to point initialisation,
/// and keeps the bookkeeping of one image pair at a time.
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// The estimate after one image pair, in the interface's terms.
struct CalibrationEstimate {
  StereoExtrinsics extrinsics;
  Vector12d parameters = Vector12d::Zero();            ///< interface order, m and rad
  Matrix12d parameter_covariance = Matrix12d::Zero();  ///< of parameters
  Matrix12d tangent_covariance = Matrix12d::Zero();    ///< of the filter's manifold error
  size_t tracked_points = 0;
  /// MotionExcitation gains of the recent vehicle rotation (roll, pitch, yaw), in [0, 1]:
  /// which parts of x_caml the current motion can determine (unexcitedTranslationAxes).
  Eigen::Vector3d excitation = Eigen::Vector3d::Ones();
  /// The filter's consistency monitor: per-block statistics and the drift-noise factors.
  ConsistencyStatus consistency;

  /// 1-sigma of each parameter (sqrt of the covariance diagonal).
  Vector12d sigmas() const { return parameter_covariance.diagonal().cwiseMax(0.0).cwiseSqrt(); }
};

/// What happened to one image pair.
struct FrameReport {
  bool motion_rejected = false;  ///< the motion was unusable: points dropped, calibration kept
  StepReport step;               ///< the filter step (empty for the first pair)
  int new_points = 0;            ///< points initialised from this pair
  int rejected_new_points = 0;   ///< candidate points that did not triangulate in range
  int invalid_observations = 0;  ///< non-finite pixels or sigmas
  /// Points no longer in the filter (lost, outliers, reset): a tracker should forget them.
  std::vector<PointId> dropped;
  std::vector<std::string> warnings;  ///< human-readable, one per problem
};

/// Online stereo extrinsic calibration from stereo observations and vehicle motion.
class StereoCalibrationEstimator {
 public:
  /// @throws std::invalid_argument naming the bad config value or camera field.
  StereoCalibrationEstimator(const FilterConfig& config, const CameraIntrinsics& left,
                             const CameraIntrinsics& right, const StereoExtrinsics& initial_guess);

  /// Processes one image pair. motion_since_previous is the vehicle motion since the
  /// previous pair; it is ignored for the first pair (and after resetTracking()).
  FrameReport processFrame(const MotionIncrement& motion_since_previous,
                           const std::vector<StereoObservation>& observations);

  /// Forgets every tracked point (e.g. time jumped back); the calibration is kept.
  std::vector<PointId> resetTracking();
  /// The right camera was knocked (CalibrationPipeline): x_camr's rotation uncertainty is
  /// re-opened to at least `rotation_sigma` (rad; its translation kept: a knock turns a
  /// camera) and every point is forgotten. Returns the forgotten points.
  std::vector<PointId> reopenRightCameraRotation(double rotation_sigma);
  /// Starts over from a new guess with the config's initial uncertainty.
  void reset(const StereoExtrinsics& guess);
  /// Starts over from a saved calibration with its covariance (tangent, see filter).
  void reset(const StereoExtrinsics& guess, const Matrix12d& tangent_covariance);

  CalibrationEstimate estimate() const;
  const CalibrationFilter& filter() const { return filter_; }
  const CameraModel& leftCamera() const { return left_; }
  const CameraModel& rightCamera() const { return right_; }

 private:
  bool toMeasurement(const StereoObservation& observation, PointMeasurement* measurement) const;

  FilterConfig config_;
  CameraModel left_;
  CameraModel right_;
  CalibrationFilter filter_;
  bool has_previous_frame_ = false;
};

}  // namespace osc
