/// @file live_rectification.h
/// @brief The stereo rectification that follows the live calibration (recomputed only when
/// the estimate moved the rectified images by more than a threshold), and the quality
/// figures of an estimate (rectification error of a frame's pairs, depth uncertainty).
#pragma once

#include <optional>
#include <vector>

#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/geometry/stereo_rectification.h"

namespace osc {

/// How good an estimate is for stereo, after one image pair.
struct CalibrationQuality {
  /// Median |v_left - v_right| (px) of the pair's stereo pairs rectified with the estimate;
  /// empty when the pair had none.
  std::optional<RectificationError> rectification_error;
  double depth_sigma_10m = 0.0;  ///< m, 1-sigma depth from the covariance, 10 m on the axis
  double depth_sigma_50m = 0.0;  ///< m, the same at 50 m
};

/// The rectification (CameraInfo R and P) of the current estimate. Not thread-safe.
class LiveRectification {
 public:
  /// @param update_px recompute when the rectified images would move by more (px, >= 0).
  /// @throws std::invalid_argument for an alpha outside [-1, 1], a negative size or update_px.
  LiveRectification(const RectificationSettings& settings, double update_px);

  /// Recomputes R and P if there are none yet, the cameras changed, or the estimate's
  /// left->right transform moved them by more than update_px (rectificationChangePx).
  /// Returns true if it recomputed. @throws std::invalid_argument as
  /// computeStereoRectification (the previous rectification is kept then).
  bool update(const CameraIntrinsics& left, const CameraIntrinsics& right,
              const StereoExtrinsics& estimate);

  /// The current rectification; empty before the first successful update().
  const std::optional<StereoRectification>& rectification() const { return rectification_; }

  /// Quality figures of @p estimate for the pairs of one image pair: the rectification error
  /// with R and P computed from exactly this estimate (not the possibly older published one)
  /// and depthSigmaOnAxis at 10 m and 50 m from its tangent covariance.
  /// @throws std::invalid_argument as computeStereoRectification / depthSigmaOnAxis.
  CalibrationQuality quality(const CameraIntrinsics& left, const CameraIntrinsics& right,
                             const std::vector<StereoObservation>& pairs,
                             const CalibrationEstimate& estimate) const;

  const RectificationSettings& settings() const { return settings_; }

 private:
  RectificationSettings settings_;
  double update_px_;
  std::optional<StereoRectification> rectification_;
  CameraIntrinsics left_, right_;  ///< the cameras rectification_ was made for
};

}  // namespace osc
