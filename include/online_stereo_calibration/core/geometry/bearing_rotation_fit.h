/// @file bearing_rotation_fit.h
/// @brief The rotation that best takes one set of directions onto another (Wahba's problem,
/// solved by SVD as Kabsch does), with outliers trimmed.
///
/// Used after a detected jump of x_caml: the tracked points' predicted left bearings
/// (with the old mounting) against the measured ones give the camera's rotation relative
/// to the vehicle, so that only the directions that moved are re-opened.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace osc {

struct BearingRotationFit {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< to ~ rotation * from
  int inliers = 0;                                         ///< pairs kept by the trimming
  double rms_angle = 0.0;  ///< rad, of the inliers' angles between to and rotation * from
};

/// Fits R with to_i ~ R from_i (unit or not: the directions are normalised), then trims the
/// pairs whose angle exceeds max(@p min_trim_angle, 3 x the median angle) and refits, a few
/// times. False (and @p fit untouched) if fewer than @p min_inliers pairs (at least 3) are
/// kept or a direction is not finite and non-zero.
bool fitBearingRotation(const std::vector<Eigen::Vector3d>& from,
                        const std::vector<Eigen::Vector3d>& to, double min_trim_angle,
                        int min_inliers, BearingRotationFit* fit);

}  // namespace osc
