#include "online_stereo_calibration/core/estimator/epipolar_consistency.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "online_stereo_calibration/core/filter/consistency_monitor.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

constexpr double kStep = 1e-6;          // rad: central differences of F in x_camr's rotation
constexpr double kHuber = 3.0;          // normalised residuals beyond this are down-weighted
constexpr int kReweightings = 3;        // Huber iterations
constexpr double kRelativeRank = 1e-6;  // eigenvalues below this share of the largest: no info

/// One pair's residual normalised by its noise, and its derivative in x_camr's rotation.
struct NormalisedResidual {
  double r = 0.0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
};

}  // namespace

std::string EpipolarEvidence::summary() const {
  std::ostringstream out;
  out << pairs << " stereo pairs against x_camr's epipolar lines: statistic " << statistic
      << (contradicts ? " > " : " <= ") << bound << " (" << dof << " dof), indicated rotation "
      << angle * 180.0 / M_PI << " deg";
  return out.str();
}

EpipolarEvidence testEpipolarLines(const std::vector<PointMeasurement>& pairs,
                                   const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                                   const StereoExtrinsics& extrinsics,
                                   const Eigen::Matrix3d& rotation_covariance, double false_alarm,
                                   int min_pairs) {
  EpipolarEvidence evidence;
  // F of x_camr turned by +-kStep about each tangent axis (boxPlus of T_caml_camr).
  const auto fundamental = [&](const Eigen::Vector3d& turn) {
    StereoExtrinsics turned = extrinsics;
    Vector6d delta = Vector6d::Zero();
    delta.tail<3>() = turn;
    turned.T_caml_camr = boxPlus(extrinsics.T_caml_camr, delta);
    return fundamentalMatrix(K_left, K_right, turned.leftToRightOptical());
  };
  const Eigen::Matrix3d F = fundamental(Eigen::Vector3d::Zero());
  std::array<Eigen::Matrix3d, 3> dF;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d turn = kStep * Eigen::Vector3d::Unit(k);
    dF[static_cast<size_t>(k)] = (fundamental(turn) - fundamental(-turn)) / (2.0 * kStep);
  }

  std::vector<NormalisedResidual> residuals;
  residuals.reserve(pairs.size());
  for (const PointMeasurement& m : pairs) {
    if (!m.z.allFinite() || !m.variance.allFinite() || !(m.variance.minCoeff() > 0.0)) continue;
    const Eigen::Vector3d xl = m.z.head<2>().homogeneous(), xr = m.z.tail<2>().homogeneous();
    const Eigen::Vector3d Fxl = F * xl, Ftxr = F.transpose() * xr;
    const double variance = Fxl(0) * Fxl(0) * m.variance(2) + Fxl(1) * Fxl(1) * m.variance(3) +
                            Ftxr(0) * Ftxr(0) * m.variance(0) + Ftxr(1) * Ftxr(1) * m.variance(1);
    if (!(variance > 0.0)) continue;
    const double sigma = std::sqrt(variance);
    NormalisedResidual n;
    n.r = xr.dot(Fxl) / sigma;
    for (int k = 0; k < 3; ++k) n.a(k) = xr.dot(dF[static_cast<size_t>(k)] * xl) / sigma;
    residuals.push_back(n);
  }
  evidence.pairs = static_cast<int>(residuals.size());
  if (evidence.pairs < std::max(min_pairs, 1)) return evidence;

  // Huber-weighted fit of the rotation error from the pairs alone (the covariance would pull
  // it to zero: what is asked is how far the pairs put x_camr); the weights from the
  // previous fit's residuals.
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (int iteration = 0; iteration < kReweightings; ++iteration) {
    H.setZero();
    b.setZero();
    for (const NormalisedResidual& n : residuals) {
      const double left = std::abs(n.r + n.a.dot(shift));
      const double weight = left > kHuber ? kHuber / left : 1.0;
      H += weight * n.a * n.a.transpose();
      b += weight * n.a * n.r;
    }
    shift = -H.completeOrthogonalDecomposition().solve(b);
  }
  evidence.rotation_shift = shift;
  evidence.angle = shift.norm();

  // T = b^T (H + H P H)^+ b over the directions the pairs inform.
  const Eigen::Matrix3d S = H + H * rotation_covariance * H;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (S + S.transpose()));
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0.0)) return evidence;
  for (int k = 0; k < 3; ++k) {
    const double lambda = eigen.eigenvalues()(k);
    if (!(lambda > kRelativeRank * largest)) continue;
    ++evidence.dof;
    const double projection = eigen.eigenvectors().col(k).dot(b);
    evidence.statistic += projection * projection / lambda;
  }
  evidence.bound = chiSquareUpperQuantile(evidence.dof, false_alarm);
  evidence.contradicts = evidence.dof > 0 && evidence.statistic > evidence.bound;
  return evidence;
}

}  // namespace osc
