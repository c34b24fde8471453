/// @file update_scores.h
/// @brief What one update's innovations say against the filter's model: the score of a shift
/// of the global error beyond its prior, and the statistics built on it. The consistency
/// monitor (consistency_monitor.h) tests the calibration blocks with them, the odometry noise
/// matcher (odometry_noise_matcher.h) the step's motion error.
///
/// For a linearised update r = J dg + n with dg ~ N(0, P) and n ~ N(0, S0), the score of "dg is
/// shifted by delta beyond its prior" at delta = 0 is g = J^T S^-1 r with S = J P J^T + S0,
/// and Cov(g) = F = J^T S^-1 J. From the update's information, without inverting P:
///   A = sum J_i^T S0_i^-1 J_i,  b = sum J_i^T S0_i^-1 r_i,  P+ = (P^-1 + A)^-1,
///   g = b - A P+ b,  F = A - A P+ A   (P+ b: the update's correction of the mean).
/// For an index set S, T_S = g_S^T F_SS^+ g_S ~ chi2(rank F_SS) under the model; with the
/// other indices O free too (a partial score), T_{S|O} = T_{S+O} - T_O ~ chi2(rank difference).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace osc {

/// Upper quantile of chi-square with `dof` degrees of freedom: P(X > q) = probability
/// (Wilson-Hilferty; within 1 % for dof >= 10 at probability >= 1e-6).
double chiSquareUpperQuantile(double dof, double probability);

/// Upper standard normal quantile: P(Z > z) = probability.
double normalUpperQuantile(double probability);

/// first, first + 1, ..., first + count - 1.
std::vector<int> indexRange(int first, int count);

/// g_S^T F_SS^+ g_S over the index set S, and the rank of F_SS. F is scaled to unit diagonal
/// first (its blocks mix metres and radians); eigenvalues at or below 1e-9 of the largest
/// count as zero: directions the update carries (relatively) no information on.
double scoreStatistic(const Eigen::MatrixXd& F, const Eigen::VectorXd& g,
                      const std::vector<int>& indices, int* rank);

/// The pseudo-inverse of a symmetric PSD F with scoreStatistic's scaling and rank tolerance.
Eigen::MatrixXd scaledPseudoInverse(const Eigen::MatrixXd& F);

/// The score g and its covariance F of a shift of the global error (file comment).
struct GlobalScore {
  Eigen::VectorXd score;        ///< g
  Eigen::MatrixXd information;  ///< F = Cov(g) under the model
  Eigen::VectorXd correction;   ///< P+ b, the update's correction of the mean
};
/// @param information A = sum J_i^T S0_i^-1 J_i (G x G)
/// @param score b = sum J_i^T S0_i^-1 r_i (G)
/// @param posterior_covariance P+ = (P^-1 + A)^-1 (G x G)
GlobalScore globalScore(const Eigen::MatrixXd& information, const Eigen::VectorXd& score,
                        const Eigen::MatrixXd& posterior_covariance);

/// One update's evidence on the calibration: the score of its shift and its covariance, and
/// what no shift of the global error explains.
struct UpdateScores {
  Eigen::Matrix<double, 12, 1> score =
      Eigen::Matrix<double, 12, 1>::Zero();  ///< g (x_caml, x_camr)
  Eigen::Matrix<double, 12, 12> information =
      Eigen::Matrix<double, 12, 12>::Zero();  ///< F = Cov(g) under the model
  double rest = 0.0;                          ///< T_rest = r^T S^-1 r - g^T F^+ g
  int rest_dof = 0;                           ///< 4 N - rank(F of the global error)
};

/// The evidence of one linearised update. The global error has G dimensions with x_caml at 0,
/// x_camr at 6 (state_layout.h).
/// @param global globalScore(A, b, P+) of the update
/// @param score b = sum J_i^T S0_i^-1 r_i (G)
/// @param residual_norm sum r_i^T S0_i^-1 r_i
/// @param measurement_dof 4 N
UpdateScores computeUpdateScores(const GlobalScore& global, const Eigen::VectorXd& score,
                                 double residual_norm, int measurement_dof);

/// One update's evidence on the step's motion error e (the last 6 entries of the global error:
/// translation, then rotation), per part p (0 translation, 1 rotation), with every other entry
/// of the global error free: the partial statistic T_p, its degrees of freedom, and
/// growth_p = tr(Q_p F_{p|o}). If e's true covariance is its prior plus (k - 1) Q_p on part p
/// (Q: the configured motion noise, applied times `applied_factor`), then
/// E[T_p] = dof_p + (k - applied_factor_p) growth_p: the window's T and growth give k.
struct MotionNoiseEvidence {
  std::array<double, 2> statistic = {0.0, 0.0};
  std::array<int, 2> dof = {0, 0};
  std::array<double, 2> growth = {0.0, 0.0};
  std::array<double, 2> applied_factor = {1.0, 1.0};
};

/// @param global the update's GlobalScore, with the motion error last
/// @param motion_noise Q, the configured covariance of the step's motion error (6 x 6)
/// @param applied_factor the factors Q_p was multiplied by in this step's prediction
MotionNoiseEvidence motionNoiseEvidence(const GlobalScore& global,
                                        const Eigen::Matrix<double, 6, 6>& motion_noise,
                                        const std::array<double, 2>& applied_factor);

}  // namespace osc
