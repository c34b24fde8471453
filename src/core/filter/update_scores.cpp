#include "online_stereo_calibration/core/filter/update_scores.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace osc {
namespace {

/// A symmetric PSD F scaled to unit diagonal, D F D with D = diag(1 / sqrt(F_aa)) (0 where
/// F_aa <= 0): the blocks mix metres and radians. Its eigenvalues at or below 1e-9 of the
/// largest count as zero: directions the update carries (relatively) no information on.
struct ScaledEigen {
  explicit ScaledEigen(const Eigen::MatrixXd& F) : scale(F.diagonal().cwiseMax(0.0).cwiseSqrt()) {
    for (int a = 0; a < scale.size(); ++a) scale(a) = scale(a) > 0.0 ? 1.0 / scale(a) : 0.0;
    eigen.compute(scale.asDiagonal() * F * scale.asDiagonal());
    largest = eigen.eigenvalues().maxCoeff();
  }
  bool informative(int k) const { return largest > 0.0 && eigen.eigenvalues()(k) > 1e-9 * largest; }

  Eigen::VectorXd scale;  ///< D's diagonal
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen;
  double largest = 0.0;
};

}  // namespace

// By bisection on erfc.
double normalUpperQuantile(double probability) {
  double lo = -40.0, hi = 40.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / M_SQRT2) > probability) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

double chiSquareUpperQuantile(double dof, double probability) {
  if (!(dof > 0.0)) return 0.0;
  // Wilson-Hilferty: (X / k)^(1/3) is close to normal with mean 1 - 2/(9k), var 2/(9k).
  const double v = 2.0 / (9.0 * dof);
  const double root = 1.0 - v + normalUpperQuantile(probability) * std::sqrt(v);
  return dof * std::max(root, 0.0) * root * root;
}

std::vector<int> indexRange(int first, int count) {
  std::vector<int> r(count);
  for (int k = 0; k < count; ++k) r[k] = first + k;
  return r;
}

double scoreStatistic(const Eigen::MatrixXd& F, const Eigen::VectorXd& g,
                      const std::vector<int>& indices, int* rank) {
  const int n = static_cast<int>(indices.size());
  Eigen::MatrixXd F_s(n, n);
  Eigen::VectorXd g_s(n);
  for (int a = 0; a < n; ++a) {
    g_s(a) = g(indices[a]);
    for (int b = 0; b < n; ++b) F_s(a, b) = F(indices[a], indices[b]);
  }
  const ScaledEigen scaled(F_s);
  g_s = scaled.scale.asDiagonal() * g_s;
  double value = 0.0;
  *rank = 0;
  for (int k = 0; k < n; ++k) {
    if (!scaled.informative(k)) continue;
    const double projection = scaled.eigen.eigenvectors().col(k).dot(g_s);
    value += projection * projection / scaled.eigen.eigenvalues()(k);
    ++*rank;
  }
  return value;
}

Eigen::MatrixXd scaledPseudoInverse(const Eigen::MatrixXd& F) {
  const ScaledEigen scaled(F);
  const int n = static_cast<int>(F.rows());
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    if (scaled.informative(k)) inverse(k) = 1.0 / scaled.eigen.eigenvalues()(k);
  }
  const Eigen::MatrixXd& V = scaled.eigen.eigenvectors();
  return scaled.scale.asDiagonal() * (V * inverse.asDiagonal() * V.transpose()) *
         scaled.scale.asDiagonal();
}

GlobalScore globalScore(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                        const Eigen::MatrixXd& P_post) {
  GlobalScore global;
  global.correction = P_post * b;
  global.score = b - A * global.correction;
  const Eigen::MatrixXd F = A - A * P_post * A;
  global.information = 0.5 * (F + F.transpose());
  return global;
}

UpdateScores computeUpdateScores(const GlobalScore& global, const Eigen::VectorXd& b,
                                 double residual_norm, int measurement_dof) {
  UpdateScores scores;
  const int G = static_cast<int>(b.size());
  const Eigen::VectorXd& g = global.score;
  const Eigen::MatrixXd& F = global.information;
  scores.score = g.head<12>();
  scores.information = F.topLeftCorner<12, 12>();
  // Total NIS of the update, r^T S^-1 r by Woodbury, less what the global block explains.
  int rank_all = 0;
  const double t_all = scoreStatistic(F, g, indexRange(0, G), &rank_all);
  const double total = residual_norm - b.dot(global.correction);
  scores.rest = std::max(total - t_all, 0.0);
  scores.rest_dof = std::max(measurement_dof - rank_all, 0);
  return scores;
}

MotionNoiseEvidence motionNoiseEvidence(const GlobalScore& global,
                                        const Eigen::Matrix<double, 6, 6>& motion_noise,
                                        const std::array<double, 2>& applied_factor) {
  MotionNoiseEvidence evidence;
  evidence.applied_factor = applied_factor;
  const int motion = static_cast<int>(global.score.size()) - 6;
  for (int part = 0; part < 2; ++part) {
    const int first = motion + 3 * part;
    evidence.statistic[part] =
        scoreStatistic(global.information, global.score, indexRange(first, 3), &evidence.dof[part]);
    evidence.growth[part] = std::max((motion_noise.block<3, 3>(3 * part, 3 * part) *
                                      global.information.block<3, 3>(first, first))
                                         .trace(),
                                     0.0);
  }
  return evidence;
}

}  // namespace osc
