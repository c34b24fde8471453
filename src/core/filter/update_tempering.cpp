#include "online_stereo_calibration/core/filter/update_tempering.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Cholesky>

namespace osc {

bool sequentialGain(const Eigen::MatrixXd& P, const LinearizedMeasurement& measurement,
                    double alpha, Eigen::MatrixXd* PJt, Eigen::MatrixXd* K) {
  Eigen::MatrixXd cross = P * measurement.J->transpose();
  const Eigen::Matrix4d S = *measurement.J * cross + alpha * *measurement.S0;
  const Eigen::LLT<Eigen::Matrix4d> S_llt(S);
  if (S_llt.info() != Eigen::Success || !S.allFinite()) return false;
  Eigen::MatrixXd gain = S_llt.solve(cross.transpose()).transpose();
  if (!gain.allFinite()) return false;
  *PJt = std::move(cross);
  *K = std::move(gain);
  return true;
}

namespace {

/// P after the filter's sequential updates with S0 scaled by @p alpha.
Eigen::MatrixXd updatedCovariance(const Eigen::MatrixXd& P,
                                  const std::vector<LinearizedMeasurement>& measurements,
                                  double alpha) {
  Eigen::MatrixXd Q = P;
  Eigen::MatrixXd QJt, K;
  for (const LinearizedMeasurement& m : measurements) {
    if (sequentialGain(Q, m, alpha, &QJt, &K)) Q.noalias() -= K * QJt.transpose();
  }
  return Q;
}

}  // namespace

double updateTempering(const Eigen::MatrixXd& P,
                       const std::vector<LinearizedMeasurement>& measurements, int limited,
                       double max_shrink) {
  if (!(max_shrink > 1.0) || measurements.empty()) return 1.0;
  const double bound = max_shrink * max_shrink;  // on the variance ratio
  limited = std::min(limited, static_cast<int>(P.rows()));
  double alpha = 1.0;
  constexpr int kSteps = 4;
  for (int step = 0; step < kSteps; ++step) {
    const Eigen::MatrixXd Q = updatedCovariance(P, measurements, alpha);
    double ratio = 1.0;  // largest prior / posterior variance
    for (int k = 0; k < limited; ++k) {
      if (Q(k, k) > 0.0 && P(k, k) > 0.0) ratio = std::max(ratio, P(k, k) / Q(k, k));
    }
    if (!(ratio > bound * (1.0 + 1e-6))) break;
    // One dimension: P / Q = 1 + I P / alpha, so alpha' = alpha (ratio - 1) / (bound - 1)
    // gives exactly the bound.
    alpha *= (ratio - 1.0) / (bound - 1.0);
  }
  return alpha;
}

}  // namespace osc
