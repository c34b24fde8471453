/// @file baseline_from_motion.h
/// @brief The stereo baseline's length from the left camera's motion (issue 14: "the baseline
/// length comes from the guess with an honest prior and then from motion; a guess 50 % off
/// must converge").
///
/// When the baseline's prior is as wide as a good part of its guess (0.15 +- 0.1 m for a 0.3 m
/// rig), no new point passes the filter's depth check (CalibrationFilter::addPoint: some
/// sigma points have nearly no baseline), so the filter can never learn the length. Here the
/// length is measured without the filter: the same points seen in two consecutive stereo
/// pairs have
///  - an inverse depth from the left camera's motion at the odometry's scale (the motion's
///    rotation and direction from the left images themselves, estimateCameraMotion, so a
///    poor x_caml guess does not enter; its length from the odometry), rho_m in 1/m, and
///  - an inverse depth from the stereo pair with a baseline of unit length, rho_b,
/// and rho_b = L rho_m + c (1 + s^2): L is the baseline's length, c the disparity offset of an
/// x_camr rotation that is off about the axis across the baseline and the view (s: the
/// point's normalised coordinate along the baseline; c is that rotation in rad, first order).
/// Fitted by RANSAC per pair, the inliers' normal equations accumulated over the pairs.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/camera_motion.h"

namespace osc {

/// One point in two consecutive stereo pairs: undistorted normalised coordinates
/// [x_left, y_left, x_right, y_right] (x/z, y/z in each optical frame).
struct StereoLink {
  Eigen::Vector4d previous = Eigen::Vector4d::Zero();
  Eigen::Vector4d current = Eigen::Vector4d::Zero();
};

/// Thresholds of the length estimate.
struct BaselineFromMotionConfig {
  CameraMotionConfig motion;        ///< the left camera's motion fit (its focal length too)
  double pixel_noise = 0.5;         ///< px, of each normalised coordinate times the focal
  double min_translation = 0.05;    ///< m of left-camera motion per pair: below, no parallax
  int min_pair_inliers = 10;        ///< fewest points on the line in one pair to count it
  int min_pairs = 5;                ///< fewest pairs before an estimate is given
  int min_inliers = 30;             ///< fewest points over all pairs
  double max_relative_sigma = 0.1;  ///< sigma_L / L at most for an estimate
};

/// The length and how it was found.
struct BaselineLength {
  bool valid = false;
  double length = 0.0;  ///< m
  /// m, 1 sigma: the fit's (inflated by its reduced chi-square), at least the pairs' own
  /// lengths' spread / sqrt(pairs).
  double sigma = 0.0;
  /// c: the disparity offset of the stereo estimate (rad, withoutDisparityOffset) and its
  /// 1 sigma (inflated as sigma).
  double offset = 0.0, offset_sigma = 0.0;
  int pairs = 0;    ///< pairs that contributed
  int inliers = 0;  ///< points on the line, over those pairs
  std::string why;  ///< when not valid: why not yet
};

/// Signed inverse depth (1 / z along @p ray, ray = [x, y, 1] in the reference optical frame)
/// of a point seen at normalised @p other in a second camera with X_other = R X_ref + t,
/// in units of |t| if t is a unit vector. Least squares over both image coordinates; NaN if
/// the views have no parallax for it. @p sigma (optional): its 1 sigma for @p noise in each
/// normalised coordinate of both views (first order).
double inverseDepthFromTwoViews(const Eigen::Vector3d& ray, const Eigen::Vector2d& other,
                                const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double noise,
                                double* sigma = nullptr);

/// @p T_lopt_ropt with the right camera turned about its centre so that the disparity offset
/// @p offset (BaselineLength::offset, measured with it) vanishes: the rotation about the axis
/// across the baseline and the view, which one stereo pair hardly determines (it slides points
/// along their epipolar lines) and motion does.
Eigen::Isometry3d withoutDisparityOffset(const Eigen::Isometry3d& T_lopt_ropt, double offset);

/// Sums of the weighted least squares of rho_b = L rho_m + c k (k = 1 + s^2) over points
/// with weights w: normal = sum w [rho_m k]^T [rho_m k], right_side = sum w [rho_m k]^T rho_b,
/// weighted_y2 = sum w rho_b^2 (for the chi-square).
struct LineSums {
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d right_side = Eigen::Vector2d::Zero();
  double weighted_y2 = 0.0;
};

/// Accumulates pairs of consecutive stereo pairs until the length is known.
class BaselineFromMotion {
 public:
  explicit BaselineFromMotion(const BaselineFromMotionConfig& config) : config_(config) {}

  /// One pair's evidence. @p T_lopt_ropt: the current left->right estimate (its rotation and
  /// direction are used, not its length); @p camera_translation: the length (m) of the left
  /// camera's motion between the two pairs from the odometry. Returns false (and says why in
  /// lastWhy()) if the pair told nothing.
  bool addPair(const std::vector<StereoLink>& links, const Eigen::Isometry3d& T_lopt_ropt,
               double camera_translation);

  /// The length from the pairs so far (valid once config's thresholds are met).
  BaselineLength estimate() const;
  const std::string& lastWhy() const { return last_why_; }
  /// The last pair did not count because the camera moved too little (min_translation) or
  /// its motion showed too little parallax (CameraMotionConfig::min_parallax): a pair further
  /// away may count.
  bool lastLackedParallax() const { return last_lacked_parallax_; }
  void clear();

 private:
  BaselineFromMotionConfig config_;
  /// The weighted least-squares sums of the line over the inliers of every pair so far.
  LineSums sums_;
  int inliers_ = 0;
  std::vector<double> pair_lengths_;  ///< each pair's own length
  std::string last_why_;
  bool last_lacked_parallax_ = false;
};

}  // namespace osc
