/// @file baseline_from_motion.cpp
/// @brief BaselineFromMotion: rho_b = L rho_m + c over points seen in consecutive stereo
/// pairs (baseline_from_motion.h).
#include "online_stereo_calibration/core/estimator/baseline_from_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// One point's two inverse depths and their sigmas.
struct InverseDepths {
  double motion = 0.0, motion_sigma = 0.0;  ///< rho_m (1/m)
  double stereo = 0.0, stereo_sigma = 0.0;  ///< rho_b (1/baseline)
  /// How much a turn of the right camera about the axis across the baseline and the view
  /// shifts rho_b: 1 + s^2, s the point's normalised coordinate along the baseline.
  double offset_gain = 1.0;
};

/// The line rho_b = L rho_m + c k (k: offset_gain) through points with errors in both inverse
/// depths: the residual's variance at slope L.
double residualVariance(const InverseDepths& d, double L) {
  return d.stereo_sigma * d.stereo_sigma + L * L * d.motion_sigma * d.motion_sigma;
}

/// Adds @p inliers to @p sums, weighted by their residual's variance at slope @p L.
void addToSums(const std::vector<InverseDepths>& depths, const std::vector<int>& inliers, double L,
               LineSums* sums) {
  for (int i : inliers) {
    const InverseDepths& d = depths[static_cast<size_t>(i)];
    const double w = 1.0 / residualVariance(d, L);
    const Eigen::Vector2d row(d.motion, d.offset_gain);
    sums->normal += w * row * row.transpose();
    sums->right_side += w * row * d.stereo;
    sums->weighted_y2 += w * d.stereo * d.stereo;
  }
}

/// Weighted least squares of the line over @p inliers at slope @p L (for the weights).
bool fitLine(const std::vector<InverseDepths>& depths, const std::vector<int>& inliers, double L,
             Eigen::Vector2d* line) {
  LineSums sums;
  addToSums(depths, inliers, L, &sums);
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(sums.normal);
  if (ldlt.info() != Eigen::Success || !(std::abs(sums.normal.determinant()) > 0.0)) return false;
  *line = ldlt.solve(sums.right_side);
  return line->allFinite();
}

std::vector<int> inliersOf(const std::vector<InverseDepths>& depths, const Eigen::Vector2d& line) {
  constexpr double kSigmas = 3.0;
  std::vector<int> inliers;
  for (size_t i = 0; i < depths.size(); ++i) {
    const InverseDepths& d = depths[i];
    const double r = d.stereo - line(0) * d.motion - line(1) * d.offset_gain;
    if (r * r <= kSigmas * kSigmas * residualVariance(d, line(0)))
      inliers.push_back(static_cast<int>(i));
  }
  return inliers;
}

}  // namespace

double inverseDepthFromTwoViews(const Eigen::Vector3d& ray, const Eigen::Vector2d& other,
                                const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double noise,
                                double* sigma) {
  // other = (R_0 X + t_0) / (R_2 X + t_2), X = ray / rho: rho (u t_2 - t_0) = R_0 ray - u R_2 ray.
  const Eigen::Vector3d Rr = R * ray;
  const Eigen::Vector2d g(other.x() * t.z() - t.x(), other.y() * t.z() - t.y());
  const Eigen::Vector2d h(Rr.x() - other.x() * Rr.z(), Rr.y() - other.y() * Rr.z());
  const double gg = g.squaredNorm();
  if (!(gg > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double rho = g.dot(h) / gg;
  if (sigma) {
    // A shift of the other view's coordinate by e moves the residual by (R_2 ray + t_2 rho) e;
    // one of the reference ray's moves it by about as much: both views' noise.
    *sigma = std::sqrt(2.0) * noise * std::abs(Rr.z() + t.z() * rho) / std::sqrt(gg);
  }
  return rho;
}

Eigen::Isometry3d withoutDisparityOffset(const Eigen::Isometry3d& T_lopt_ropt, double offset) {
  // With X_right = R X_left + t, a right camera turned by d about a = t x e_z (optical y for a
  // horizontal rig) shifts every stereo inverse depth (inverseDepthFromTwoViews, unit t) by
  // -d (1 + s^2) to first order (s: the coordinate along the baseline), which the fit's
  // offset takes: turning it by -offset about a takes the offset out. The camera's
  // centre stays: both R and t turn.
  const Eigen::Isometry3d T_ropt_lopt = T_lopt_ropt.inverse();
  const Eigen::Vector3d axis =
      T_ropt_lopt.translation().normalized().cross(Eigen::Vector3d::UnitZ()).normalized();
  if (!axis.allFinite()) return T_lopt_ropt;
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = expSO3(-offset * axis);
  return (turned * T_ropt_lopt).inverse();
}

bool BaselineFromMotion::addPair(const std::vector<StereoLink>& links,
                                 const Eigen::Isometry3d& T_lopt_ropt, double camera_translation) {
  last_lacked_parallax_ = false;
  if (!(camera_translation >= config_.min_translation)) {
    last_lacked_parallax_ = true;
    std::ostringstream why;
    why << "the left camera moved " << camera_translation << " m (least " << config_.min_translation
        << ")";
    last_why_ = why.str();
    return false;
  }
  std::vector<Eigen::Vector2d> previous, current;
  for (const StereoLink& link : links) {
    previous.push_back(link.previous.head<2>());
    current.push_back(link.current.head<2>());
  }
  const CameraMotion motion = estimateCameraMotion(previous, current, config_.motion);
  if (!motion.valid) {
    last_lacked_parallax_ = motion.parallax > 0.0 && motion.parallax < config_.motion.min_parallax;
    last_why_ = "left camera motion: " + motion.why;
    return false;
  }
  // X_prev = R X_curr + t (optical): the previous camera as the "other" view of a point in the
  // current one, at the odometry's scale.
  const Eigen::Matrix3d& B = rotationBodyOptical();
  const Eigen::Matrix3d R_prev_curr = B.transpose() * motion.R_prev_curr * B;
  const Eigen::Vector3d t_prev_curr =
      B.transpose() * motion.translation_direction * camera_translation;
  // X_right = R X_left + t with a baseline of unit length.
  const Eigen::Isometry3d T_ropt_lopt = T_lopt_ropt.inverse();
  const Eigen::Vector3d t_unit = T_ropt_lopt.translation().normalized();
  const double noise = config_.pixel_noise / config_.motion.focal;
  const Eigen::Vector2d along = t_unit.head<2>().normalized();
  std::vector<InverseDepths> depths;
  for (const StereoLink& link : links) {
    const Eigen::Vector3d ray(link.current(0), link.current(1), 1.0);
    InverseDepths d;
    d.motion = inverseDepthFromTwoViews(ray, link.previous.head<2>(), R_prev_curr, t_prev_curr,
                                        noise, &d.motion_sigma);
    d.stereo = inverseDepthFromTwoViews(ray, link.current.tail<2>(), T_ropt_lopt.linear(), t_unit,
                                        noise, &d.stereo_sigma);
    d.offset_gain = along.allFinite() ? 1.0 + std::pow(along.dot(link.current.head<2>()), 2) : 1.0;
    if (std::isfinite(d.motion) && std::isfinite(d.stereo) && d.motion > 0.0 &&
        d.motion_sigma > 0.0 && d.stereo_sigma > 0.0) {
      depths.push_back(d);
    }
  }
  if (static_cast<int>(depths.size()) < config_.min_pair_inliers) {
    last_why_ = std::to_string(depths.size()) + " points in front of the moving camera";
    return false;
  }
  // RANSAC over pairs of points (deterministic: every pair of a fixed stride).
  std::vector<int> best;
  Eigen::Vector2d best_line = Eigen::Vector2d::Zero();
  const int n = static_cast<int>(depths.size());
  const int stride = std::max(1, n / 25);
  for (int i = 0; i < n; i += stride) {
    for (int j = i + 1; j < n; j += stride) {
      const InverseDepths &a = depths[static_cast<size_t>(i)], &b = depths[static_cast<size_t>(j)];
      Eigen::Vector2d line;
      // Two equations rho_b = L rho_m + c k in (L, c).
      const double det = a.motion * b.offset_gain - b.motion * a.offset_gain;
      if (!(std::abs(det) > 0.0)) continue;
      line(0) = (a.stereo * b.offset_gain - b.stereo * a.offset_gain) / det;
      line(1) = (a.motion * b.stereo - b.motion * a.stereo) / det;
      if (!(line(0) > 0.0)) continue;
      std::vector<int> inliers = inliersOf(depths, line);
      if (inliers.size() > best.size()) {
        best.swap(inliers);
        best_line = line;
      }
    }
  }
  // Refit on the inliers, twice (the weights depend on the slope).
  for (int round = 0; round < 2 && static_cast<int>(best.size()) >= 2; ++round) {
    if (!fitLine(depths, best, best_line(0), &best_line) || !(best_line(0) > 0.0)) break;
    best = inliersOf(depths, best_line);
  }
  if (static_cast<int>(best.size()) < config_.min_pair_inliers || !(best_line(0) > 0.0)) {
    last_why_ = std::to_string(best.size()) + " of " + std::to_string(n) + " points on one line";
    return false;
  }
  addToSums(depths, best, best_line(0), &sums_);
  pair_lengths_.push_back(best_line(0));
  inliers_ += static_cast<int>(best.size());
  last_why_.clear();
  return true;
}

BaselineLength BaselineFromMotion::estimate() const {
  BaselineLength result;
  const int pairs = static_cast<int>(pair_lengths_.size());
  result.pairs = pairs;
  result.inliers = inliers_;
  std::ostringstream why;
  if (pairs < config_.min_pairs || inliers_ < config_.min_inliers) {
    why << pairs << " pairs and " << inliers_ << " points so far (least " << config_.min_pairs
        << " and " << config_.min_inliers << ")";
    result.why = why.str();
    return result;
  }
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(sums_.normal);
  const Eigen::Vector2d line = ldlt.solve(sums_.right_side);
  const Eigen::Matrix2d covariance = ldlt.solve(Eigen::Matrix2d::Identity());
  if (ldlt.info() != Eigen::Success || !line.allFinite() || !covariance.allFinite()) {
    result.why = "the line fit is singular";
    return result;
  }
  // Reduced chi-square: the per-point sigmas are first-order and ignore the motion fit's own
  // error (common to a pair's points), so the scatter decides when it is larger.
  const double chi2 =
      sums_.weighted_y2 - 2.0 * line.dot(sums_.right_side) + line.dot(sums_.normal * line);
  const double reduced = std::max(1.0, chi2 / std::max(1, inliers_ - 2));
  result.length = line(0);
  result.offset = line(1);
  result.sigma = std::sqrt(std::max(0.0, covariance(0, 0)) * reduced);
  // Each pair's points share that pair's motion fit (its direction is a degree or so off over
  // a few dozen points), an error the per-point sigmas do not see: the pairs' own lengths
  // scatter by it, so the mean of K of them is known to their spread / sqrt(K) at best.
  if (pair_lengths_.size() >= 2) {
    const double k = static_cast<double>(pair_lengths_.size());
    double mean = 0.0, spread = 0.0;
    for (double l : pair_lengths_) mean += l / k;
    for (double l : pair_lengths_) spread += (l - mean) * (l - mean) / (k - 1.0);
    result.sigma = std::max(result.sigma, std::sqrt(spread / k));
  }
  result.offset_sigma = std::sqrt(std::max(0.0, covariance(1, 1)) * reduced);
  if (!(result.length > 0.0) || !(result.sigma <= config_.max_relative_sigma * result.length)) {
    why << "length " << result.length << " m with 1 sigma " << result.sigma << " m (at most "
        << 100.0 * config_.max_relative_sigma << " %)";
    result.why = why.str();
    return result;
  }
  result.valid = true;
  return result;
}

void BaselineFromMotion::clear() {
  last_lacked_parallax_ = false;
  sums_ = LineSums();
  inliers_ = 0;
  pair_lengths_.clear();
  last_why_.clear();
}

}  // namespace osc
