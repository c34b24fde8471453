/// @file epipolar_trend.h
/// @brief The frame's common distance of refined stereo pairs from their epipolar lines.
///
/// Refined (sub-pixel) pairs lie within a few hundredths of a pixel of their epipolar line
/// while x_camr is right, and a pair that slid along an outline lies off it by tenths: the
/// front end refuses pairs off their line by more than their own noise. A knocked right camera
/// moves every pair off its line at once (a small pitch_r by a constant, a small roll_r in
/// proportion to the column). The pairs are then measured against that common distance, so
/// that they still reach the filter, which sees the change, instead of all being refused and
/// the filter starved.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace osc {

/// One refined pair: its signed distance (px) from the nominal epipolar line and where its
/// right pixel lies (undistorted px).
struct EpipolarResidual {
  double distance = 0.0;
  Eigen::Vector2d right_pixel = Eigen::Vector2d::Zero();
};

/// distance ≈ c0 + c1 u, with u the right pixel's column about the image centre divided by
/// the focal length. (A tilted baseline would add a term in the disparity, and a roll_r one in
/// the row; in a road scene both correlate with the row and with each other, and fitting them
/// made the band wander by tenths of a pixel from frame to frame.)
class EpipolarTrend {
 public:
  /// No trend: every pair measured against its own line.
  EpipolarTrend() = default;
  /// Robust (Huber-weighted) least-squares fit to the residuals. No trend from fewer than
  /// kMinResiduals of them, nor when the fitted distance stays below kMinDistance px over
  /// them (that is the pairs' own noise, not a moved camera).
  static EpipolarTrend fit(const std::vector<EpipolarResidual>& residuals, double center_column,
                           double focal);

  /// The common distance (px) expected for a pair at this right pixel.
  double at(const Eigen::Vector2d& right_pixel) const;
  /// c0, c1 (px).
  const Eigen::Vector2d& coefficients() const { return coefficients_; }
  /// Root mean square of the fitted distance over the pairs it was fitted to (px; 0 for no
  /// trend): how far off its lines the frame's geometry is.
  double rms() const { return rms_; }

  static constexpr int kMinResiduals = 12;
  static constexpr double kMinDistance = 0.1;

 private:
  Eigen::Vector2d regressors(const Eigen::Vector2d& right_pixel) const;

  Eigen::Vector2d coefficients_ = Eigen::Vector2d::Zero();
  double rms_ = 0.0;
  double center_column_ = 0.0;
  double focal_ = 1.0;
};

}  // namespace osc
