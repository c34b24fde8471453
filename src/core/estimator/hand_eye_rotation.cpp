#include "online_stereo_calibration/core/estimator/hand_eye_rotation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;
/// Median of the norm of a Gaussian vector over its per-axis sigma: 3 dof (a rotation
/// residual) and 2 dof (a direction residual, perpendicular to the direction).
constexpr double kMedianNorm3 = 1.5382;
constexpr double kMedianNorm2 = 1.1774;

/// [w x y z] of a rotation, w >= 0 (the pairs' small increments stay on one sheet).
Eigen::Vector4d quaternionOf(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  Eigen::Vector4d v(q.w(), q.x(), q.y(), q.z());
  return v(0) < 0.0 ? Eigen::Vector4d(-v) : v;
}

/// p (x) q = left(p) q, [w x y z].
Eigen::Matrix4d left(const Eigen::Vector4d& p) {
  Eigen::Matrix4d m;
  m(0, 0) = p(0);
  m.block<1, 3>(0, 1) = -p.tail<3>().transpose();
  m.block<3, 1>(1, 0) = p.tail<3>();
  m.block<3, 3>(1, 1) = p(0) * Eigen::Matrix3d::Identity() + skew(p.tail<3>());
  return m;
}

/// q (x) p = right(p) q, [w x y z].
Eigen::Matrix4d right(const Eigen::Vector4d& p) {
  Eigen::Matrix4d m;
  m(0, 0) = p(0);
  m.block<1, 3>(0, 1) = -p.tail<3>().transpose();
  m.block<3, 1>(1, 0) = p.tail<3>();
  m.block<3, 3>(1, 1) = p(0) * Eigen::Matrix3d::Identity() - skew(p.tail<3>());
  return m;
}

Eigen::Vector4d pure(const Eigen::Vector3d& v) { return Eigen::Vector4d(0.0, v.x(), v.y(), v.z()); }

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace

HandEyeRotation::HandEyeRotation(const HandEyeRotationConfig& config) : config_(config) {}

void HandEyeRotation::addRotationPair(const Eigen::Matrix3d& R_vehicle,
                                      const Eigen::Matrix3d& R_camera) {
  if (!R_vehicle.allFinite() || !R_camera.allFinite() ||
      !(logSO3(R_vehicle).norm() >= config_.min_rotation)) {
    return;
  }
  rotations_.push_back({R_vehicle, R_camera});
  while (rotations_.size() > config_.window) rotations_.pop_front();
}

void HandEyeRotation::addDirectionPair(const Eigen::Vector3d& t_vehicle,
                                       const Eigen::Vector3d& t_camera) {
  if (!t_vehicle.allFinite() || !t_camera.allFinite() || !(t_vehicle.norm() > 0.0) ||
      !(t_camera.norm() > 0.0)) {
    return;
  }
  directions_.push_back({t_vehicle.normalized(), t_camera.normalized()});
  while (directions_.size() > config_.window) directions_.pop_front();
}

void HandEyeRotation::clear() {
  rotations_.clear();
  directions_.clear();
}

HandEyeRotationResult HandEyeRotation::solve() const {
  HandEyeRotationResult result;
  result.rotation_pairs = rotationPairs();
  result.direction_pairs = directionPairs();
  const int pairs = result.rotation_pairs + result.direction_pairs;
  if (pairs < std::max(config_.min_pairs, 3)) {
    result.covariance = Eigen::Matrix3d::Identity() * std::numeric_limits<double>::infinity();
    result.max_sigma = std::numeric_limits<double>::infinity();
    result.reason = "not determined yet: " + std::to_string(pairs) + " motion pairs (least " +
                    std::to_string(config_.min_pairs) + ")";
    return result;
  }

  // Each pair's 4x4 block M with M q = 0 for the true q.
  std::vector<Eigen::Matrix4d> blocks;
  blocks.reserve(static_cast<size_t>(pairs));
  for (const RotationPair& p : rotations_) {
    blocks.push_back(left(quaternionOf(p.vehicle)) - right(quaternionOf(p.camera)));
  }
  for (const DirectionPair& p : directions_) {
    blocks.push_back(left(pure(p.vehicle)) - right(pure(p.camera)));
  }
  // Per-axis residual sigmas of each kind, first guesses; then estimated from the residuals.
  double sigma_rotation = 0.05 * kDeg, sigma_direction = 3.0 * kDeg;
  std::vector<double> huber(blocks.size(), 1.0);
  std::vector<Eigen::Vector3d> residuals(blocks.size());
  Eigen::Matrix3d X = Eigen::Matrix3d::Identity();
  Eigen::Vector4d eigenvalues = Eigen::Vector4d::Zero();
  auto residualOf = [&](size_t i, const Eigen::Matrix3d& x) -> Eigen::Vector3d {
    if (i < rotations_.size()) {
      const RotationPair& p = rotations_[i];
      return logSO3(p.camera.transpose() * x.transpose() * p.vehicle * x);
    }
    const DirectionPair& p = directions_[i - rotations_.size()];
    return (x * p.camera).cross(p.vehicle);
  };
  for (int iteration = 0; iteration < 5; ++iteration) {
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    for (size_t i = 0; i < blocks.size(); ++i) {
      // Block residuals: |q_a - q_c| ~ angle / 2 for a rotation pair, ~ angle for a direction.
      const double w =
          huber[i] * (i < rotations_.size() ? 2.0 / sigma_rotation : 1.0 / sigma_direction);
      normal += w * w * blocks[i].transpose() * blocks[i];
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(normal);
    eigenvalues = eigen.eigenvalues();
    const Eigen::Vector4d q = eigen.eigenvectors().col(0);
    X = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
    std::vector<double> rotation_norms, direction_norms;
    for (size_t i = 0; i < blocks.size(); ++i) {
      residuals[i] = residualOf(i, X);
      (i < rotations_.size() ? rotation_norms : direction_norms).push_back(residuals[i].norm());
    }
    sigma_rotation = std::max(config_.min_rotation_residual, median(rotation_norms) / kMedianNorm3);
    sigma_direction =
        std::max(config_.min_direction_residual, median(direction_norms) / kMedianNorm2);
    for (size_t i = 0; i < blocks.size(); ++i) {
      const double bound =
          config_.huber_sigmas *
          (i < rotations_.size() ? kMedianNorm3 * sigma_rotation : kMedianNorm2 * sigma_direction);
      const double r = residuals[i].norm();
      huber[i] = r > bound ? std::sqrt(bound / r) : 1.0;  // Huber's IRLS weight on the row
    }
  }
  result.R_veh_cam = X;
  result.rotation_residual = result.rotation_pairs > 0 ? sigma_rotation : 0.0;
  result.direction_residual = result.direction_pairs > 0 ? sigma_direction : 0.0;
  result.conditioning =
      eigenvalues(3) > 0.0 ? std::sqrt(std::max(0.0, eigenvalues(1)) / eigenvalues(3)) : 0.0;

  // Gauss-Newton information of the tangent error at X (central differences).
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  const double h = 1e-6;
  for (size_t i = 0; i < blocks.size(); ++i) {
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = Eigen::Vector3d::Unit(k) * h;
      J.col(k) = (residualOf(i, X * expSO3(d)) - residualOf(i, X * expSO3(-d))) / (2.0 * h);
    }
    const double sigma = i < rotations_.size() ? sigma_rotation : sigma_direction;
    information += huber[i] * huber[i] / (sigma * sigma) * J.transpose() * J;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> info(information);
  const double largest = info.eigenvalues()(2);
  Eigen::Vector3d variances;
  for (int k = 0; k < 3; ++k) {
    const double lambda = info.eigenvalues()(k);
    variances(k) = lambda > 1e-12 * std::max(largest, 1.0)
                       ? 1.0 / lambda
                       : std::numeric_limits<double>::infinity();
  }
  const Eigen::Matrix3d V = info.eigenvectors();
  result.covariance = std::isfinite(variances(0))
                          ? Eigen::Matrix3d(V * variances.asDiagonal() * V.transpose())
                          : Eigen::Matrix3d(Eigen::Matrix3d::Identity() * variances(0));
  result.max_sigma = std::sqrt(variances(0));
  result.weakest_axis_vehicle = X * V.col(0);
  if (result.weakest_axis_vehicle.maxCoeff() < -result.weakest_axis_vehicle.minCoeff()) {
    result.weakest_axis_vehicle = -result.weakest_axis_vehicle;  // report it pointing "up"
  }
  result.determined = result.max_sigma <= config_.max_sigma;
  std::ostringstream why;
  why.precision(3);
  const Eigen::Vector3d& a = result.weakest_axis_vehicle;
  if (!result.determined) {
    why << "not determined yet: too little rotation about the vehicle axis [" << a.x() << ", "
        << a.y() << ", " << a.z() << "] (1 sigma " << result.max_sigma / kDeg << " deg, at most "
        << config_.max_sigma / kDeg << "; " << result.rotation_pairs << " rotation and "
        << result.direction_pairs << " direction pairs)";
  } else {
    why << "determined from " << result.rotation_pairs << " rotation and " << result.direction_pairs
        << " direction pairs: worst axis [" << a.x() << ", " << a.y() << ", " << a.z()
        << "] 1 sigma " << result.max_sigma / kDeg << " deg";
  }
  result.reason = why.str();
  return result;
}

}  // namespace osc
