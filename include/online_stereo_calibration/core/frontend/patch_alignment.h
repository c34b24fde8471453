/// @file patch_alignment.h
/// @brief Sub-pixel alignment of a small image patch from one image into another
/// (inverse-compositional Lucas-Kanade, translation only, bias-compensated), with the checks
/// that tell a reliable alignment from an unreliable one: a well-conditioned patch (not a
/// straight edge: aperture problem), a small shift, a high normalised cross-correlation
/// (the two patches show the same surface: not an occluding edge).
#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace osc {

/// Settings of alignPatch. Units: px.
struct PatchAlignmentConfig {
  int half_size = 4;             ///< patch of (2 half_size + 1)^2 pixels
  int max_iterations = 10;       ///< Gauss-Newton steps
  double max_shift = 2.0;        ///< largest move from the initial guess
  double min_ncc = 0.9;          ///< least normalised cross-correlation after alignment
  double min_eigenvalue = 0.05;  ///< least smaller/larger eigenvalue ratio of the structure tensor
  /// How the template is sampled from `source`: the source offset (px) of one pixel step in
  /// `target` (column 0: a step along x, column 1: along y). The identity where the surface
  /// looks the same in both; 1/s I where `target` shows it s times larger (an approaching
  /// point); a distorted lens adds its local stretch at each pixel. Resampling the template
  /// keeps the translation-only alignment from drifting where the patch's look changes.
  /// Must be invertible.
  Eigen::Matrix2d template_sampling = Eigen::Matrix2d::Identity();
};

/// Result of alignPatch.
struct PatchAlignment {
  bool ok = false;                                     ///< passed every check
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< aligned position in `target` (px)
  double ncc = 0.0;                                    ///< normalised cross-correlation
  double eigen_ratio = 0.0;  ///< smaller / larger eigenvalue of the template's structure tensor
};

/// Aligns the patch of `source` (mono8) centred at `source_point` (px, sub-pixel allowed)
/// into `target` (mono8), starting at `guess`. Pixel centres at integer coordinates.
PatchAlignment alignPatch(const cv::Mat& source, const Eigen::Vector2d& source_point,
                          const cv::Mat& target, const Eigen::Vector2d& guess,
                          const PatchAlignmentConfig& config);

/// True if the aligned pair of patches straddles a depth discontinuity: some half of the
/// patch (left, right, upper, lower) that is textured along `direction` (unit, the epipolar
/// direction in the target) matches clearly better at a shift of >= 2 px along it (search
/// +-max_shift px) than at the aligned position, i.e. the two halves have different
/// disparities (an occluding contour: the pixel and the feature belong to different surfaces).
bool straddlesDepthDiscontinuity(const cv::Mat& source, const Eigen::Vector2d& source_point,
                                 const cv::Mat& target, const Eigen::Vector2d& target_point,
                                 const Eigen::Vector2d& direction, int half_size, int max_shift);

}  // namespace osc
