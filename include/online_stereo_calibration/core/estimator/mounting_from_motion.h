/// @file mounting_from_motion.h
/// @brief The left camera's mounting rotation (x_caml's rotation, R_veh_caml) from the
/// vehicle's and the camera's motion alone, frame by frame: the estimator's hand-eye start
/// (issue 14), for a guess that is far off (a camera mounted backwards or sideways).
///
/// Each frame the left pixels of the ids seen in the previous frame too give the camera's
/// motion (camera_motion.h); with the odometry's increment over the same interval it makes a
/// rotation pair and a direction pair for HandEyeRotation (hand_eye_rotation.h).
#pragma once

#include <unordered_map>
#include <vector>

#include "online_stereo_calibration/core/estimator/camera_motion.h"
#include "online_stereo_calibration/core/estimator/hand_eye_rotation.h"
#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"

namespace osc {

/// A restart of x_caml's rotation that the motion asks for.
struct MountingRestart {
  Eigen::Matrix3d R_veh_caml = Eigen::Matrix3d::Identity();  ///< the hand-eye rotation
  /// Covariance (rad^2) of its tangent error (filter's convention, pose.h boxPlus), every
  /// axis at least min_restart_sigma.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double distance = 0.0;  ///< Mahalanobis distance to the filter's rotation (3 dof)
  HandEyeRotationResult hand_eye;
};

/// Collects the motion pairs of a drive for the hand-eye rotation of the left camera.
class MountingFromMotion {
 public:
  /// @param left the left camera (its pixels are undistorted with it).
  MountingFromMotion(const CameraModel& left, const HandEyeRotationConfig& config);

  /// One frame: @p motion is the vehicle's motion since the previous frame, usable only if
  /// @p motion_usable (false for the first frame, after a tracking reset or a rejected
  /// motion). Returns the fit of the camera motion (valid false if none was made).
  CameraMotion addFrame(const MotionIncrement& motion, bool motion_usable,
                        const std::vector<StereoObservation>& observations);
  /// The same from correspondences found otherwise (left_motion_matches.h, when the ids do
  /// not persist): normalised coordinates of the same points in the previous and the current
  /// left image, @p motion the vehicle's over the same interval.
  CameraMotion addMatches(const MotionIncrement& motion,
                          const std::vector<Eigen::Vector2d>& previous,
                          const std::vector<Eigen::Vector2d>& current);
  /// The last addFrame had a usable motion, and its ids gave a pair.
  bool lastMotionUsable() const { return last_motion_usable_; }
  bool lastFramePaired() const { return last_frame_paired_; }
  /// Forgets the previous frame (the next one starts a new pair); the pairs are kept.
  void forgetFrame() { previous_.clear(); }
  /// Forgets everything and starts collecting again.
  void clear();

  /// Once the hand-eye rotation is determined (done() from then on): true if the filter's
  /// rotation R_filter (with its tangent covariance P_filter, rad^2) is farther from it than
  /// @p restart_distance (Mahalanobis, both covariances), with the restart in @p restart.
  /// Its covariance is the hand-eye's with every axis widened to at least
  /// @p min_restart_sigma (rad). False while undetermined or when they agree.
  bool checkFilter(const Eigen::Matrix3d& R_filter, const Eigen::Matrix3d& P_filter,
                   double restart_distance, double min_restart_sigma, MountingRestart* restart);
  /// The rotation was determined (and compared with the filter): collecting has ended.
  bool done() const { return done_; }

  /// The hand-eye solution of the pairs so far.
  HandEyeRotationResult solve() const { return solver_.solve(); }
  const HandEyeRotation& solver() const { return solver_; }

 private:
  CameraModel left_;
  CameraMotionConfig motion_config_;
  HandEyeRotation solver_;
  bool done_ = false;
  bool last_motion_usable_ = false, last_frame_paired_ = false;
  int pairs_at_last_solve_ = -1;
  /// Normalised undistorted left coordinates of the previous frame's observations, by id.
  std::unordered_map<PointId, Eigen::Vector2d> previous_;
};

}  // namespace osc
