#include "online_stereo_calibration/core/filter/update_tempering.h"

#include <algorithm>
#include <cmath>
#include <limits>
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
  if (measurements.empty()) return 1.0;
  limited = std::min(limited, static_cast<int>(P.rows()));
  // The largest allowed prior / posterior variance ratio of each limited component.
  Eigen::VectorXd bound = Eigen::VectorXd::Constant(
      limited,
      max_shrink > 1.0 ? max_shrink * max_shrink : std::numeric_limits<double>::infinity());
  if (!(bound.minCoeff() < std::numeric_limits<double>::infinity())) return 1.0;
  // A bound at 1 (no shrink allowed) holds the update back: S0 scaled so far up that it
  // changes nothing measurable.
  constexpr double kHeldBack = 1e12;
  double alpha = 1.0;
  constexpr int kSteps = 4;
  for (int step = 0; step < kSteps; ++step) {
    const Eigen::MatrixXd Q = updatedCovariance(P, measurements, alpha);
    double factor = 1.0;  // by which alpha must grow for the most violated bound
    for (int k = 0; k < limited; ++k) {
      if (!(Q(k, k) > 0.0 && P(k, k) > 0.0)) continue;
      const double ratio = P(k, k) / Q(k, k);
      if (!(ratio > bound(k) * (1.0 + 1e-6))) continue;
      // One dimension: P / Q = 1 + I P / alpha, so alpha' = alpha (ratio - 1) / (bound - 1)
      // gives exactly the bound.
      factor = bound(k) - 1.0 > 1e-9 ? std::max(factor, (ratio - 1.0) / (bound(k) - 1.0))
                                     : std::numeric_limits<double>::infinity();
    }
    if (!(factor > 1.0)) break;
    alpha = std::min(alpha * factor, kHeldBack);
    if (alpha >= kHeldBack) break;
  }
  return alpha;
}

}  // namespace osc
