#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace osc {

namespace {

/// Kabsch: the rotation maximising sum to_i . (R from_i) over the selected pairs.
Eigen::Matrix3d wahbaRotation(const std::vector<Eigen::Vector3d>& from,
                              const std::vector<Eigen::Vector3d>& to,
                              const std::vector<bool>& selected) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    if (selected[i]) B += to[i] * from[i].transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

bool fitBearingRotation(const std::vector<Eigen::Vector3d>& from,
                        const std::vector<Eigen::Vector3d>& to, double min_trim_angle,
                        int min_inliers, BearingRotationFit* fit) {
  const size_t n = from.size();
  if (to.size() != n || static_cast<int>(n) < std::max(3, min_inliers)) return false;
  std::vector<Eigen::Vector3d> a(n), b(n);
  for (size_t i = 0; i < n; ++i) {
    if (!from[i].allFinite() || !to[i].allFinite() || !(from[i].norm() > 0.0) ||
        !(to[i].norm() > 0.0)) {
      return false;
    }
    a[i] = from[i].normalized();
    b[i] = to[i].normalized();
  }
  std::vector<bool> selected(n, true);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  std::vector<double> angles(n);
  constexpr int kTrimmingRounds = 3;
  for (int round = 0; round <= kTrimmingRounds; ++round) {
    R = wahbaRotation(a, b, selected);
    for (size_t i = 0; i < n; ++i) angles[i] = angleBetween(b[i], R * a[i]);
    if (round == kTrimmingRounds) break;
    std::vector<double> sorted = angles;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    const double threshold = std::max(min_trim_angle, 3.0 * sorted[n / 2]);
    for (size_t i = 0; i < n; ++i) selected[i] = angles[i] <= threshold;
  }
  int inliers = 0;
  double sum_squares = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!selected[i]) continue;
    ++inliers;
    sum_squares += angles[i] * angles[i];
  }
  if (inliers < std::max(3, min_inliers)) return false;
  fit->rotation = R;
  fit->inliers = inliers;
  fit->rms_angle = std::sqrt(sum_squares / inliers);
  return true;
}

}  // namespace osc
