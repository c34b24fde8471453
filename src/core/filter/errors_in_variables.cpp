#include "online_stereo_calibration/core/filter/errors_in_variables.h"

#include <Eigen/LU>

namespace osc {

LinearStepMap linearizeStep(const HomogeneousStep& step, int inputs) {
  const auto map = [&](const Eigen::VectorXd& x) {
    Eigen::Matrix4d M;
    for (int j = 0; j < 4; ++j) M.col(j) = step(x, HomogeneousPoint::Unit(j));
    return M;
  };
  LinearStepMap linear;
  linear.at_zero = map(Eigen::VectorXd::Zero(inputs));
  linear.derivatives.resize(inputs);
  // The inputs are errors (m, rad, m/s): 1e-5 is far inside their sigmas, far above rounding.
  constexpr double kStep = 1e-5;
  for (int a = 0; a < inputs; ++a) {
    const Eigen::VectorXd dx = kStep * Eigen::VectorXd::Unit(inputs, a);
    linear.derivatives[a] = (map(dx) - map(-dx)) / (2.0 * kStep);
  }
  return linear;
}

std::array<Eigen::MatrixXd, 3> regressionGradient(const PointCoordinates& coordinates,
                                                  const LinearStepMap& map,
                                                  const Eigen::Vector3d& point,
                                                  const std::vector<int>& columns, int global_dim) {
  // c(m) = N m / (n^T m) of the moved point m = M(x) h; B_a = Pi(m) M_a h with
  // Pi = (N - c n^T) / (n^T m), and its derivative along delta = M(0) dh:
  // dPi = -((Pi delta) n^T + Pi (n^T delta)) / (n^T m).
  const Eigen::Matrix<double, 3, 4> N = coordinates.homogeneousNumerator();
  const Eigen::Vector4d n = coordinates.homogeneousDenominator();
  const HomogeneousPoint h = coordinates.homogeneous(point);
  const Eigen::Vector4d m = map.at_zero * h;
  const double denominator = n.dot(m);
  const Eigen::Matrix<double, 3, 4> Pi = (N - (N * m / denominator) * n.transpose()) / denominator;
  std::array<Eigen::MatrixXd, 3> gradient;
  for (int k = 0; k < 3; ++k) {
    // homogeneous() is linear in the coordinates (either kind), so this difference is exact.
    const Eigen::Vector4d dh = coordinates.homogeneous(point + Eigen::Vector3d::Unit(k)) - h;
    const Eigen::Vector4d delta = map.at_zero * dh;
    const Eigen::Matrix<double, 3, 4> dPi =
        -((Pi * delta) * n.transpose() + Pi * n.dot(delta)) / denominator;
    gradient[k] = Eigen::MatrixXd::Zero(3, global_dim);
    for (size_t a = 0; a < columns.size(); ++a) {
      const Eigen::Matrix4d& M_a = map.derivatives[a];
      gradient[k].col(columns[a]) = dPi * (M_a * h) + Pi * (M_a * dh);
    }
  }
  return gradient;
}

Eigen::VectorXd errorsInVariablesScore(const std::array<Eigen::MatrixXd, 3>& gradient,
                                       const Eigen::Matrix<double, 4, 3>& H_p,
                                       const Eigen::Matrix4d& S0,
                                       const Eigen::Matrix3d& own_error_cross) {
  const Eigen::Matrix<double, 3, 4> HtSi = H_p.transpose() * S0.inverse();
  const Eigen::Matrix<double, 4, 3> residual_cross = H_p * own_error_cross;
  Eigen::VectorXd score = Eigen::VectorXd::Zero(gradient[0].cols());
  for (int k = 0; k < 3; ++k)
    score.noalias() += gradient[k].transpose() * (HtSi * residual_cross.col(k));
  return score;
}

}  // namespace osc
