/// @file update_tempering.h
/// @brief How much to temper one update so that no calibration sigma shrinks by more than a
/// given factor (issue 14: "no collapse on thin evidence").
///
/// A Kalman update is linearised where the filter stands. From a start (or a re-opened
/// block) far from the truth, the first update's linearisation is poor; with many points it
/// still shrinks the sigmas tenfold or more in one frame and moves the estimate far along a
/// wrong gradient, which the next frames cannot undo (measured: pitch_l moved 77 deg against
/// a 10 deg prior in one update; 25 of the 88 default campaign runs that were not honest
/// were beyond 5 sigma from frame 30 on). Tempering multiplies the update's measurement
/// covariances by a factor alpha >= 1, so that the sigma shrinks by at most the given factor
/// and the estimate moves part of the way. The next frame linearises there: over a few
/// frames the start becomes an iterated (progressive) update. What a tempered update
/// leaves out is information given away, never information invented: the tempered
/// posterior is wider than the untempered one.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace osc {

/// One point's linearised measurement of the global error: r = J dg + n, n ~ N(0, S0).
struct LinearizedMeasurement {
  const Eigen::MatrixXd* J = nullptr;   ///< 4 x G
  const Eigen::Matrix4d* S0 = nullptr;  ///< 4 x 4
};

/// One step of the filter's sequential update (CalibrationFilter::runPass): @p PJt = P J^T
/// and the gain @p K = P J^T S^-1 with S = J P J^T + alpha S0. False, with nothing set, when
/// S is not positive definite or K not finite (rounding over many sequential updates from a
/// wide prior can leave S indefinite; the filter skips such a point rather than turn the whole
/// state into NaN).
bool sequentialGain(const Eigen::MatrixXd& P, const LinearizedMeasurement& measurement,
                    double alpha, Eigen::MatrixXd* PJt, Eigen::MatrixXd* K);

/// The factor alpha >= 1 for S0 such that the update of prior covariance @p P with
/// @p measurements shrinks none of the first @p limited standard deviations by more than
/// @p max_shrink (the sequential update the filter applies, S = J P J^T + alpha S0). 1 when
/// that does not bind (max_shrink <= 1 is off). Found by a few fixed-point steps on alpha (exact
/// for one state dimension, slightly above the bound for correlated ones).
double updateTempering(const Eigen::MatrixXd& P,
                       const std::vector<LinearizedMeasurement>& measurements, int limited,
                       double max_shrink);

}  // namespace osc
