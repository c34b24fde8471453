/// @file stereo_calibration_estimator.h
/// @brief The facade every front end calls (simulators, the offline evaluator, the ROS
/// nodelet): raw stereo observations + measured motion in, calibration out.
///
/// It converts raw pixels to the filter's undistorted measurements with the camera models,
/// routes tracked points to the filter's update and unknown ones to point initialisation,
/// and keeps the bookkeeping of one image pair at a time.
#pragma once

#include <array>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/baseline_restart.h"
#include "online_stereo_calibration/core/estimator/consistency_monitor.h"
#include "online_stereo_calibration/core/estimator/epipolar_consistency.h"
#include "online_stereo_calibration/core/estimator/frame_event.h"
#include "online_stereo_calibration/core/estimator/jump_test.h"
#include "online_stereo_calibration/core/estimator/left_camera_gap_check.h"
#include "online_stereo_calibration/core/estimator/mounting_from_motion.h"
#include "online_stereo_calibration/core/estimator/odometry_noise_matcher.h"
#include "online_stereo_calibration/core/estimator/restart_from_estimate.h"
#include "online_stereo_calibration/core/estimator/right_camera_score_test.h"
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
  /// What the odometry noise matcher learned: factors on the configured motion noise.
  OdometryNoiseStatus odometry_noise;
  /// The camera-odometry time offset (CalibrationFilter::timeOffset): camera clock minus
  /// odometry clock (s; FilterConfig::initial_time_offset), and its 1 sigma (0 = not
  /// estimated).
  double time_offset = 0.0;
  double time_offset_sigma = 0.0;
  /// The rate at which x_camr's rotation drifts (CalibrationFilter::camrDriftRate; rad/s,
  /// boxPlus tangent) and its 1 sigmas (zero = not estimated).
  Eigen::Vector3d camr_drift_rate = Eigen::Vector3d::Zero();
  Eigen::Vector3d camr_drift_rate_sigma = Eigen::Vector3d::Zero();
  /// The part of parameter_covariance (and of tangent_covariance) that the odometry's scale
  /// uncertainty adds (FilterConfig::odometry_scale_sigma; zero when 0): convergence.h does
  /// not wait for it.
  Matrix12d odometry_scale_covariance = Matrix12d::Zero();

  /// 1-sigma of each parameter (sqrt of the covariance diagonal).
  Vector12d sigmas() const { return parameter_covariance.diagonal().cwiseMax(0.0).cwiseSqrt(); }
};

/// What happened to one image pair.
struct FrameReport {
  StepReport step;  ///< the filter step (empty for the first pair)
  /// The consistency monitor after the step (per-block window statistics, bounds, the
  /// drift-noise factors it set; consistency_monitor.h).
  ConsistencyStatus consistency;
  /// What the components did in this frame and what they found wrong, one line each, in
  /// order (frame_event.h): re-openings, restarts, widenings, a rejected motion, a baseline
  /// guess no point triangulates with, ...
  FrameEvents events;
  int new_points = 0;            ///< points initialised from this pair
  int rejected_new_points = 0;   ///< candidate points that did not triangulate in range
  int invalid_observations = 0;  ///< non-finite pixels or sigmas
  /// Points no longer in the filter (lost, outliers, reset): a tracker should forget them.
  std::vector<PointId> dropped;
  /// Fewer stereo pairs (tracked and new) than FilterConfig::min_points_to_update: the
  /// calibration was predicted, not updated, and the tracked points start afresh (the
  /// event kTooFewPoints is given in the first such pair of a stretch).
  bool too_few_points = false;

  bool has(FrameEvent kind) const { return events.has(kind); }
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
  /// re-opened to at least `rotation_sigma` (rad) and every point is forgotten. Its translation
  /// is kept (a knock turns a camera). Returns the forgotten points.
  std::vector<PointId> reopenRightCameraRotation(double rotation_sigma);
  /// x_camr re-seeded from a whole-image stereo fit (CalibrationPipeline at a start or after
  /// a re-opening, FilterConfig::stereo_fit_start): its mean becomes @p T_caml_camr and its tangent
  /// covariance block @p covariance (m, rad; [dt, dtheta] as the filter's), uncorrelated with
  /// x_caml, which keeps its estimate and covariance. At a start the guess takes the same
  /// x_camr (a later hand-eye restart keeps it); after a re-opening it does not. Every point is
  /// forgotten and the odometry states (the time offset) start from their priors. Re-linearised
  /// (restart_from_estimate.h) as after a start if @p start, else as after a re-opening of x_camr.
  /// Returns the forgotten points.
  std::vector<PointId> reseedRightCamera(const Eigen::Isometry3d& T_caml_camr,
                                         const Matrix6d& covariance, bool start);
  /// Starts over from a new guess with the config's initial uncertainty.
  void reset(const StereoExtrinsics& guess);
  /// Starts over from a saved calibration with its covariance (tangent, see filter) as
  /// estimate() reports it: estimate() right after gives it back, unless it is sharper than
  /// the odometry's scale allows (FilterConfig::odometry_scale_sigma; e.g. sigmas only), in
  /// which case it comes back widened by the scale.
  void reset(const StereoExtrinsics& guess, const Matrix12d& tangent_covariance);

  CalibrationEstimate estimate() const;
  /// s: read the odometry for the next pair at the image stamps minus this and say so in
  /// MotionIncrement::time_shift. It is the current estimate of the camera-odometry time
  /// offset (FilterConfig::read_odometry_at_offset; else 0), so that the filter's
  /// first-order offset correction (process_model.h correctedMotion), which errs on a jerky
  /// rig, covers only the estimate's error.
  double odometryTimeShift() const {
    return config_.read_odometry_at_offset != 0 ? filter_.timeOffset() : 0.0;
  }
  const CalibrationFilter& filter() const { return filter_; }
  const CameraModel& leftCamera() const { return left_; }
  const CameraModel& rightCamera() const { return right_; }
  /// The hand-eye start still collects and the last processFrame's ids gave it no pair (at
  /// image level with x_caml far off no track survives from one pair to the next): a caller
  /// with the images may give it the left image's own matches (addLeftCameraMatches).
  bool wantsLeftCameraMatches() const;
  /// Correspondences of the previous and the last processed pair's left images (normalised
  /// coordinates, left_motion_matches.h) for the hand-eye start, with the motion given to that
  /// processFrame. Ignored unless wantsLeftCameraMatches().
  void addLeftCameraMatches(const MotionIncrement& motion,
                            const std::vector<Eigen::Vector2d>& previous,
                            const std::vector<Eigen::Vector2d>& current);
  /// The same points in the previous and the next processFrame's pair (previous, current;
  /// raw pixels, ids ignored): for the baseline's length from motion
  /// (FilterConfig::baseline_from_motion) from a front end that does not track the pairs the
  /// filter refused (CalibrationPipeline matches them by their left descriptors). Without
  /// them, the candidates seen with the same id in both pairs are linked.
  void linkStereoMatches(const std::vector<std::pair<StereoObservation, StereoObservation>>& links);
  /// The baseline's length from motion wants linkStereoMatches for the next pair: no point
  /// could be initialised in the last one.
  bool wantsStereoLinks() const { return baseline_restart_.wantsLinks(); }
  /// The next pair is to be linked to the same earlier pair as this one (the camera has not
  /// moved enough since it: BaselineRestart::keepsReference), not to this one.
  bool keepsStereoLinkReference() const { return baseline_restart_.keepsReference(); }
  /// The hand-eye start is still collecting (on, rotation not yet determined).
  bool handEyeActive() const { return config_.hand_eye_start != 0 && !mounting_.done(); }
  /// The hand-eye start's pairs and solver (FilterConfig::hand_eye_start).
  const MountingFromMotion& mountingFromMotion() const { return mounting_; }

 private:
  bool toMeasurement(const StereoObservation& observation, PointMeasurement* measurement) const;
  /// The linearisation guard's restart (restart_from_estimate.h) after an accepted step:
  /// every point dropped into report->dropped, the event FrameEvent::kRelinearized.
  /// True if it restarted.
  bool restartIfLinearizedFarOff(FrameReport* report);
  /// The gap check (left_camera_gap_check.h) after an accepted step without a jump: x_caml
  /// re-opened (every point dropped into report->dropped,
  /// FrameEvent::kLeftCameraReopenedAfterGap) and anchored. True if it did.
  bool reopenLeftCameraAfterGap(const MotionIncrement& motion, FrameReport* report);
  /// Counts the pairs whose @p tracked points were all measured and none predictable, and
  /// warns (FrameEvent::kNoPointMeasurable) at the kUnmeasurablePairsToWarn-th in a row.
  void warnIfNoPointMeasurable(const std::vector<PointMeasurement>& tracked, FrameReport* report);
  /// What a reset forgets besides the filter: the evidence on the baseline, the knock,
  /// few-points and unmeasurable streaks, the hand-eye pairs, the unobserved stretch.
  void forgetDriveEvidence();
  /// The hand-eye start (mounting_from_motion.h): feeds the frame's motion pair; once the
  /// rotation is determined and far from x_caml's, starts the filter afresh from the guess
  /// with that rotation for x_caml's (its translation sigma at least
  /// hand_eye_restart_translation_sigma). True if it did (every point dropped).
  bool restartFromMotion(const MotionIncrement& motion,
                         const std::vector<StereoObservation>& observations, FrameReport* report);

  /// The consistency monitor follows the filter: a start since the last call resets it, a
  /// re-opening empties its window. Called after every call that may start or re-open.
  void followFilter();
  /// The monitor's drift-noise factors onto the filter (after every change of the monitor).
  void setFilterDriftInflation();
  /// The odometry noise matcher learns from the step's update; its factors onto the filter,
  /// and FrameEvent::kOdometryNoiseLearned when the noise is raised or set back.
  void learnOdometryNoise(const MotionIncrement& motion, FrameReport* report);
  /// While no point can be initialised: BaselineRestart's pair, and x_camr re-seeded at the
  /// length from motion when it proposes it (FilterConfig::baseline_from_motion).
  void learnBaselineLength(const MotionIncrement& motion, bool motion_links_pairs,
                           const std::vector<PointMeasurement>& candidates, FrameReport* report);
  /// Tests this pair's stereo pairs (tracked and new) against x_camr's epipolar lines
  /// (epipolar_consistency.h) and, after FilterConfig::epipolar_knock_pairs contradicting
  /// pairs in a row, re-opens x_camr's rotation (reopenRightCameraRotation): the tracked
  /// points then join the candidates. True if it did.
  bool reopenIfOffEpipolarLines(std::vector<PointMeasurement>* tracked,
                                std::vector<PointMeasurement>* candidates, FrameReport* report);

  FilterConfig config_;
  CameraModel left_;
  CameraModel right_;
  CalibrationFilter filter_;
  bool has_previous_frame_ = false;
  /// The last pair had too few stereo pairs to update (FrameReport::too_few_points).
  bool held_for_few_points_ = false;
  /// Pairs in a row whose tracked points were all measured and none predictable
  /// (FrameEvent::kNoPointMeasurable).
  int unmeasurable_pairs_ = 0;
  /// Linearisation guard: the restart from the estimate after a start or re-opening far off.
  RestartFromEstimate restart_;
  /// Change detection at the filter's gate: many points gated out, a block jumped.
  JumpTest jump_test_;
  /// Change detection, x_camr: its rotation widened on the evidence of the updates' score.
  RightCameraScoreTest score_test_;
  /// Change detection, x_caml: tested when points come back after a stretch without any.
  LeftCameraGapCheck gap_check_;
  /// Change detection, x_camr: its epipolar lines tested with every image pair.
  EpipolarKnockTest knock_test_;
  /// The last start's guess and its tangent covariance (restartFromMotion starts from them).
  StereoExtrinsics guess_;
  Eigen::MatrixXd guess_covariance_;
  MountingFromMotion mounting_;
  /// Start: the baseline's length from motion while no point could be initialised.
  BaselineRestart baseline_restart_;
  /// Per-block score test of the updates; scales the filter's random walk (eq. 10-13) per
  /// block. Its window ends with each start and re-opening of the filter (followFilter).
  ConsistencyMonitor monitor_;
  int monitor_starts_ = 0;      ///< CalibrationFilter::starts() the monitor has followed
  int monitor_reopenings_ = 0;  ///< CalibrationFilter::reopenings() it has followed
  /// Odometry model: the motion noise learned from the updates' innovations.
  OdometryNoiseMatcher noise_matcher_;
};

}  // namespace osc
