#include "online_stereo_calibration/core/estimator/jump_test.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// chi-square(2) at 99.9 %: the left image's share of a stereo innovation.
constexpr double kLeftGate = 13.82;

}  // namespace

JumpTestOptions JumpTestOptions::from(const FilterConfig& config) {
  JumpTestOptions o;
  o.rejected_fraction = config.jump_rejected_fraction;
  o.min_points = config.jump_min_points;
  o.sustained_rejected_fraction = config.jump_sustained_rejected_fraction;
  o.sustained_frames = config.jump_sustained_frames;
  o.settle_time = config.jump_settle_time;
  o.rotation_sigma = config.jump_rotation_sigma;
  o.translation_sigma = config.jump_translation_sigma;
  o.fit_rotation_sigma = config.jump_fit_rotation_sigma;
  return o;
}

Reopening JumpTest::decide(const GateOutcome& gate, const CalibrationFilter& filter) {
  Reopening reopening;
  if (filter.starts() != last_start_) {
    last_start_ = filter.starts();
    streak_ = 0;
  }
  const int tested = static_cast<int>(gate.points.size());
  int rejected = 0, left_failures = 0;
  for (const GatedPoint& point : gate.points) {
    if (!point.gated_out) continue;
    ++rejected;
    if (point.nis_left > kLeftGate) ++left_failures;
  }
  // The left image does not see x_camr: if it fails too, x_caml moved (via eq. 8).
  const JumpBlock suspect =
      2 * left_failures >= rejected ? JumpBlock::kVehicleToLeft : JumpBlock::kLeftToRight;
  const bool enough_tested = tested >= options_.min_points;
  const bool partly = enough_tested && rejected >= options_.sustained_rejected_fraction * tested;
  streak_ = partly ? streak_ + 1 : 0;
  // Not while the suspect block is still settling: a start-up transient gates out many
  // points for some frames too (default campaign run 180 re-opened x_camr at frame 32).
  const bool sustained = options_.sustained_frames > 0 && streak_ >= options_.sustained_frames &&
                         filter.timeSinceOpened(suspect) >= options_.settle_time;
  const bool at_once = rejected >= options_.rejected_fraction * tested;
  if (!enough_tested || !(at_once || sustained) || !filter.canReopen(suspect)) return reopening;
  streak_ = 0;
  reopening.block = suspect;
  reopening.message = "sudden calibration change detected";
  // Only a jump found at once has all its tracked points measured across it; after a
  // sustained test most were initialised after it.
  const bool fitted = at_once && suspect == JumpBlock::kVehicleToLeft &&
                      fitLeftCameraTurn(gate, filter.intrinsics(), &reopening);
  if (!fitted)
    reopening.sigma = uniformBlockSigmas(options_.translation_sigma, options_.rotation_sigma);
  return reopening;
}

bool JumpTest::fitLeftCameraTurn(const GateOutcome& gate, const StereoIntrinsics& intrinsics,
                                 Reopening* reopening) const {
  if (!(options_.fit_rotation_sigma > 0.0)) return false;
  // The points are stored in the left optical frame, so their predictions carry the old
  // mounting: a camera turned by Q (R_veh_caml -> R_veh_caml Q) sees them at Q^T times
  // their predicted bearings.
  const Eigen::Matrix3d K_inverse = intrinsics.K_left.inverse();
  std::vector<Eigen::Vector3d> predicted, measured;
  for (const GatedPoint& point : gate.points) {
    predicted.push_back(K_inverse * point.predicted_left.homogeneous());
    measured.push_back(K_inverse * point.measured_left.homogeneous());
  }
  // Trimmed beyond 3 median angles, but never below ~5 pixels' worth of angle.
  const double min_trim_angle = 5.0 / intrinsics.K_left(0, 0);
  BearingRotationFit fit;
  if (!fitBearingRotation(predicted, measured, min_trim_angle, options_.min_points, &fit)) {
    return false;
  }
  // The turn must explain the points to their own predicted accuracy: a filter that is
  // merely off (its points initialised with a wrong mounting after a stretch without
  // points) gates many out at once too, and no single turn fits those.
  int explained = 0;
  for (size_t i = 0; i < gate.points.size(); ++i) {
    const GatedPoint& point = gate.points[i];
    const Eigen::Vector2d turned_pixel =
        (intrinsics.K_left * fit.rotation * predicted[i]).hnormalized();
    const Eigen::Vector2d r = point.measured_left - turned_pixel;
    if (r.dot(point.S_left.llt().solve(r)) <= kLeftGate) ++explained;
  }
  if (explained < options_.rejected_fraction * static_cast<double>(gate.points.size())) {
    return false;
  }
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Matrix3d Q_body = R_bo * fit.rotation.transpose() * R_bo.transpose();
  const Eigen::Vector3d turned = logSO3(Q_body);  // dtheta of x_caml (pose.h boxPlus)
  // Each axis is re-opened by what it turned, at least the floor: those that did not turn
  // keep nearly what they knew (a yaw step of a sideways camera re-opened to 10 deg on every
  // axis left pitch_l, told only by turns, 3 sigma off at sigma 1 deg; default campaign run
  // 144).
  Vector6d sigma;
  sigma.head<3>().setConstant(options_.translation_sigma);
  for (int k = 0; k < 3; ++k) {
    sigma(3 + k) = std::min(options_.rotation_sigma,
                            std::max(options_.fit_rotation_sigma, std::abs(turned(k))));
  }
  reopening->sigma = sigma;
  reopening->turned = true;
  reopening->turn = Q_body;
  std::ostringstream message;
  message << " (x_caml: its rotation fitted to " << fit.inliers << " of " << gate.points.size()
          << " points, explaining " << explained << ", turned it by "
          << turned.norm() * 180.0 / M_PI << " deg, rms " << fit.rms_angle * 180.0 / M_PI
          << " deg; re-opened to 1 sigma " << sigma.tail<3>().transpose() * 180.0 / M_PI
          << " deg about its x/y/z)";
  reopening->message += message.str();
  return true;
}

}  // namespace osc
