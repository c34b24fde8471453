#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"

#include <cmath>

namespace osc {
namespace {

StereoIntrinsics stereoIntrinsics(const CameraModel& left, const CameraModel& right) {
  StereoIntrinsics k;
  k.K_left = left.K();
  k.K_right = right.K();
  return k;
}

}  // namespace

StereoCalibrationEstimator::StereoCalibrationEstimator(const FilterConfig& config,
                                                       const CameraIntrinsics& left,
                                                       const CameraIntrinsics& right,
                                                       const StereoExtrinsics& initial_guess)
    : config_(config),
      left_(left),
      right_(right),
      filter_(config, stereoIntrinsics(left_, right_)) {
  filter_.reset(initial_guess);
}

bool StereoCalibrationEstimator::toMeasurement(const StereoObservation& o,
                                               PointMeasurement* m) const {
  if (!o.left_pixel.allFinite() || !o.right_pixel.allFinite() || !std::isfinite(o.sigma_left) ||
      !std::isfinite(o.sigma_right)) {
    return false;
  }
  m->id = o.id;
  Eigen::Vector2d left_undistorted, right_undistorted;
  if (!left_.undistortPixel(o.left_pixel, &left_undistorted) ||
      !right_.undistortPixel(o.right_pixel, &right_undistorted)) {
    return false;  // beyond what the lens model maps to a ray (camera_model.h)
  }
  m->z << left_undistorted, right_undistorted;
  const double sl = o.sigma_left > 0.0 ? o.sigma_left : config_.pixel_noise;
  const double sr = o.sigma_right > 0.0 ? o.sigma_right : config_.pixel_noise;
  m->variance << sl * sl, sl * sl, sr * sr, sr * sr;
  return m->z.allFinite();
}

FrameReport StereoCalibrationEstimator::processFrame(
    const MotionIncrement& motion, const std::vector<StereoObservation>& observations) {
  FrameReport report;
  std::vector<PointMeasurement> tracked, candidates;
  for (const StereoObservation& o : observations) {
    PointMeasurement m;
    if (!toMeasurement(o, &m)) {
      ++report.invalid_observations;
      continue;
    }
    (filter_.hasPoint(o.id) ? tracked : candidates).push_back(m);
  }
  if (report.invalid_observations > 0) {
    report.warnings.push_back(
        std::to_string(report.invalid_observations) +
        " observation(s) ignored: NaN/Inf pixel or sigma, or a pixel no ray of the lens "
        "model reaches");
  }

  if (has_previous_frame_) {
    report.step = filter_.step(motion, tracked);
    if (!report.step.accepted) {
      // Without a usable motion the points cannot be predicted: start tracking afresh.
      report.motion_rejected = true;
      report.warnings.push_back("motion rejected: " + report.step.message);
      report.dropped = resetTracking();
      candidates.insert(candidates.end(), tracked.begin(), tracked.end());
    } else {
      report.dropped = report.step.lost;
      report.dropped.insert(report.dropped.end(), report.step.outliers.begin(),
                            report.step.outliers.end());
      if (report.step.jump != JumpBlock::kNone) {
        report.warnings.push_back(report.step.message);
        candidates.insert(candidates.end(), tracked.begin(), tracked.end());
      }
      if (report.step.covariance_repaired) {
        report.warnings.push_back(
            "calibration covariance was not positive definite and was repaired");
      }
    }
  }
  has_previous_frame_ = true;

  // New points after the correction, so they start from the best calibration (Sec. II-A).
  for (const PointMeasurement& m : candidates) {
    if (filter_.pointCount() >= static_cast<size_t>(config_.max_points)) break;
    if (filter_.hasPoint(m.id)) continue;
    if (filter_.addPoint(m)) {
      ++report.new_points;
    } else {
      ++report.rejected_new_points;
    }
  }
  // A point re-initialised from this pair (after a jump or a motion reset) is not dropped.
  std::vector<PointId> still_dropped;
  for (PointId id : report.dropped) {
    if (!filter_.hasPoint(id)) still_dropped.push_back(id);
  }
  report.dropped.swap(still_dropped);
  return report;
}

std::vector<PointId> StereoCalibrationEstimator::resetTracking() {
  std::vector<PointId> dropped;
  for (const PointEstimate& p : filter_.points()) dropped.push_back(p.id);
  for (PointId id : dropped) filter_.removePoint(id);
  has_previous_frame_ = false;
  return dropped;
}

std::vector<PointId> StereoCalibrationEstimator::reopenRightCameraRotation(double rotation_sigma) {
  has_previous_frame_ = false;
  return filter_.reopen(JumpBlock::kLeftToRight, 0.0, rotation_sigma);
}

void StereoCalibrationEstimator::reset(const StereoExtrinsics& guess) {
  filter_.reset(guess);
  has_previous_frame_ = false;
}

void StereoCalibrationEstimator::reset(const StereoExtrinsics& guess,
                                       const Matrix12d& tangent_covariance) {
  filter_.reset(guess, tangent_covariance);
  has_previous_frame_ = false;
}

CalibrationEstimate StereoCalibrationEstimator::estimate() const {
  CalibrationEstimate e;
  e.extrinsics = filter_.extrinsics();
  e.parameters = e.extrinsics.toParameters();
  e.tangent_covariance = filter_.covariance();
  e.parameter_covariance = filter_.parameterCovariance();
  e.tracked_points = filter_.pointCount();
  e.excitation = filter_.excitationGains();
  e.consistency = filter_.consistency();
  return e;
}

}  // namespace osc
