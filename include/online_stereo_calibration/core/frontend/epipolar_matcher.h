/// @file epipolar_matcher.h
/// @brief Epipolar-guided stereo matching (seed eq. 5-6) with the current estimate of
/// x_camr and its uncertainty: candidates in a band around the epipolar line, on the side of
/// positive disparity, then descriptor threshold, ratio test and one-to-one.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// One left-right correspondence (indices into the two FeatureSets).
struct StereoMatch {
  int left = -1;
  int right = -1;
  double descriptor_distance = 0.0;  ///< normalised, see FrontEndConfig
  double line_distance = 0.0;        ///< signed distance (px) from the epipolar line
  double band = 0.0;                 ///< half-width (px) of the band it was accepted in
  /// The next best normalised distance seen from either keypoint (infinity if none).
  double second_distance = 0.0;
};

/// Matches left keypoints to right keypoints along their epipolar lines.
class EpipolarMatcher {
 public:
  /// Depths (m, along the left ray) bounding the search segment: from the image of the
  /// point at max_depth (infinity: the zero-disparity end) to that at min_depth, widened by
  /// the uncertainty of x_camr.
  EpipolarMatcher(const FrontEndConfig& config, double min_depth,
                  double max_depth = std::numeric_limits<double>::infinity());

  /// Sets the geometry of this frame: intrinsics, the current x_camr (T_caml_camr, body
  /// frames) and its 6x6 tangent covariance (the camr block of CalibrationFilter::covariance()).
  void setGeometry(const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                   const Eigen::Isometry3d& T_caml_camr, const Matrix6d& camr_covariance);

  /// Half-width (px) of the band for a left undistorted pixel and a right candidate: the
  /// 1-sigma line distance from x_camr's covariance (numerically through eq. 5-6) and the
  /// pixel noise of both images, times band_sigmas, clamped to [min_band, max_band].
  double bandHalfWidth(const Eigen::Vector2d& left, const Eigen::Vector2d& right) const;

  /// The epipolar line of a left undistorted pixel (eq. 6, normalised so that l.dot(x) is a
  /// distance in px) and the lines of the six sigma-perturbed x_camr.
  struct Lines {
    Eigen::Vector3d nominal;
    Eigen::Vector3d sigma[6];
  };
  Lines lines(const Eigen::Vector2d& left) const;
  /// bandHalfWidth with the left pixel's lines computed once.
  double bandHalfWidth(const Lines& lines, const Eigen::Vector2d& right) const;
  /// The band of a sub-pixel (refined) pair: `pixel_sigma` (px per image) in place of
  /// config.pixel_sigma and no min_band floor (that floor is for keypoints on the pixel grid;
  /// a refined pair off its line by more than its own noise and x_camr's uncertainty has
  /// slid, e.g. along an outline).
  double refinedBandHalfWidth(const Lines& lines, const Eigen::Vector2d& right,
                              double pixel_sigma) const;

  /// Matches in undistorted coordinates. Keypoints flagged in left_used / right_used (may be
  /// empty) take no part. A match passes the descriptor bound and Lowe's ratio test from
  /// both sides and is mutual (each keypoint the other's best), hence one-to-one. Sorted by
  /// left index.
  std::vector<StereoMatch> match(const FeatureSet& left, const FeatureSet& right,
                                 const std::vector<char>& left_used,
                                 const std::vector<char>& right_used) const;

  /// The fundamental matrix of the current estimate (eq. 5).
  const Eigen::Matrix3d& fundamental() const { return F_; }

 private:
  /// Variance (px^2) of a right pixel's distance to the line: 2 pixel_sigma^2 plus the
  /// spread of the six sigma-perturbed lines.
  double lineDistanceVariance(const Lines& lines, const Eigen::Vector2d& right,
                              double pixel_sigma) const;
  FrontEndConfig config_;
  double min_depth_;
  double max_depth_;
  Eigen::Matrix3d K_left_inv_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d K_right_ = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d T_ropt_lopt_ = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d F_ = Eigen::Matrix3d::Identity();
  /// Per tangent direction j of x_camr: F and T_ropt_lopt perturbed by sqrt(eigenvalue)
  /// along the j-th eigenvector of the covariance (so the spread is sum of squares).
  Eigen::Matrix3d F_sigma_[6];
  Eigen::Isometry3d T_sigma_[6];
};

}  // namespace osc
