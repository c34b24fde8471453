#include "online_stereo_calibration/core/filter/unscented_transform.h"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace osc {

UnscentedWeights unscentedWeights(int dimension, const UnscentedParameters& p) {
  const double L = static_cast<double>(dimension);
  const double lambda = p.alpha * p.alpha * (L + p.kappa) - L;
  UnscentedWeights w;
  w.gamma = std::sqrt(L + lambda);
  w.mean_center = lambda / (L + lambda);
  w.cov_center = w.mean_center + (1.0 - p.alpha * p.alpha + p.beta);
  w.other = 1.0 / (2.0 * (L + lambda));
  return w;
}

bool makeSymmetricPsd(Eigen::MatrixXd* P, double floor) {
  const Eigen::MatrixXd symmetric = 0.5 * (*P + P->transpose());
  const double asymmetry = (symmetric - *P).cwiseAbs().maxCoeff();
  *P = symmetric;
  Eigen::LLT<Eigen::MatrixXd> llt(*P);
  if (llt.info() == Eigen::Success && floor <= 0.0) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(*P);
  const Eigen::VectorXd values = eigen.eigenvalues();
  if (values.minCoeff() >= floor) return false;
  const Eigen::VectorXd clamped = values.cwiseMax(floor);
  *P = eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
  const double scale = std::max(1e-300, values.cwiseAbs().maxCoeff());
  return (clamped - values).maxCoeff() > 1e-12 * scale || asymmetry > 1e-12 * scale;
}

bool matrixSquareRoot(const Eigen::MatrixXd& P, Eigen::MatrixXd* S, bool* repaired) {
  *repaired = false;
  if (!P.allFinite()) return false;
  Eigen::LLT<Eigen::MatrixXd> llt(P);
  if (llt.info() == Eigen::Success) {
    *S = llt.matrixL();
    return true;
  }
  // Not PD (a zero-variance input, or rounding): clamp the spectrum at a floor relative to
  // the largest variance so that the sigma points stay finite and distinct.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (P + P.transpose()));
  const double floor = 1e-14 * std::max(1e-300, eigen.eigenvalues().cwiseAbs().maxCoeff());
  const Eigen::VectorXd roots = eigen.eigenvalues().cwiseMax(floor).cwiseSqrt();
  *S = eigen.eigenvectors() * roots.asDiagonal();
  *repaired = true;
  return true;
}

bool unscentedTransform(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance,
                        const VectorFunction& f, const UnscentedParameters& parameters,
                        UnscentedResult* result, bool compute_regression) {
  const int L = static_cast<int>(mean.size());
  Eigen::MatrixXd S;
  if (!mean.allFinite() || !matrixSquareRoot(covariance, &S, &result->repaired_input)) return false;
  const UnscentedWeights w = unscentedWeights(L, parameters);

  // Evaluate f at the 2L+1 sigma points (Julier 2002, eq. 12-13).
  Eigen::VectorXd y0;
  if (!f(mean, &y0) || !y0.allFinite()) return false;
  const int M = static_cast<int>(y0.size());
  Eigen::MatrixXd Y(M, 2 * L);
  Eigen::VectorXd y;
  for (int k = 0; k < L; ++k) {
    const Eigen::VectorXd offset = w.gamma * S.col(k);
    if (!f(mean + offset, &y) || !y.allFinite()) return false;
    Y.col(k) = y;
    if (!f(mean - offset, &y) || !y.allFinite()) return false;
    Y.col(L + k) = y;
  }

  result->mean = w.mean_center * y0 + w.other * Y.rowwise().sum();
  const Eigen::VectorXd d0 = y0 - result->mean;
  const Eigen::MatrixXd D = Y.colwise() - result->mean;
  result->covariance = w.cov_center * d0 * d0.transpose() + w.other * D * D.transpose();
  // Cov(y, x): the input deviations are +-gamma*S(:,k); the centre point has none.
  result->cross = w.other * w.gamma * (D.leftCols(L) - D.rightCols(L)) * S.transpose();

  if (!compute_regression) return result->mean.allFinite() && result->covariance.allFinite();

  // Statistical linearisation A = Cov(y,x) Cov(x)^-1 = Cov(y,x) S^-T S^-1.
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(L, L);
  const Eigen::MatrixXd S_inv =
      result->repaired_input ? Eigen::MatrixXd(S.inverse())
                             : Eigen::MatrixXd(S.triangularView<Eigen::Lower>().solve(identity));
  result->jacobian = result->cross * S_inv.transpose() * S_inv;
  result->residual =
      result->covariance - result->jacobian * covariance * result->jacobian.transpose();
  makeSymmetricPsd(&result->residual, 0.0);
  return result->mean.allFinite() && result->covariance.allFinite() && result->jacobian.allFinite();
}

}  // namespace osc
