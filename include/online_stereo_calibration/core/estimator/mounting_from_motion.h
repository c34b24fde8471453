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
  /// Forgets the previous frame (the next one starts a new pair); the pairs are kept.
  void forgetFrame() { previous_.clear(); }
  /// Forgets everything.
  void clear();

  /// The hand-eye solution of the pairs so far.
  HandEyeRotationResult solve() const { return solver_.solve(); }
  const HandEyeRotation& solver() const { return solver_; }

 private:
  CameraModel left_;
  CameraMotionConfig motion_config_;
  HandEyeRotation solver_;
  /// Normalised undistorted left coordinates of the previous frame's observations, by id.
  std::unordered_map<PointId, Eigen::Vector2d> previous_;
};

}  // namespace osc
