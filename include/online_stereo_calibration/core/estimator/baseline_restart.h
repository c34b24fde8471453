/// @file baseline_restart.h
/// @brief Start, baseline from motion: while stereo pairs come but no point can be
/// initialised (the baseline guess far off), the baseline's length is measured from the left
/// camera's motion at the odometry's scale (baseline_from_motion.h), and x_camr's translation
/// is proposed for a restart at it (docs/design.md, "start").
///
/// Only a length the filter does not know is restarted: then its sigma points reach almost no
/// baseline and no point passes the depth check. With a length it knows, the points are kept
/// out by something else (x_caml or x_camr's rotation far off), which a restart of x_camr from
/// the current estimate would lock in.
#pragma once

#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/baseline_from_motion.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"

namespace osc {

/// x_camr re-seeded at the measured length (StereoCalibrationEstimator::reseedRightCamera).
struct BaselineReseed {
  bool reseed = false;
  Eigen::Isometry3d T_caml_camr = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  ///< x_camr's tangent block [dt, dtheta]
  std::string message;                     ///< the event's line
};

/// The evidence of the pairs since no point could be initialised (one per estimator).
class BaselineRestart {
 public:
  /// @p K_left, @p K_right: the cameras' matrices (the pairs' pixels are undistorted).
  BaselineRestart(const FilterConfig& config, const Eigen::Matrix3d& K_left,
                  const Eigen::Matrix3d& K_right);

  /// The same points in the previous and the next pair (undistorted; from a front end that
  /// matched them by descriptors). @p given: links were given, even if none could be used;
  /// then the candidates are not linked by id.
  void setLinks(std::vector<std::pair<PointMeasurement, PointMeasurement>> links, bool given);
  /// Links are wanted for the next pair: no point could be initialised in the last one.
  bool wantsLinks() const { return !previous_candidates_.empty(); }
  /// The next pair is linked to the same reference pair as this one was, not to this one:
  /// the left camera's motion since the reference had too little parallax to count
  /// (BaselineFromMotion::lastLackedParallax; a MAV at 20 Hz in a room moves 2-3 cm per pair,
  /// 0.6 px). The front end then keeps its reference pair's matches.
  bool keepsReference() const { return pairs_on_reference_ > 0; }
  /// Forgets every pair (the points could be initialised, or x_camr changed).
  void forget();
  /// The measurement so far, for the warning that no point could be initialised: the length
  /// (or why there is none yet) and why the last pair did not count, if it did not.
  std::string progress() const;

  /// One pair in which no point could be initialised: its candidates are linked to the
  /// reference pair's (the last pair's, or an earlier one while keepsReference(); by id, or
  /// the given links), the left camera's motion between them added, and,
  /// once the length is known well enough and the filter does not know it, the restart of
  /// x_camr's translation returned. @p motion_links_pairs: @p motion is the one since the
  /// last pair (not the first pair after a start or a reset).
  BaselineReseed afterPair(const MotionIncrement& motion, bool motion_links_pairs,
                           const std::vector<PointMeasurement>& candidates,
                           const CalibrationFilter& filter);

 private:
  Eigen::Matrix3d K_left_inverse_, K_right_inverse_;
  BaselineFromMotion measurement_;
  /// The reference pair's candidates in normalised coordinates [left (2), right (2)], by id.
  std::unordered_map<PointId, Eigen::Vector4d> previous_candidates_;
  /// The vehicle's motion from the reference pair to the last pair (T_ref_last).
  Eigen::Isometry3d since_reference_ = Eigen::Isometry3d::Identity();
  /// Pairs linked to the reference so far while its parallax was too small (0: the next pair
  /// is linked to the last one).
  int pairs_on_reference_ = 0;
  std::vector<std::pair<PointMeasurement, PointMeasurement>> given_links_;
  bool links_given_ = false;
};

/// @p T_caml_camr turned about its centre so that the disparity offset @p offset (rad,
/// BaselineLength::offset) vanishes (withoutDisparityOffset), in the body frames.
Eigen::Isometry3d turnedByDisparityOffset(const StereoExtrinsics& extrinsics, double offset);

}  // namespace osc
