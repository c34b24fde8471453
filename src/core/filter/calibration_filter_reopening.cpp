#include "online_stereo_calibration/core/filter/calibration_filter.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/filter/update_tempering.h"
#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

#include "calibration_filter_internal.h"

namespace osc {

using namespace calibration_filter_internal;

void CalibrationFilter::widenRotationVariance(JumpBlock block, const Eigen::Vector3d& added) {
  if (block == JumpBlock::kNone) return;
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  covariance_.diagonal().segment<3>(first + layout::kRotation) += added;
}

bool CalibrationFilter::canReopen(JumpBlock block) const {
  // While a block is still as uncertain as a re-opened one (start-up), many gated-out points
  // are the ordinary transient, not a sudden change.
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  const Vector6d variance = covariance_.diagonal().segment<6>(first);
  if (!(variance.segment<3>(layout::kRotation).maxCoeff() <
        std::pow(config_.jump_rotation_sigma, 2)))
    return false;
  // A translation the motion cannot determine (zl on a flat road) never gets below the
  // re-opened sigma; once the block has had time to settle its rotation alone decides
  // (an x_caml yaw step on an urban drive went undetected for 150 frames).
  return variance.segment<3>(layout::kTranslation).maxCoeff() <
             std::pow(config_.jump_translation_sigma, 2) ||
         time_since_opened_[blockIndex(block)] >= config_.jump_settle_time;
}

void CalibrationFilter::reopenBlock(JumpBlock block, StepReport* report) {
  report->jump_sigma =
      uniformBlockSigmas(config_.jump_translation_sigma, config_.jump_rotation_sigma);
  widenBlock(block, report->jump_sigma);
}

bool CalibrationFilter::reopenLeftCameraAtFittedRotation(
    const std::vector<PointInnovation>& innovations, StepReport* report) {
  if (!(config_.jump_fit_rotation_sigma > 0.0)) return false;
  // The points are stored in the left optical frame, so their predictions carry the old
  // mounting: a camera turned by Q (R_veh_caml -> R_veh_caml Q) sees them at Q^T times
  // their predicted bearings.
  const Eigen::Matrix3d K_inverse = intrinsics_.K_left.inverse();
  std::vector<Eigen::Vector3d> predicted, measured;
  for (const PointInnovation& inn : innovations) {
    const Eigen::Vector2d left = inn.predicted.head<2>();
    predicted.push_back(K_inverse * left.homogeneous());
    measured.push_back(K_inverse * (left + inn.residual.head<2>()).homogeneous());
  }
  // Trimmed beyond 3 median angles, but never below ~5 pixels' worth of angle.
  const double min_trim_angle = 5.0 / intrinsics_.K_left(0, 0);
  BearingRotationFit fit;
  if (!fitBearingRotation(predicted, measured, min_trim_angle, config_.jump_min_points, &fit)) {
    return false;
  }
  // The turn must explain the points to their own predicted accuracy: a filter that is
  // merely off (its points initialised with a wrong mounting after a stretch without
  // points) gates many out at once too, and no single turn fits those.
  int explained = 0;
  for (size_t i = 0; i < innovations.size(); ++i) {
    const PointInnovation& inn = innovations[i];
    const Eigen::Vector2d turned_pixel =
        (intrinsics_.K_left * fit.rotation * predicted[i]).hnormalized();
    const Eigen::Vector2d r = inn.predicted.head<2>() + inn.residual.head<2>() - turned_pixel;
    if (r.dot(inn.S.topLeftCorner<2, 2>().llt().solve(r)) <= kLeftGate) ++explained;
  }
  if (explained < config_.jump_rejected_fraction * static_cast<double>(innovations.size())) {
    return false;
  }
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Matrix3d Q_body = R_bo * fit.rotation.transpose() * R_bo.transpose();
  const Eigen::Vector3d turned = logSO3(Q_body);  // dtheta of x_caml (pose.h boxPlus)
  extrinsics_.T_veh_caml.linear() = extrinsics_.T_veh_caml.linear() * Q_body;
  // Each axis is re-opened by what it turned, at least the floor: those that did not turn
  // keep nearly what they knew (a yaw step of a sideways camera re-opened to 10 deg on every
  // axis left pitch_l, told only by turns, 3 sigma off at sigma 1 deg; default campaign run
  // 144).
  Vector6d sigma;
  sigma.head<3>().setConstant(config_.jump_translation_sigma);
  for (int k = 0; k < 3; ++k) {
    sigma(3 + k) = std::min(config_.jump_rotation_sigma,
                            std::max(config_.jump_fit_rotation_sigma, std::abs(turned(k))));
  }
  report->jump_sigma = sigma;
  widenBlock(JumpBlock::kVehicleToLeft, sigma);
  std::ostringstream message;
  message << " (x_caml: its rotation fitted to " << fit.inliers << " of " << innovations.size()
          << " points, explaining " << explained << ", turned it by "
          << turned.norm() * 180.0 / M_PI << " deg, rms " << fit.rms_angle * 180.0 / M_PI
          << " deg; re-opened to 1 sigma " << sigma.tail<3>().transpose() * 180.0 / M_PI
          << " deg about its x/y/z)";
  report->message += message.str();
  return true;
}

std::vector<PointId> CalibrationFilter::reopen(JumpBlock block, const Vector6d& sigma) {
  std::vector<PointId> removed;
  if (block == JumpBlock::kNone) return removed;
  for (const TrackedPoint& point : points_) removed.push_back(point.id);
  points_.clear();
  index_.clear();
  last_prediction_.reset();
  monitor_.clearWindow();
  widenBlock(block, sigma);
  return removed;
}

void CalibrationFilter::widenBlock(JumpBlock block, const Vector6d& sigma) {
  if (block == JumpBlock::kNone) return;
  const int first = block == JumpBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  const Vector6d variance =
      covariance_.diagonal().segment<6>(first).cwiseMax(sigma.cwiseProduct(sigma));
  // Decorrelate the re-opened block from the rest: its old correlations no longer hold.
  covariance_.middleRows<6>(first).setZero();
  covariance_.middleCols<6>(first).setZero();
  covariance_.block<6, 6>(first, first) = variance.asDiagonal();
  time_since_opened_[blockIndex(block)] = 0.0;
}

}  // namespace osc
