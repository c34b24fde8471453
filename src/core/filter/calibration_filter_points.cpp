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

bool CalibrationFilter::addPoint(const PointMeasurement& m) {
  if (hasPoint(m.id) || !m.z.allFinite() || !m.variance.allFinite() ||
      !(m.variance.minCoeff() > 0.0)) {
    return false;
  }
  // Scaled UT over [x_camr (6), left pixel noise (2), right pixel noise (2)] (Sec. II-A).
  MatrixXd C = MatrixXd::Zero(10, 10);
  C.topLeftCorner<6, 6>() = covariance_.block<6, 6>(layout::kCamr, layout::kCamr);
  C.bottomRightCorner<4, 4>() = m.variance.asDiagonal();
  const double min_depth = config_.min_point_depth, max_depth = config_.max_point_depth;
  const bool scaled = config_.baseline_scaled_points != 0;
  const VectorFunction triangulate = [&](const VectorXd& x, VectorXd* y) {
    const Eigen::Isometry3d T_caml_camr = boxPlus(extrinsics_.T_caml_camr, x.head<6>());
    const Eigen::Isometry3d T_lopt_ropt = leftToRightOptical(T_caml_camr);
    const double scale = pointScale(T_caml_camr);
    if (!(scale > 0.0)) return false;
    Eigen::Vector3d metric;
    if (coordinates_.inverseDepth()) {
      // Any disparity has an inverse depth: a sigma point beyond infinity is still one.
      const auto c = triangulateInverseDepth(m.z + x.tail<4>(), T_lopt_ropt, intrinsics_);
      if (!c || c->z() > 2.0 / min_depth) return false;
      metric = *c;
    } else {
      const auto p = triangulateStereo(m.z + x.tail<4>(), T_lopt_ropt, intrinsics_);
      if (!p || p->z() < 0.5 * min_depth || p->z() > 2.0 * max_depth) return false;
      metric = *p;
    }
    // In units of this sigma point's baseline: a function of the pixels and x_camr's
    // rotation and direction only (the disparity), not of the baseline's length.
    Eigen::Vector3d stored;
    if (!coordinates_.fromHomogeneous(scaledFromMetric(coordinates_.homogeneous(metric), scale),
                                      &stored))
      return false;
    if (scaled) {
      // ... and the metric point as well, for the depth check below.
      y->resize(6);
      *y << stored, metric;
    } else {
      *y = stored;
    }
    return true;
  };
  UnscentedResult ut;
  if (!unscentedTransformWithFallback(VectorXd::Zero(10), C, triangulate, ut_, &ut)) return false;
  // The depth is judged in metres over the baseline's uncertainty: the mean of the metric
  // point over the sigma points, as with metric points. (The stored point's mean in units
  // of the baseline times the mean baseline would not see that baseline: a small rig with a
  // baseline prior as wide as the baseline would accept points whose metric depth is
  // unknown to a factor of two or more, and some such runs ended 40-200 sigma off.)
  const double depth = coordinates_.depth(scaled ? Eigen::Vector3d(ut.mean.tail<3>())
                                                 : Eigen::Vector3d(ut.mean.head<3>()));
  if (!(depth >= min_depth && depth <= max_depth)) return false;
  TrackedPoint point;
  point.id = m.id;
  point.mean = ut.mean.head<3>();
  point.B = MatrixXd::Zero(3, persistentDim());
  point.B.middleCols<6>(layout::kCamr) = ut.jacobian.topLeftCorner<3, 6>();
  // D = Cov(p) - B P B^T: what the calibration does not explain (pixel noise, nonlinearity).
  MatrixXd D = ut.covariance.topLeftCorner<3, 3>() - point.B * covariance_ * point.B.transpose();
  makeSymmetricPsd(&D, 1e-12);
  point.D = D;
  index_[point.id] = points_.size();
  points_.push_back(std::move(point));
  return true;
}

void CalibrationFilter::removePoint(PointId id) {
  const auto found = index_.find(id);
  if (found == index_.end()) return;
  std::vector<bool> remove(points_.size(), false);
  remove[found->second] = true;
  removeIndices(remove);
}

std::vector<PointEstimate> CalibrationFilter::points() const {
  std::vector<PointEstimate> result;
  result.reserve(points_.size());
  // Metres = scale * stored position; the scale (the baseline's length) is uncertain too:
  // d scale = u^T dt_r (u: the baseline's direction; boxPlus adds translations).
  const double scale = pointScale();
  const double min_inverse_depth = minInverseDepth() * scale;
  MatrixXd scale_row = MatrixXd::Zero(1, covariance_.rows());
  if (config_.baseline_scaled_points != 0 && scale > 0.0) {
    scale_row.middleCols<3>(layout::kCamr + layout::kTranslation) =
        extrinsics_.T_caml_camr.translation().transpose() / scale;
  }
  for (const TrackedPoint& point : points_) {
    PointEstimate e;
    e.id = point.id;
    const Eigen::Vector3d stored = coordinates_.position(point.mean, min_inverse_depth);
    e.position_lopt = scale * stored;
    // Cov(position) = J^-1 Cov(c) J^-T, J = d c / d position (a far point: clamped as above),
    // plus the scale's share.
    Eigen::Matrix3d J_inverse = Eigen::Matrix3d::Identity();
    if (coordinates_.inverseDepth()) {
      Eigen::Vector3d clamped = point.mean;
      clamped.z() = std::max(clamped.z(), min_inverse_depth);
      J_inverse = coordinates_.jacobianFromPosition(clamped).inverse();
    }
    const MatrixXd M =
        scale * J_inverse * point.B.leftCols(covariance_.cols()) + stored * scale_row;
    e.covariance = M * covariance_ * M.transpose() +
                   scale * scale * J_inverse * point.D * J_inverse.transpose();
    result.push_back(e);
  }
  return result;
}

MatrixXd CalibrationFilter::denseCovariance() const {
  const int g = persistentDim();
  const int n = g + 3 * static_cast<int>(points_.size());
  MatrixXd full = MatrixXd::Zero(n, n);
  full.topLeftCorner(g, g) = covariance_;
  for (size_t i = 0; i < points_.size(); ++i) {
    const int a = g + 3 * static_cast<int>(i);
    const MatrixXd BP = points_[i].B * covariance_;
    full.block(a, 0, 3, g) = BP;
    full.block(0, a, g, 3) = BP.transpose();
    for (size_t j = 0; j < points_.size(); ++j) {
      const int b = g + 3 * static_cast<int>(j);
      full.block(a, b, 3, 3) = BP * points_[j].B.transpose();
    }
    full.block(a, a, 3, 3) += points_[i].D;
  }
  return full;
}

}  // namespace osc
