/// @file unscented_transform.h
/// @brief The scaled unscented transform (Julier 2002) and the statistical linear
/// regression it implies: y = f(x) is replaced by y ~ mean + A (x - x_mean) + e with
/// Cov(e) = the part of Cov(y) the regression does not explain.
///
/// The filter uses the regression form so that a UKF step on one point's small joint
/// state (e.g. x_caml and the point) can be applied exactly to the structured covariance.
#pragma once

#include <functional>

#include <Eigen/Core>

namespace osc {

/// Scaled UT parameters (alpha, beta, kappa).
struct UnscentedParameters {
  double alpha = 0.5;
  double beta = 2.0;
  double kappa = 0.0;
};

/// Weights and spread of the 2L+1 scaled sigma points of an L-dimensional Gaussian.
struct UnscentedWeights {
  double gamma = 0.0;        ///< sigma points at mean +- gamma * column of sqrt(P)
  double mean_center = 0.0;  ///< W0^(m)
  double cov_center = 0.0;   ///< W0^(c)
  double other = 0.0;        ///< Wi^(m) = Wi^(c), i >= 1
};
UnscentedWeights unscentedWeights(int dimension, const UnscentedParameters& parameters);

/// y = f(x); returns false if x is outside f's domain (e.g. a point behind a camera).
using VectorFunction = std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd* y)>;

/// Outcome of unscentedTransform.
struct UnscentedResult {
  Eigen::VectorXd mean;        ///< E[y]
  Eigen::MatrixXd covariance;  ///< Cov(y)
  Eigen::MatrixXd cross;       ///< Cov(y, x)
  Eigen::MatrixXd jacobian;    ///< A = Cov(y, x) Cov(x)^-1 (statistical linearisation)
  Eigen::MatrixXd residual;    ///< Cov(y) - A Cov(x) A^T, made symmetric PSD
  bool repaired_input = false; ///< Cov(x) was not PD and was repaired before use
};

/// Propagates N(mean, covariance) through f with the scaled unscented transform.
/// Returns false if f fails on any sigma point or the covariance is not finite.
/// With compute_regression = false, jacobian and residual are left empty (saves O(L^3)).
bool unscentedTransform(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance,
                        const VectorFunction& f, const UnscentedParameters& parameters,
                        UnscentedResult* result, bool compute_regression = true);

/// A square root S with S S^T = P (Cholesky); if P is not numerically PD, the symmetric
/// eigen-decomposition with eigenvalues clamped at a small positive floor is used and
/// *repaired is set. Returns false only for non-finite P.
bool matrixSquareRoot(const Eigen::MatrixXd& P, Eigen::MatrixXd* S, bool* repaired);

/// Symmetrises P and clamps its eigenvalues to >= floor. Returns true if it changed
/// more than rounding (i.e. P was not symmetric PSD).
bool makeSymmetricPsd(Eigen::MatrixXd* P, double floor = 0.0);

}  // namespace osc
