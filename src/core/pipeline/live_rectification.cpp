#include "online_stereo_calibration/core/pipeline/live_rectification.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace osc {
namespace {

bool sameCamera(const CameraIntrinsics& a, const CameraIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && a.model == b.model && a.distortion == b.distortion;
}

}  // namespace

LiveRectification::LiveRectification(const RectificationSettings& settings, double update_px)
    : settings_(settings), update_px_(update_px) {
  if (!(settings.alpha >= -1.0 && settings.alpha <= 1.0)) {
    throw std::invalid_argument("rectification alpha " + std::to_string(settings.alpha) +
                                ": must be in [-1, 1]");
  }
  if (settings.width < 0 || settings.height < 0) {
    throw std::invalid_argument("rectification width/height must be >= 0");
  }
  if (!(update_px >= 0.0) || !std::isfinite(update_px)) {
    throw std::invalid_argument("rectification update threshold must be >= 0 px");
  }
}

bool LiveRectification::update(const CameraIntrinsics& left, const CameraIntrinsics& right,
                               const StereoExtrinsics& estimate) {
  const Eigen::Isometry3d T_lopt_ropt = estimate.leftToRightOptical();
  if (rectification_ && sameCamera(left, left_) && sameCamera(right, right_) &&
      rectificationChangePx(*rectification_, T_lopt_ropt) <= update_px_) {
    return false;
  }
  rectification_ = computeStereoRectification(left, right, T_lopt_ropt, settings_);
  left_ = left;
  right_ = right;
  return true;
}

CalibrationQuality LiveRectification::quality(const CameraIntrinsics& left,
                                              const CameraIntrinsics& right,
                                              const std::vector<StereoObservation>& pairs,
                                              const CalibrationEstimate& estimate) const {
  CalibrationQuality quality;
  const StereoRectification now =
      computeStereoRectification(left, right, estimate.extrinsics.leftToRightOptical(), settings_);
  quality.rectification_error =
      rectificationError(pairs, CameraModel(left), CameraModel(right), now);
  quality.depth_sigma_10m =
      depthSigmaOnAxis(estimate.extrinsics, estimate.tangent_covariance, 10.0);
  quality.depth_sigma_50m =
      depthSigmaOnAxis(estimate.extrinsics, estimate.tangent_covariance, 50.0);
  return quality;
}

}  // namespace osc
