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

EpipolarMatcher::EpipolarMatcher(const FrontEndConfig& config, double min_depth, double max_depth)
    : config_(config), min_depth_(min_depth), max_depth_(max_depth) {
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

EpipolarMatcher::Lines EpipolarMatcher::lines(const Eigen::Vector2d& left) const {
  Lines l;
  l.nominal = epipolarLine(F_, left);  // eq. 6
  for (int j = 0; j < 6; ++j) l.sigma[j] = epipolarLine(F_sigma_[j], left);
  return l;
}

double EpipolarMatcher::bandHalfWidth(const Lines& lines, const Eigen::Vector2d& right) const {
  return std::clamp(
      config_.band_sigmas * std::sqrt(lineDistanceVariance(lines, right, config_.pixel_sigma)),
      config_.min_band, config_.max_band);
}

double EpipolarMatcher::refinedBandHalfWidth(const Lines& lines, const Eigen::Vector2d& right,
                                             double pixel_sigma) const {
  return std::min(config_.band_sigmas * std::sqrt(lineDistanceVariance(lines, right, pixel_sigma)),
                  config_.max_band);
}

double EpipolarMatcher::lineDistanceVariance(const Lines& lines, const Eigen::Vector2d& right,
                                             double pixel_sigma) const {
  const Eigen::Vector3d r(right.x(), right.y(), 1.0);
  const double d0 = lines.nominal.dot(r);
  double variance = 2.0 * pixel_sigma * pixel_sigma;
  for (int j = 0; j < 6; ++j) {
    const double dj = lines.sigma[j].dot(r) - d0;
    variance += dj * dj;
  }
  return variance;
}

double EpipolarMatcher::bandHalfWidth(const Eigen::Vector2d& left,
                                      const Eigen::Vector2d& right) const {
  return bandHalfWidth(lines(left), right);
}

std::vector<StereoMatch> EpipolarMatcher::match(const FeatureSet& left, const FeatureSet& right,
                                                const std::vector<char>& left_used,
                                                const std::vector<char>& right_used) const {
  const double inf = std::numeric_limits<double>::infinity();
  // The best proposal of each left keypoint, and per right keypoint the best and second
  // best left keypoint among all whose band it lies in (for the mutual check).
  std::vector<StereoMatch> best_of_left(left.size());
  std::vector<double> second_of_left(left.size(), inf);
  std::vector<int> right_best(right.size(), -1);
  std::vector<double> right_best_distance(right.size(), inf), right_second(right.size(), inf);
  std::vector<int> stamp(right.size(), -1);
  std::vector<int> candidates;
  const double pixel_var = 2.0 * config_.pixel_sigma * config_.pixel_sigma;

  for (size_t i = 0; i < left.size(); ++i) {
    if (!left_used.empty() && left_used[i]) continue;
    const Eigen::Vector2d& xl = left.undistorted[i];
    const Eigen::Vector3d ray = K_left_inv_ * Eigen::Vector3d(xl.x(), xl.y(), 1.0);
    // Segment of the epipolar line from the image of the point at max_depth (or infinity:
    // zero disparity) to the image of the point at min_depth (positive disparity side):
    // nothing outside the depths the filter accepts is searched (plausible disparities only).
    Eigen::Vector2d x_inf, x_near;
    const bool far_finite = std::isfinite(max_depth_);
    if (!(far_finite ? projectRight(K_right_, T_ropt_lopt_ * (max_depth_ * ray), &x_inf)
                     : projectRight(K_right_, T_ropt_lopt_.linear() * ray, &x_inf))) {
      continue;
    }
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
      if (far_finite ? projectRight(K_right_, T_sigma_[j] * (max_depth_ * ray), &p)
                     : projectRight(K_right_, T_sigma_[j].linear() * ray, &p)) {
        var_inf += std::pow(dir.dot(p - x_inf), 2);
      }
      if (projectRight(K_right_, T_sigma_[j] * (near_depth * ray), &p)) {
        var_near += std::pow(dir.dot(p - x_near), 2);
      }
    }
    const Lines line = lines(xl);
    const double margin_inf = std::min(config_.band_sigmas * std::sqrt(var_inf), config_.max_band);
    const double margin_near =
        std::min(config_.band_sigmas * std::sqrt(var_near), config_.max_band);
    const double band = std::max(bandHalfWidth(line, x_inf), bandHalfWidth(line, x_near));
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

    StereoMatch& best = best_of_left[i];
    best.descriptor_distance = inf;
    double& second = second_of_left[i];
    for (int j : candidates) {
      const size_t sj = static_cast<size_t>(j);
      if (stamp[sj] == static_cast<int>(i)) continue;  // chunk overlap
      stamp[sj] = static_cast<int>(i);
      if (!right_used.empty() && right_used[sj]) continue;
      const Eigen::Vector2d& xr = right.undistorted[sj];
      const double t = dir.dot(xr - x_inf);
      if (t < t_min || t > t_max) continue;  // negative disparity or closer than min_depth
      const double d = line.nominal.dot(Eigen::Vector3d(xr.x(), xr.y(), 1.0));
      if (std::abs(d) > config_.max_band) continue;
      const double half = bandHalfWidth(line, xr);
      if (std::abs(d) > half) continue;
      const double dist = left.distance(static_cast<int>(i), right, j);
      if (dist < best.descriptor_distance) {
        second = best.descriptor_distance;
        best.left = static_cast<int>(i);
        best.right = j;
        best.descriptor_distance = dist;
        best.line_distance = d;
        best.band = half;
      } else if (dist < second) {
        second = dist;
      }
      if (dist < right_best_distance[sj]) {
        right_second[sj] = right_best_distance[sj];
        right_best_distance[sj] = dist;
        right_best[sj] = static_cast<int>(i);
      } else if (dist < right_second[sj]) {
        right_second[sj] = dist;
      }
    }
  }
  // Accept a proposal when it is distinctive from both sides: within the distance bound,
  // passing Lowe's ratio test among the left keypoint's candidates and among the right
  // keypoint's candidates (the left keypoints whose bands hold it), and mutual (the right
  // keypoint's best left keypoint is this one), which also makes the matches one-to-one.
  std::vector<StereoMatch> matches;
  for (size_t i = 0; i < left.size(); ++i) {
    StereoMatch m = best_of_left[i];
    if (m.left < 0 || m.descriptor_distance > config_.max_descriptor_distance) continue;
    const double second = second_of_left[i];
    if (second < inf && m.descriptor_distance >= config_.ratio * second) continue;
    const size_t sj = static_cast<size_t>(m.right);
    if (right_best[sj] != static_cast<int>(i)) continue;
    if (right_second[sj] < inf && m.descriptor_distance >= config_.ratio * right_second[sj]) {
      continue;
    }
    m.second_distance = std::min(second, right_second[sj]);
    matches.push_back(m);
  }
  return matches;
}

}  // namespace osc
