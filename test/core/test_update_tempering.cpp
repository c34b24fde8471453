// Update tempering (update_tempering.h): one strong measurement shrinks a sigma by exactly the
// bound, an update within the bound or on unlimited states is not tempered, and correlated
// states of many points stay near the bound; checked against the sequential update written out.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/filter/update_tempering.h"

namespace osc {
namespace {

/// The posterior covariance of the sequential update with S0 scaled by @p alpha.
Eigen::MatrixXd temperedPosterior(const Eigen::MatrixXd& P, const std::vector<Eigen::MatrixXd>& J,
                                  const std::vector<Eigen::Matrix4d>& S0, double alpha) {
  Eigen::MatrixXd Q = P;
  for (size_t i = 0; i < J.size(); ++i) {
    const Eigen::MatrixXd QJt = Q * J[i].transpose();
    const Eigen::Matrix4d S = J[i] * QJt + alpha * S0[i];
    Q -= QJt * S.llt().solve(QJt.transpose());
  }
  return Q;
}

std::vector<LinearizedMeasurement> linearized(const std::vector<Eigen::MatrixXd>& J,
                                              const std::vector<Eigen::Matrix4d>& S0) {
  std::vector<LinearizedMeasurement> measurements;
  for (size_t i = 0; i < J.size(); ++i) measurements.push_back({&J[i], &S0[i]});
  return measurements;
}

TEST(UpdateTempering, OneStrongMeasurementShrinksASigmaByExactlyTheBound) {
  // sigma 10 measured with sigma 0.1: untempered the sigma shrinks 100-fold.
  const Eigen::MatrixXd P = Eigen::MatrixXd::Constant(1, 1, 100.0);
  const std::vector<Eigen::MatrixXd> J = {Eigen::MatrixXd::Constant(4, 1, 1.0)};
  const std::vector<Eigen::Matrix4d> S0 = {0.01 * Eigen::Matrix4d::Identity()};
  const double alpha = updateTempering(P, linearized(J, S0), 1, 3.0);
  EXPECT_GT(alpha, 100.0);
  const double shrink = std::sqrt(P(0, 0) / temperedPosterior(P, J, S0, alpha)(0, 0));
  EXPECT_NEAR(shrink, 3.0, 1e-6);
  EXPECT_EQ(updateTempering(P, linearized(J, S0), 1, 0.0), 1.0);  // off
}

TEST(UpdateTempering, AnUpdateWithinTheBoundOrOnUnlimitedStatesIsNotTempered) {
  const Eigen::MatrixXd P = Eigen::Vector2d(1.0, 1.0).asDiagonal();
  std::vector<Eigen::MatrixXd> J = {Eigen::MatrixXd::Zero(4, 2)};
  J[0].col(0).setOnes();  // measures state 0 four times with sigma 1: it shrinks by sqrt(5)
  const std::vector<Eigen::Matrix4d> S0 = {Eigen::Matrix4d::Identity()};
  EXPECT_EQ(updateTempering(P, linearized(J, S0), 2, 3.0), 1.0);
  EXPECT_GT(updateTempering(P, linearized(J, S0), 2, 2.0), 1.0);
  // The same measurement of state 1 only, when only state 0 is limited.
  J[0].setZero();
  J[0].col(1).setOnes();
  EXPECT_EQ(updateTempering(P, linearized(J, S0), 1, 2.0), 1.0);
}

TEST(UpdateTempering, CorrelatedStatesOfManyPointsStayNearTheBound) {
  // Six correlated states, 50 random measurements 1000 times more precise than the prior:
  // every limited sigma shrinks by at most the bound (a little above it for correlated
  // states), and at least one by nearly as much.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(6, 6);
  for (int i = 0; i < A.size(); ++i) A(i) = normal(rng);
  const Eigen::MatrixXd P = A * A.transpose() + Eigen::MatrixXd::Identity(6, 6);
  std::vector<Eigen::MatrixXd> J;
  std::vector<Eigen::Matrix4d> S0;
  for (int k = 0; k < 50; ++k) {
    Eigen::MatrixXd Jk(4, 6);
    for (int i = 0; i < Jk.size(); ++i) Jk(i) = normal(rng);
    J.push_back(Jk);
    S0.push_back(1e-3 * Eigen::Matrix4d::Identity());
  }
  const double alpha = updateTempering(P, linearized(J, S0), 6, 3.0);
  const Eigen::MatrixXd Q = temperedPosterior(P, J, S0, alpha);
  double largest = 0.0;
  for (int k = 0; k < 6; ++k) largest = std::max(largest, std::sqrt(P(k, k) / Q(k, k)));
  EXPECT_LT(largest, 3.0 * 1.05);
  EXPECT_GT(largest, 3.0 * 0.9);
  const Eigen::MatrixXd untempered = temperedPosterior(P, J, S0, 1.0);
  EXPECT_GT(std::sqrt(P(0, 0) / untempered(0, 0)), 30.0);  // what it prevents
}

}  // namespace
}  // namespace osc
