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

void CalibrationFilter::applyReopening(const Reopening& reopening, StepReport* report) {
  ++reopenings_;
  report->jump = reopening.block;
  report->message = reopening.message;
  if (reopening.turned) {
    extrinsics_.T_veh_caml.linear() = extrinsics_.T_veh_caml.linear() * reopening.turn;
  }
  report->jump_sigma = reopening.sigma;
  widenBlock(reopening.block, reopening.sigma);
  report->lost.reserve(points_.size());
  for (const TrackedPoint& point : points_) report->lost.push_back(point.id);
  report->outliers.clear();
  points_.clear();
  index_.clear();
  report->message += "; points re-initialised";
}

std::vector<PointId> CalibrationFilter::reopen(JumpBlock block, const Vector6d& sigma) {
  std::vector<PointId> removed;
  if (block == JumpBlock::kNone) return removed;
  for (const TrackedPoint& point : points_) removed.push_back(point.id);
  points_.clear();
  index_.clear();
  last_prediction_.reset();
  ++reopenings_;
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
