#include "online_stereo_calibration/core/frontend/epipolar_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

Eigen::Isometry3d rightFromLeftOptical(const Eigen::Isometry3d& T_caml_camr) {
  StereoExtrinsics e;
  e.T_caml_camr = T_caml_camr;
  return e.leftToRightOptical().inverse();
}

/// Undistorted pixel of a right-optical point; false if not in front.
bool projectRight(const Eigen::Matrix3d& K, const Eigen::Vector3d& p, Eigen::Vector2d* pixel) {
  if (p.z() <= 1e-9) return false;
  const Eigen::Vector3d h = K * (p / p.z());
  *pixel = h.head<2>();
  return true;
}

}  // namespace

EpipolarMatcher::EpipolarMatcher(const FrontEndConfig& config, double min_depth)
    : config_(config), min_depth_(min_depth) {
  setGeometry(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
              Eigen::Isometry3d::Identity(), Matrix6d::Zero());
}

void EpipolarMatcher::setGeometry(const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                                  const Eigen::Isometry3d& T_caml_camr,
                                  const Matrix6d& camr_covariance) {
  K_left_inv_ = K_left.inverse();
  K_right_ = K_right;
  T_ropt_lopt_ = rightFromLeftOptical(T_caml_camr);
  F_ = fundamentalMatrix(K_left, K_right, T_ropt_lopt_.inverse());  // eq. 5
  // P = V diag(lambda) V^T: the line distance's variance is the sum over j of the squared
  // change along sqrt(lambda_j) v_j (exact to first order, robust to a large P).
  const Matrix6d P = 0.5 * (camr_covariance + camr_covariance.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(P);
  for (int j = 0; j < 6; ++j) {
    const double lambda = std::max(0.0, eig.eigenvalues()(j));
    const Vector6d delta = std::sqrt(lambda) * eig.eigenvectors().col(j);
    T_sigma_[j] = rightFromLeftOptical(boxPlus(T_caml_camr, delta));
    F_sigma_[j] = fundamentalMatrix(K_left, K_right, T_sigma_[j].inverse());
  }
}

double EpipolarMatcher::bandHalfWidth(const Eigen::Vector2d& left,
                                      const Eigen::Vector2d& right) const {
  const Eigen::Vector3d r(right.x(), right.y(), 1.0);
  const double d0 = epipolarLine(F_, left).dot(r);  // eq. 6
  double variance = 2.0 * config_.pixel_sigma * config_.pixel_sigma;
  for (int j = 0; j < 6; ++j) {
    const double dj = epipolarLine(F_sigma_[j], left).dot(r) - d0;
    variance += dj * dj;
  }
  return std::clamp(config_.band_sigmas * std::sqrt(variance), config_.min_band, config_.max_band);
}

std::vector<StereoMatch> EpipolarMatcher::match(const FeatureSet& left, const FeatureSet& right,
                                                const std::vector<char>& left_used,
                                                const std::vector<char>& right_used) const {
  const double inf = std::numeric_limits<double>::infinity();
  // Best proposal per right keypoint (one-to-one: the smaller descriptor distance wins).
  std::vector<StereoMatch> best_for_right(right.size());
  std::vector<int> stamp(right.size(), -1);
  std::vector<int> candidates;
  const double pixel_var = 2.0 * config_.pixel_sigma * config_.pixel_sigma;

  for (size_t i = 0; i < left.size(); ++i) {
    if (!left_used.empty() && left_used[i]) continue;
    const Eigen::Vector2d& xl = left.undistorted[i];
    const Eigen::Vector3d ray = K_left_inv_ * Eigen::Vector3d(xl.x(), xl.y(), 1.0);
    // Segment of the epipolar line from the image of the point at infinity (zero
    // disparity) to the image of the point at min_depth (positive disparity side).
    Eigen::Vector2d x_inf, x_near;
    if (!projectRight(K_right_, T_ropt_lopt_.linear() * ray, &x_inf)) continue;
    double near_depth = min_depth_;
    bool near_ok = projectRight(K_right_, T_ropt_lopt_ * (near_depth * ray), &x_near);
    for (int k = 0; k < 8 && !near_ok; ++k) {
      near_depth *= 2.0;
      near_ok = projectRight(K_right_, T_ropt_lopt_ * (near_depth * ray), &x_near);
    }
    if (!near_ok) continue;
    Eigen::Vector2d dir = x_near - x_inf;
    const double length = dir.norm();
    if (length < 1e-9) {
      dir = Eigen::Vector2d::UnitX();  // no baseline: the segment is a point
    } else {
      dir /= length;
    }
    // Along-line uncertainty of the two ends and the largest band half-width, from the
    // covariance of x_camr.
    double var_inf = pixel_var, var_near = pixel_var;
    for (int j = 0; j < 6; ++j) {
      Eigen::Vector2d p;
      if (projectRight(K_right_, T_sigma_[j].linear() * ray, &p)) {
        var_inf += std::pow(dir.dot(p - x_inf), 2);
      }
      if (projectRight(K_right_, T_sigma_[j] * (near_depth * ray), &p)) {
        var_near += std::pow(dir.dot(p - x_near), 2);
      }
    }
    const double margin_inf = std::min(config_.band_sigmas * std::sqrt(var_inf), config_.max_band);
    const double margin_near =
        std::min(config_.band_sigmas * std::sqrt(var_near), config_.max_band);
    const double band = std::max(bandHalfWidth(xl, x_inf), bandHalfWidth(xl, x_near));
    const double t_min = -std::max(margin_inf, config_.min_band);
    const double t_max = length + std::max(margin_near, config_.min_band);

    // Gather candidates chunk by chunk along the (clipped) segment.
    candidates.clear();
    const double chunk = std::max(32.0, 2.0 * band);
    const double x_lo = -band - 1.0, y_lo = -band - 1.0;
    const double x_hi = 1e5, y_hi = 1e5;  // the grid clamps; huge segments are bounded below
    const double t_end = std::min(t_max, t_min + 20000.0);
    for (double t0 = t_min; t0 < t_end; t0 += chunk) {
      const double t1 = std::min(t0 + chunk, t_end);
      const Eigen::Vector2d a = x_inf + t0 * dir, b = x_inf + t1 * dir;
      const Eigen::Vector2d lo = a.cwiseMin(b).array() - band;
      const Eigen::Vector2d hi = a.cwiseMax(b).array() + band;
      if (hi.x() < x_lo || hi.y() < y_lo || lo.x() > x_hi || lo.y() > y_hi) continue;
      right.undistorted_grid.query(lo, hi, &candidates);
    }

    const Eigen::Vector3d line = epipolarLine(F_, xl);  // eq. 6
    double best = inf, second = inf;
    int best_j = -1;
    double best_line = 0.0, best_band = 0.0;
    for (int j : candidates) {
      if (stamp[static_cast<size_t>(j)] == static_cast<int>(i)) continue;  // chunk overlap
      stamp[static_cast<size_t>(j)] = static_cast<int>(i);
      if (!right_used.empty() && right_used[static_cast<size_t>(j)]) continue;
      const Eigen::Vector2d& xr = right.undistorted[static_cast<size_t>(j)];
      const double t = dir.dot(xr - x_inf);
      if (t < t_min || t > t_max) continue;  // negative disparity or closer than min_depth
      const double d = line.dot(Eigen::Vector3d(xr.x(), xr.y(), 1.0));
      const double half = bandHalfWidth(xl, xr);
      if (std::abs(d) > half) continue;
      const double dist = right.distance(j, left.descriptors.row(static_cast<int>(i)));
      if (dist < best) {
        second = best;
        best = dist;
        best_j = j;
        best_line = d;
        best_band = half;
      } else if (dist < second) {
        second = dist;
      }
    }
    if (best_j < 0 || best > config_.max_descriptor_distance) continue;
    if (second < inf && best >= config_.ratio * second) continue;  // Lowe's ratio test
    StereoMatch& slot = best_for_right[static_cast<size_t>(best_j)];
    if (slot.left < 0 || best < slot.descriptor_distance) {
      slot.left = static_cast<int>(i);
      slot.right = best_j;
      slot.descriptor_distance = best;
      slot.line_distance = best_line;
      slot.band = best_band;
    }
  }
  std::vector<StereoMatch> matches;
  for (const StereoMatch& m : best_for_right) {
    if (m.left >= 0) matches.push_back(m);
  }
  std::sort(matches.begin(), matches.end(),
            [](const StereoMatch& a, const StereoMatch& b) { return a.left < b.left; });
  return matches;
}

}  // namespace osc
