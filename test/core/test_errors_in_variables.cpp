// The errors-in-variables compensation (errors_in_variables.h): the regression's gradient
// against numerical derivatives, and the score against the bias it compensates, measured by
// sampling a point's error. (Its effect on the baseline of a weak-stereo rig is in
// test_campaign.cpp.)
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/filter/errors_in_variables.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {
namespace {

/// A step like the filter's: the camera moves by T0 (0.2 m sideways, 1.5 deg of yaw), the
/// inputs are its pose error (6) and the baseline's relative error (1), by which the stored
/// inverse depth is divided (points in units of the baseline).
HomogeneousPoint movedByStep(const Eigen::VectorXd& x, const HomogeneousPoint& h) {
  Vector6d motion;
  motion << 0.2, 0.01, 0.03, 0.002, 0.026, -0.004;
  const Eigen::Isometry3d T = boxPlus(expSE3(motion), x.head<6>());
  const double scale = 1.0 - x(6);
  HomogeneousPoint moved;
  moved << T.linear() * h.head<3>() + T.translation() * h.w() * scale, h.w();
  return moved;
}

/// The coordinates of @p point moved by the step with inputs @p x.
Eigen::Vector3d moved(const PointCoordinates& c, const Eigen::Vector3d& point,
                      const Eigen::VectorXd& x) {
  Eigen::Vector3d out;
  EXPECT_TRUE(c.fromHomogeneous(movedByStep(x, c.homogeneous(point)), &out));
  return out;
}

/// B = d moved / d x at x = 0 (3 x 7), by central differences.
Eigen::MatrixXd regression(const PointCoordinates& c, const Eigen::Vector3d& point) {
  Eigen::MatrixXd B(3, 7);
  const double h = 1e-6;
  for (int a = 0; a < 7; ++a) {
    const Eigen::VectorXd dx = h * Eigen::VectorXd::Unit(7, a);
    B.col(a) = (moved(c, point, dx) - moved(c, point, -dx)) / (2.0 * h);
  }
  return B;
}

/// F_p = d moved / d point at x = 0, by central differences.
Eigen::Matrix3d pointJacobian(const PointCoordinates& c, const Eigen::Vector3d& point) {
  Eigen::Matrix3d F;
  const double h = 1e-6;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d dp = h * Eigen::Vector3d::Unit(k);
    F.col(k) = (moved(c, point + dp, zero) - moved(c, point - dp, zero)) / (2.0 * h);
  }
  return F;
}

Eigen::Vector3d examplePoint(const PointCoordinates& c) {
  // 12 m ahead, a little left and up, in units of a 0.12 m baseline.
  return c.fromPosition(Eigen::Vector3d(-2.0, -0.5, 12.0) / 0.12);
}

TEST(ErrorsInVariables, TheGradientIsTheDerivativeOfTheRegressionInItsColumns) {
  // The inputs sit in columns 2..8 of a 10-wide global error: the rest stays zero.
  const std::vector<int> columns = {2, 3, 4, 5, 6, 7, 8};
  const LinearStepMap map = linearizeStep(movedByStep, 7);
  for (const bool inverse_depth : {true, false}) {
    const PointCoordinates c(inverse_depth);
    const Eigen::Vector3d point = examplePoint(c);
    const std::array<Eigen::MatrixXd, 3> gradient = regressionGradient(c, map, point, columns, 10);
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-4 * std::max(std::abs(point(k)), 1e-2);
      const Eigen::Vector3d dp = h * Eigen::Vector3d::Unit(k);
      const Eigen::MatrixXd numeric =
          (regression(c, point + dp) - regression(c, point - dp)) / (2.0 * h);
      ASSERT_EQ(gradient[k].rows(), 3);
      ASSERT_EQ(gradient[k].cols(), 10);
      EXPECT_EQ(gradient[k].leftCols(2).norm(), 0.0);
      EXPECT_EQ(gradient[k].col(9).norm(), 0.0);
      const Eigen::MatrixXd analytic = gradient[k].middleCols(2, 7);
      EXPECT_LT((analytic - numeric).norm(), 1e-4 * (numeric.norm() + 1.0))
          << (inverse_depth ? "inverse depth" : "position") << ", coordinate " << k
          << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
    }
  }
}

TEST(ErrorsInVariables, TheScoreIsTheBiasOfRegressingOnANoisyPoint) {
  // A point known only from a 0.12 m rig's stereo (0.7 px of disparity noise at 600 px) is
  // moved and measured; the update regresses the residual on the global error with J
  // evaluated at the point's estimate p - e. Averaged over e, J(p - e)^T S0^-1 r(e) is what
  // errorsInVariablesScore says, with the opposite sign (the linear part of r, at the true
  // global error 0, averages out; antithetic pairs e, -e cancel it exactly).
  const PointCoordinates c(true);
  const Eigen::Vector3d point = examplePoint(c);
  const LinearStepMap map = linearizeStep(movedByStep, 7);
  const std::vector<int> columns = {0, 1, 2, 3, 4, 5, 6};
  Eigen::Matrix<double, 4, 3> H_p;  // a stereo measurement of (a, b, rho): pixels
  H_p << 600, 0, 0,                 //
      0, 600, 0,                    //
      600, 0, -600,  // the right image: x shifted by the disparity f rho (rho in baselines)
      0, 600, 0;
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();  // the stereo point's error covariance
  const double pixel = 0.5 / 600.0, disparity = 0.7 / 600.0;
  D.diagonal() << pixel * pixel, pixel * pixel, disparity * disparity;
  const Eigen::Matrix3d F_p = pointJacobian(c, point);
  Eigen::Matrix4d S0 = H_p * F_p * D * F_p.transpose() * H_p.transpose();
  S0.diagonal().array() += 0.25;
  const Eigen::Matrix4d S0_inverse = S0.inverse();

  const Eigen::VectorXd expected =
      -errorsInVariablesScore(regressionGradient(c, map, point, columns, 7), H_p, S0, F_p * D);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  const Eigen::Matrix3d L = D.llt().matrixL();
  const Eigen::Vector3d truth_moved = moved(c, point, Eigen::VectorXd::Zero(7));
  const int pairs = 40000;
  std::vector<Eigen::MatrixXd> J;
  std::vector<Eigen::Vector4d> r;
  Eigen::Vector4d mean_r = Eigen::Vector4d::Zero();
  for (int i = 0; i < pairs; ++i) {
    const Eigen::Vector3d e = L * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d estimate = point - sign * e;
      J.push_back(H_p * regression(c, estimate));
      r.push_back(H_p * (truth_moved - moved(c, estimate, Eigen::VectorXd::Zero(7))));
      mean_r += r.back() / (2.0 * pairs);
    }
  }
  // The residual's mean (the step's curvature over D) is the filter's UT's: taken out.
  // 80000 samples: the products of two Gaussians average slowly (4000 pairs: 20 % off).
  Eigen::VectorXd sampled = Eigen::VectorXd::Zero(7);
  for (size_t i = 0; i < r.size(); ++i)
    sampled += J[i].transpose() * S0_inverse * (r[i] - mean_r) / static_cast<double>(r.size());
  // The camera's translation, the rotations and the baseline all carry the bias.
  ASSERT_GT(expected.norm(), 0.0);
  EXPECT_LT((sampled - expected).norm(), 0.05 * expected.norm())
      << "sampled " << sampled.transpose() << "\nexpected " << expected.transpose();
}

}  // namespace
}  // namespace osc
