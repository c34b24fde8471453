// Scaled unscented transform: exact on linear maps, close to a 1e5-sample Monte Carlo on a
// nonlinear one.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/filter/unscented_transform.h"

namespace osc {
namespace {

TEST(UnscentedTransform, WeightsSumToOne) {
  for (int L : {1, 3, 9, 15}) {
    const UnscentedWeights w = unscentedWeights(L, UnscentedParameters{0.5, 2.0, 0.0});
    EXPECT_NEAR(w.mean_center + 2 * L * w.other, 1.0, 1e-12);
  }
}

TEST(UnscentedTransform, LinearMapIsExact) {
  Eigen::MatrixXd A(2, 3);
  A << 1, 2, 3, -1, 0.5, 4;
  const Eigen::Vector2d b(0.3, -2);
  Eigen::MatrixXd P(3, 3);
  P << 2, 0.3, 0.1, 0.3, 1, -0.2, 0.1, -0.2, 0.5;
  const Eigen::Vector3d mean(1, -1, 2);
  UnscentedResult r;
  ASSERT_TRUE(unscentedTransform(
      mean, P,
      [&](const Eigen::VectorXd& x, Eigen::VectorXd* y) {
        *y = A * x + b;
        return true;
      },
      UnscentedParameters{}, &r));
  EXPECT_TRUE(r.mean.isApprox(A * mean + b, 1e-10));
  EXPECT_TRUE(r.covariance.isApprox(A * P * A.transpose(), 1e-10));
  EXPECT_TRUE(r.cross.isApprox(A * P, 1e-10));
  EXPECT_TRUE(r.jacobian.isApprox(A, 1e-10));
  EXPECT_LT(r.residual.norm(), 1e-9);
}

// Polar -> Cartesian with a large angular spread: the classic case where linearisation
// fails and the UT tracks the true mean and covariance.
TEST(UnscentedTransform, MatchesMonteCarloOnPolarToCartesian) {
  const Eigen::Vector2d mean(10.0, 0.5);  // range, bearing
  Eigen::Matrix2d P;
  P << 0.5 * 0.5, 0.0, 0.0, 0.3 * 0.3;
  const auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd* y) {
    y->resize(2);
    *y << x(0) * std::cos(x(1)), x(0) * std::sin(x(1));
    return true;
  };
  UnscentedResult r;
  ASSERT_TRUE(unscentedTransform(mean, P, f, UnscentedParameters{1.0, 2.0, 0.0}, &r));

  std::mt19937_64 rng(42);
  std::normal_distribution<double> n01;
  const int samples = 100000;
  Eigen::Vector2d mc_mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d mc_cov = Eigen::Matrix2d::Zero();
  std::vector<Eigen::Vector2d> ys(samples);
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector2d x(mean(0) + 0.5 * n01(rng), mean(1) + 0.3 * n01(rng));
    Eigen::VectorXd y;
    f(x, &y);
    ys[s] = y;
    mc_mean += y;
  }
  mc_mean /= samples;
  for (const auto& y : ys) mc_cov += (y - mc_mean) * (y - mc_mean).transpose();
  mc_cov /= samples - 1;
  // The linearised mean would be (8.78, 4.79); the true mean is pulled inwards by ~4 %.
  EXPECT_NEAR(r.mean(0), mc_mean(0), 0.05);
  EXPECT_NEAR(r.mean(1), mc_mean(1), 0.05);
  // Second-order accurate: within 10 % of the Monte Carlo covariance, and closer to it than
  // the first-order (EKF) propagation J P J^T.
  Eigen::Matrix2d J;
  J << std::cos(0.5), -10 * std::sin(0.5), std::sin(0.5), 10 * std::cos(0.5);
  const Eigen::Matrix2d linear_cov = J * P * J.transpose();
  EXPECT_LT((r.covariance - mc_cov).norm(), 0.10 * mc_cov.norm());
  EXPECT_LT((r.covariance - mc_cov).norm(), (linear_cov - mc_cov).norm());
  const Eigen::Vector2d linearised(10 * std::cos(0.5), 10 * std::sin(0.5));
  EXPECT_GT((linearised - mc_mean).norm(), 0.3);  // the test would catch a linearisation
}

TEST(UnscentedTransform, FailingFunctionIsReported) {
  UnscentedResult r;
  EXPECT_FALSE(unscentedTransform(
      Eigen::VectorXd::Zero(2), Eigen::MatrixXd::Identity(2, 2),
      [](const Eigen::VectorXd& x, Eigen::VectorXd* y) {
        *y = x;
        return x(0) < 0.1;
      },
      UnscentedParameters{}, &r));
}

TEST(UnscentedTransform, NonPdCovarianceIsRepairedNotFatal) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(2, 2);
  P(0, 0) = 1.0;  // second variable has zero variance
  UnscentedResult r;
  ASSERT_TRUE(unscentedTransform(
      Eigen::VectorXd::Zero(2), P,
      [](const Eigen::VectorXd& x, Eigen::VectorXd* y) {
        *y = 2 * x;
        return true;
      },
      UnscentedParameters{}, &r));
  EXPECT_TRUE(r.repaired_input);
  EXPECT_NEAR(r.covariance(0, 0), 4.0, 1e-9);
  EXPECT_TRUE(r.covariance.allFinite());
}

TEST(UnscentedTransform, NanCovarianceIsRejected) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(2, 2);
  P(1, 1) = std::nan("");
  UnscentedResult r;
  EXPECT_FALSE(unscentedTransform(
      Eigen::VectorXd::Zero(2), P,
      [](const Eigen::VectorXd& x, Eigen::VectorXd* y) {
        *y = x;
        return true;
      },
      UnscentedParameters{}, &r));
}

}  // namespace
}  // namespace osc
