/// @file global_stereo_fit.h
/// @brief The left -> right rotation and baseline direction from one stereo pair alone,
/// without any calibration (issue 14): descriptors matched over the whole images (mutual
/// best, ratio test), the essential matrix by RANSAC on normalised undistorted points
/// (cv::findEssentialMat, five-point), and its decomposition (cv::recoverPose). Evidence
/// that the estimate of x_camr is wrong (a knocked right camera) needs such a fit: the mere
/// absence of epipolar-guided pairs is also what a texture-poor or dark view gives.
#pragma once

#include <string>

#include <Eigen/Core>

namespace osc {

class CameraModel;
struct FeatureSet;

/// The fit of one pair. Frames: optical (z forward, x right, y down).
struct GlobalStereoFit {
  bool valid = false;  ///< enough inliers for the rotation below to mean anything
  std::string why;     ///< why not valid (or a summary if valid)
  int matches = 0;     ///< mutual-best descriptor matches passing the ratio test
  int inliers = 0;     ///< RANSAC inliers of the essential matrix (cheirality included)
  /// Rotation of the right optical frame in the left optical frame (R of T_lopt_ropt), fitted
  /// with the baseline direction held at the caller's (see fitStereoGeometry).
  Eigen::Matrix3d R_lopt_ropt = Eigen::Matrix3d::Identity();
  /// Covariance (rad^2) of the rotation error, right-multiplied (R = R_fit * Exp(e)), from
  /// the inliers' spread about their epipolar lines (Gauss-Newton).
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Zero();
  /// The five-point solution's own baseline direction (unit, left optical frame): weakly
  /// determined by one pair (it trades off against the rotation), for information only.
  Eigen::Vector3d free_baseline_direction = Eigen::Vector3d::UnitX();
  /// RMS distance (px) of the inliers from their epipolar lines under R_lopt_ropt.
  double rms_px = 0.0;
  /// The baseline direction (unit, left optical frame) R_lopt_ropt goes with: the caller's
  /// if held (GlobalStereoFitConfig::baseline_direction_covariance zero), else the one
  /// refined together with the rotation under that prior.
  Eigen::Vector3d baseline_direction = Eigen::Vector3d::UnitX();
  /// With a direction prior only (else zero): covariance of baseline_direction's change
  /// (perpendicular to it, rank 2) and its cross-covariance with the rotation error (rows
  /// rotation, as rotation_covariance, which is then the rotation's marginal covariance).
  Eigen::Matrix3d baseline_direction_covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d rotation_direction_covariance = Eigen::Matrix3d::Zero();
};

/// Matching and RANSAC settings of fitStereoGeometry.
struct GlobalStereoFitConfig {
  double max_descriptor_distance = 0.25;  ///< normalised (FeatureSet::distance), in (0, 1]
  double ratio = 0.8;                     ///< Lowe's ratio: best < ratio * second best
  double ransac_threshold = 1.0;          ///< px, distance from the epipolar line
  int min_inliers = 30;                   ///< fewer: not valid
  /// Prior covariance (left optical frame; its part perpendicular to the direction is used)
  /// of the change of the baseline direction given to fitStereoGeometry. Zero (default): the
  /// direction is held there. Otherwise the rotation and the direction are refined together
  /// (maximum a posteriori: the inliers' Sampson distances, weighted by their own spread, and
  /// this prior), since one pair determines the rotation well only with the direction.
  Eigen::Matrix3d baseline_direction_covariance = Eigen::Matrix3d::Zero();
};

/// Fits the pair's epipolar geometry from its keypoints (as StereoFrontEnd detected them):
/// the five-point RANSAC selects the inliers, then the rotation is refined (Gauss-Newton on
/// their Sampson distances) with the baseline direction held at @p baseline_direction (unit,
/// left optical frame, e.g. the current estimate's). One pair cannot separate a rotation
/// from a turn of the baseline direction well (on EuRoC the free five-point solution is
/// 0.5-1 deg and 11-27 deg off), while a knock turns the camera, not its centre. With a prior
/// on the direction (GlobalStereoFitConfig::baseline_direction_covariance) both are refined
/// together instead, with their joint covariance.
/// Costs about one Hamming distance per left x right keypoint pair: call it only when
/// needed. Never throws for degenerate input; the result is then not valid.
GlobalStereoFit fitStereoGeometry(const FeatureSet& left, const FeatureSet& right,
                                  const CameraModel& left_camera, const CameraModel& right_camera,
                                  const Eigen::Vector3d& baseline_direction,
                                  const GlobalStereoFitConfig& config = GlobalStereoFitConfig());

/// Angle (rad) of the rotation between two rotation matrices: |log(Ra^T Rb)|.
double rotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace osc
