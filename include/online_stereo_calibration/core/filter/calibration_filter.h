/// @file calibration_filter.h
/// @brief The paper's UKF over [x_caml, x_camr, points] (seed eq. 4), in a structured
/// form whose cost grows linearly with the number of points.
///
/// Structure exploited: each point's prediction depends only on x_caml, the motion and
/// itself; each measurement only on x_camr and itself. Given the calibration g, the
/// points' errors are then independent, so the joint Gaussian is held exactly as
///   p_i = p_hat_i + B_i * dg + e_i,   e_i ~ N(0, D_i) independent,  dg ~ N(0, P),
/// i.e. Cov(p_i, g) = B_i P and Cov(p_i, p_j) = B_i P B_j^T + [i == j] D_i.
/// Each nonlinear step is a scaled unscented transform on one point's small joint state
/// (at most 15 dimensions), whose statistical linear regression is applied to this form;
/// the calibration update is the exact Kalman update of all points' measurements with the
/// points marginalised. Memory and time O(N) instead of O(N^2) / O(N^3).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/filter/measurement_model.h"
#include "online_stereo_calibration/core/filter/motion_excitation.h"
#include "online_stereo_calibration/core/filter/point_coordinates.h"
#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/filter/unscented_transform.h"
#include "online_stereo_calibration/core/filter/update_scores.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// One stereo measurement of a tracked point in undistorted pixels (measurement_model.h).
struct PointMeasurement {
  PointId id = 0;
  Eigen::Vector4d z = Eigen::Vector4d::Zero();         ///< [u_l, v_l, u_r, v_r]
  Eigen::Vector4d variance = Eigen::Vector4d::Ones();  ///< px^2 per coordinate
};

/// The filter's estimate of one tracked point.
struct PointEstimate {
  PointId id = 0;
  Eigen::Vector3d position_lopt = Eigen::Vector3d::Zero();  ///< left optical frame (m)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();     ///< marginal covariance
};

/// Where a tracked point is expected in the next image pair, before it is measured.
struct PredictedObservation {
  PointId id = 0;
  Eigen::Vector4d z = Eigen::Vector4d::Zero();  ///< predicted [u_l, v_l, u_r, v_r], undistorted px
  Eigen::Matrix4d S =
      Eigen::Matrix4d::Identity();  ///< innovation covariance (px^2), incl. pixel noise
  /// The point's depth in the left camera before the motion over its predicted depth after
  /// it: how much larger its surface appears in the new image (> 1 when approaching).
  double depth_ratio = 1.0;
};

/// Which calibration block a detected sudden change was attributed to.
enum class JumpBlock { kNone, kVehicleToLeft, kLeftToRight };

/// A block's re-opening sigmas [dt (3), dtheta (3)] with one width per kind.
inline Vector6d uniformBlockSigmas(double translation_sigma, double rotation_sigma) {
  Vector6d sigma;
  sigma << Eigen::Vector3d::Constant(translation_sigma), Eigen::Vector3d::Constant(rotation_sigma);
  return sigma;
}

/// One tested point at a step's outlier gate, as a change detector sees it (JumpTest).
struct GatedPoint {
  Eigen::Vector2d predicted_left = Eigen::Vector2d::Zero();  ///< undistorted px
  Eigen::Vector2d measured_left = Eigen::Vector2d::Zero();   ///< undistorted px
  Eigen::Matrix2d S_left = Eigen::Matrix2d::Identity();      ///< left 2x2 of the innovation cov.
  double nis_left = 0.0;   ///< the left image's share of the normalised innovation squared
  bool gated_out = false;  ///< beyond FilterConfig::outlier_gate
};

/// What the outlier gate of a step's first pass saw, before the update.
struct GateOutcome {
  std::vector<GatedPoint> points;  ///< every measured point that could be linearised
};

/// A change detector's verdict: re-open @p block before the update (which is then skipped
/// and every point dropped), or nothing (kNone).
struct Reopening {
  JumpBlock block = JumpBlock::kNone;
  /// The block's [dt (3), dtheta (3)] sigmas; each keeps its earlier sigma where larger.
  Vector6d sigma = Vector6d::Zero();
  /// x_caml's rotation moves R_veh_caml -> R_veh_caml * turn first (a fitted turn).
  bool turned = false;
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  std::string message;  ///< the event's line
};

/// Looks at a step's gate before its update (CalibrationFilter::step).
using ChangeDetector = std::function<Reopening(const GateOutcome&)>;

/// What one filter step did.
struct StepReport {
  bool accepted = false;              ///< false: the input was rejected and nothing changed
  std::string message;                ///< why it was rejected, or notes
  int measurements_used = 0;          ///< points that updated the filter
  int invalid_measurements = 0;       ///< non-finite or non-positive-variance measurements ignored
  std::vector<PointId> outliers;      ///< gated out (Mahalanobis) and removed
  std::vector<PointId> lost;          ///< not measured (or unpredictable) and removed
  JumpBlock jump = JumpBlock::kNone;  ///< a sudden calibration change was detected
  /// After a jump: the sigmas the block's [dt (3), dtheta (3)] were re-opened to (each
  /// component keeps its earlier sigma where that was larger).
  Vector6d jump_sigma = Vector6d::Zero();
  bool covariance_repaired = false;  ///< the calibration covariance had to be made PD
  double mean_nis = 0.0;             ///< mean normalised innovation squared of used points (4 dof)
  /// >= 1: the factor the update's measurement covariances were multiplied by so that no
  /// calibration sigma shrank by more than max_sigma_shrink_per_update (update_tempering.h).
  double tempering = 1.0;
};

/// Structured UKF for the stereo extrinsics and the tracked points.
class CalibrationFilter {
 public:
  /// @throws std::invalid_argument listing every invalid config value.
  CalibrationFilter(const FilterConfig& config, const StereoIntrinsics& intrinsics);

  /// Starts over from a guess with the config's initial sigmas; removes every point. The
  /// odometry states (the time offset) start from their priors too.
  void reset(const StereoExtrinsics& guess);
  /// Starts over from a guess with the given tangent covariance (see covariance()); the
  /// odometry states start from their priors.
  /// @throws std::invalid_argument if the covariance is not finite, symmetric PD.
  void reset(const StereoExtrinsics& guess, const Matrix12d& covariance);
  /// Re-linearises the calibration (StereoCalibrationEstimator's restart from the current
  /// estimate): its tangent covariance becomes @p covariance, uncorrelated with the rest, and
  /// every point is removed; the odometry states (time offset, velocity bias, x_camr's drift
  /// rate) keep what they learned.
  /// @throws std::invalid_argument if the covariance is not finite, symmetric PD.
  void restartCalibration(const Matrix12d& covariance);

  /// Predicts with the measured motion (eq. 7-28) and corrects with the measurements
  /// (eq. 29-30). Tracked points without a measurement are removed (Sec. II-C), and so
  /// are outliers. A rejected motion leaves the filter untouched (report.accepted false).
  /// @p detect, when given, sees the first pass's gate before the update; when it returns
  /// a block, the block is re-opened as it says, every point is dropped and the step ends
  /// without an update (report.jump).
  StepReport step(const MotionIncrement& motion, const std::vector<PointMeasurement>& measurements,
                  const ChangeDetector& detect = ChangeDetector());

  /// Where each tracked point will be seen after the motion, with its innovation
  /// covariance (for the tracker's search windows, Sec. II-C). The filter is not changed.
  /// Empty if the motion is unusable.
  std::vector<PredictedObservation> predictObservations(const MotionIncrement& motion) const;

  /// Triangulates a new point with a scaled UT over x_camr and both pixels' noise and
  /// adds it with its covariance and its cross-covariance with the calibration (Sec. II-A).
  /// False (and nothing added) if the rays do not meet within the depth range.
  bool addPoint(const PointMeasurement& measurement);
  void removePoint(PointId id);
  bool hasPoint(PointId id) const { return index_.count(id) > 0; }
  /// A sudden change of one camera's mounting found outside the filter (the front end finds
  /// no stereo pair any more, CalibrationPipeline): the block's uncertainty is widened to at
  /// least the given sigmas and decorrelated from the rest, and every point is removed (their
  /// regressions on the block no longer hold). @p sigma: [dt (3), dtheta (3)] of the block's
  /// tangent error (uniformBlockSigmas). Returns the removed points' ids.
  std::vector<PointId> reopen(JumpBlock block, const Vector6d& sigma);
  size_t pointCount() const { return points_.size(); }
  /// A block may be re-opened: its rotation sigmas are below jump_rotation_sigma and its
  /// translation sigmas below jump_translation_sigma or it has had jump_settle_time_s since it
  /// was started or widened (while as uncertain as a re-opened block, many gated-out points are
  /// the start-up transient, not a change).
  bool canReopen(JumpBlock block) const;
  /// s of accepted motion since @p block was started or widened.
  double timeSinceOpened(JumpBlock block) const {
    return time_since_opened_[block == JumpBlock::kVehicleToLeft ? 0 : 1];
  }
  /// Adds @p added (rad^2, per axis) to the variances of @p block's rotation; mean, points and
  /// correlations kept (a widening on evidence, not a re-opening).
  void widenRotationVariance(JumpBlock block, const Eigen::Vector3d& added);
  /// The last step's update scores (update_scores.h), nullptr when its final pass made no
  /// monitored update (no measurement, a tempered update, the monitor off).
  const UpdateScores* lastUpdateScores() const { return has_scores_ ? &scores_ : nullptr; }
  /// How many times the filter was started (reset, restartCalibration): a component that
  /// counts steps since a start compares it.
  int starts() const { return starts_; }
  /// How many times a block was re-opened (reopen, or a change detector's verdict in a step):
  /// a component whose evidence a re-opening ends (the consistency monitor) compares it.
  int reopenings() const { return reopenings_; }
  /// The factors on the calibration's random walk (eq. 10-13) from the next prediction on
  /// (the consistency monitor's; 1 = as configured). A prediction kept by
  /// predictObservations with other factors is dropped.
  void setDriftInflation(const DriftInflation& factors) {
    if (factors == drift_inflation_) return;
    drift_inflation_ = factors;
    last_prediction_.reset();
  }
  /// The factors on the configured motion noise's variance, translation and rotation, from the
  /// next prediction on (the odometry noise matcher's; 1 = as configured). A prediction kept
  /// by predictObservations with other factors is dropped.
  void setMotionNoiseFactors(const std::array<double, 2>& factors) {
    if (factors == motion_noise_factors_) return;
    motion_noise_factors_ = factors;
    last_prediction_.reset();
  }
  /// The last step's evidence on the motion noise (none: no update, or the per-point model).
  const MotionNoiseEvidence* lastMotionNoiseEvidence() const {
    return has_motion_evidence_ ? &motion_evidence_ : nullptr;
  }
  /// How much of the recent vehicle rotation is excitation, per axis (MotionExcitation).
  Eigen::Vector3d excitationGains() const { return excitation_.gains(); }

  const StereoExtrinsics& extrinsics() const { return extrinsics_; }
  /// Covariance of the tangent error [dt_l, dtheta_l, dt_r, dtheta_r] (pose.h boxPlus).
  Matrix12d covariance() const { return covariance_.topLeftCorner<12, 12>(); }
  /// Covariance of the interface's 12 parameters (RPY), by first-order propagation.
  Matrix12d parameterCovariance() const;

  /// The camera-odometry time offset state (FilterConfig::initial_time_offset_sigma;
  /// process_model.h correctedMotion): camera clock minus odometry clock (s), and its 1 sigma
  /// (0 when not estimated).
  double timeOffset() const { return time_offset_; }
  double timeOffsetSigma() const { return stateSigma(time_offset_index_); }
  /// The odometry's velocity error state (FilterConfig::odometry_velocity_bias_sigma and
  /// odometry_forward_velocity_bias_sigma; m/s, vehicle axes; 0 on an axis not estimated) and
  /// its 1 sigmas (0 when not estimated).
  const Eigen::Vector3d& velocityBias() const { return velocity_bias_; }
  Eigen::Vector3d velocityBiasSigma() const;
  /// x_camr's rotation drift rate (rad/s, boxPlus tangent; FilterConfig::
  /// camr_rotation_drift_rate_sigma) and its 1 sigmas (zero when not estimated).
  const Eigen::Vector3d& camrDriftRate() const { return drift_rate_; }
  Eigen::Vector3d camrDriftRateSigma() const;
  std::vector<PointEstimate> points() const;
  /// The full (P + 3N)^2 covariance the structured form represents (P = 12 + the odometry
  /// states + x_camr's drift rate), points in the order of points() and in the filter's point
  /// coordinates (FilterConfig::inverse_depth_points, in units of the baseline with
  /// FilterConfig::baseline_scaled_points). For tests and diagnostics; O(N^2).
  Eigen::MatrixXd denseCovariance() const;

  const FilterConfig& config() const { return config_; }
  const StereoIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  struct TrackedPoint {
    PointId id = 0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();  ///< in coordinates_
    Eigen::MatrixXd B;                               ///< 3 x G regression on the global error
    Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
    bool updated = false;  ///< has had a Kalman update
  };
  struct PointInnovation;  // defined in src/core/filter/calibration_filter_internal.h
  struct Prediction;       // defined in src/core/filter/calibration_filter_internal.h

  std::string checkMotion(const MotionIncrement& motion) const;
  /// The inverse depth (1/m) below which a point is placed, where a position is needed (its
  /// process noise, points()): half that of the farthest new point.
  double minInverseDepth() const { return 0.5 / config_.max_point_depth; }
  /// The length a stored point is measured in (FilterConfig::baseline_scaled_points): the
  /// baseline |t_r| of @p T_caml_camr, or 1 (metres) for metric points.
  double pointScale(const Eigen::Isometry3d& T_caml_camr) const {
    return config_.baseline_scaled_points != 0 ? T_caml_camr.translation().norm() : 1.0;
  }
  double pointScale() const { return pointScale(extrinsics_.T_caml_camr); }
  /// @throws std::invalid_argument unless @p covariance is finite, symmetric and PD.
  static void requireValidStartCovariance(const Matrix12d& covariance);
  /// The part of a start common to reset() and restartCalibration(): the calibration's mean
  /// becomes @p guess; points, monitors and streaks start over. The covariance is the caller's.
  void startCalibration(const StereoExtrinsics& guess);
  /// Size of the persistent global error: calibration (12) + odometry states + x_camr's
  /// drift rate.
  int persistentDim() const { return layout::kCalibrationDim + odometry_dim_ + drift_rate_dim_; }
  double stateSigma(int index) const {
    return index < 0 ? 0.0 : std::sqrt(std::max(covariance_(index, index), 0.0));
  }
  /// The start covariance: @p calibration and the odometry state's prior, uncorrelated.
  Eigen::MatrixXd startCovariance(const Matrix12d& calibration) const;
  /// The step's motion noise before motion_noise_factors_: the odometry's own covariance of
  /// the increment when it gives one, else the configured model.
  Matrix6d configuredMotionNoise(const MotionIncrement& motion) const;
  /// The step's vehicle motion at the current odometry states, and its derivative (boxPlus
  /// tangent) with respect to them (6 x odometry_dim_).
  void motionModel(const MotionIncrement& motion, Eigen::Isometry3d* corrected,
                   Eigen::MatrixXd* jacobian) const;
  /// The step is worth repeating linearised at the corrected motion
  /// (FilterConfig::motion_relinearizations): the vehicle is slower than 2 m/s.
  bool wantsMotionRelinearized(const MotionIncrement& motion) const;
  /// One predict + update linearised at `motion` with the given prior mean of the motion
  /// error; a non-final pass only estimates the motion error. @p detect (may be null) sees
  /// the gate before the update. False: a block was re-opened (the step is complete then).
  bool runPass(const MotionIncrement& motion, const Vector6d& prior_motion_error,
               const std::vector<PointMeasurement>& measurements, bool final_pass,
               const ChangeDetector* detect, StepReport* report, Vector6d* motion_error);
  /// Drift, motion-error augmentation and point prediction; returns the global covariance
  /// (12, or 18 with the step's motion error) and marks points that could not be predicted.
  /// The prediction (drift, points) from the current state; remember: keep it in
  /// last_prediction_ for a later predict() from the same state with the same motion.
  Eigen::MatrixXd predict(const MotionIncrement& motion, std::vector<bool>* failed,
                          bool remember = false);
  Eigen::MatrixXd predictAnew(const MotionIncrement& motion, std::vector<bool>* failed);
  /// remember: keep the point's UT in last_prediction_ for the step (predictObservations).
  bool linearizeMeasurement(size_t index, const Eigen::MatrixXd& P, const Eigen::Vector4d& z,
                            const Eigen::Vector4d& variance, PointInnovation* innovation,
                            bool remember = false) const;
  void applyCalibrationDrift(double dt);
  void predictPoints(const MotionIncrement& motion, const Eigen::MatrixXd& P_global,
                     std::vector<bool>* failed);
  void marginalizeMotionError(const Eigen::MatrixXd& P_global);
  /// Applies a change detector's verdict inside a step: x_caml's turn, the block widened,
  /// every point dropped into report->lost.
  void applyReopening(const Reopening& reopening, StepReport* report);
  /// Widens the block's variances to at least @p sigma^2 (per component) and decorrelates it.
  void widenBlock(JumpBlock block, const Vector6d& sigma);
  void removeIndices(const std::vector<bool>& remove);
  bool repairCovariance();
  void rebuildIndex();

  FilterConfig config_;
  /// The odometry states in the global error after the calibration (state_layout.h
  /// kOdometry): how many, and where each is (-1: not estimated).
  int odometry_dim_ = 0;
  int time_offset_index_ = -1;
  int velocity_bias_index_ = -1;  ///< first of velocity_bias_axes_.size()
  /// The vehicle axes (0 x forward, 1 y, 2 z) whose velocity error is a state, in order.
  std::vector<int> velocity_bias_axes_;
  double time_offset_ = 0.0;  ///< s, camera clock minus odometry clock
  Eigen::Vector3d velocity_bias_ = Eigen::Vector3d::Zero();  ///< m/s, vehicle axes
  /// x_camr's rotation drift rate (FilterConfig::camr_rotation_drift_rate_sigma): 3 states
  /// after the odometry's, or none.
  int drift_rate_dim_ = 0;
  int drift_rate_index_ = -1;
  Eigen::Vector3d drift_rate_ = Eigen::Vector3d::Zero();  ///< rad/s, tangent of x_camr
  /// The last accepted motion increments since the last reset, oldest first, at most
  /// kTwistTrendIncrements (twistsAtEnds).
  std::vector<MotionIncrement> previous_motions_;
  MotionExcitation excitation_;
  /// s of accepted motion since each block (x_caml, x_camr) was started or widened
  /// (canReopen).
  std::array<double, 2> time_since_opened_ = {0.0, 0.0};
  /// Starts so far (startCalibration) and re-openings (reopen, applyReopening).
  int starts_ = 0;
  int reopenings_ = 0;
  /// Factors on the calibration's random walk (setDriftInflation).
  DriftInflation drift_inflation_;
  std::array<double, 2> motion_noise_factors_ = {1.0, 1.0};
  PointCoordinates coordinates_;  ///< how TrackedPoint::mean stores a point
  UnscentedParameters ut_;
  StereoIntrinsics intrinsics_;
  StereoExtrinsics extrinsics_;
  /// Covariance of the persistent global error [calibration (12), odometry states, x_camr's
  /// drift rate].
  Eigen::MatrixXd covariance_;
  std::vector<TrackedPoint> points_;
  std::unordered_map<PointId, size_t> index_;
  /// The last predictObservations' prediction: the step that follows, with the same motion
  /// from the same state, reuses it instead of repeating the per-point UTs (so neither
  /// predictObservations nor step may run concurrently on one filter).
  mutable std::shared_ptr<const Prediction> last_prediction_;
  /// The final pass's scores of this step, for the monitor (has_scores_: an update ran).
  UpdateScores scores_;
  bool has_scores_ = false;
  MotionNoiseEvidence motion_evidence_;
  bool has_motion_evidence_ = false;
};

}  // namespace osc
