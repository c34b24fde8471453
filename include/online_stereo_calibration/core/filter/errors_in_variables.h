/// @file errors_in_variables.h
/// @brief The errors-in-variables compensation of the filter's update (FilterConfig::
/// errors_in_variables_compensation; docs/RESULTS.md "Session 33").
///
/// A step moves a point by the camera's motion: [d; w] -> [A d + c w; w] (eq. 7-8), bilinear
/// in the point's inverse depth w and the translation c. The filter regresses the moved point
/// on the global error (B = d moved / d g, calibration_filter.h) at the point's estimate, and
/// the residual of its next measurement contains that estimate's error e. So the update's
/// score J^T S0^-1 r has, beyond its linear part, the expectation
///   E[(sum_k dJ/dp_k e_k)^T S0^-1 H_p F_p e] = sum_k (H_p dB_k)^T S0^-1 H_p F_p D e_k
/// with the opposite sign (J = H_p B + ..., D = Cov(e), F_p = d moved / d p): the classic
/// attenuation of a regression on a noisy regressor. It shrinks the camera's translation
/// measured through the points by E[sigma_rho^2] / E[rho^2]: the baseline is estimated long
/// (0.22 % on a 0.125 m rig at 564 px, every run), and what a free baseline does not absorb
/// goes to the lever arm (yl of a sideways camera, +0.8 sigma). The compensation adds that
/// expectation back to the score.
///
/// It is first order in the point's error and exact for one update per point (a simulated
/// regression, scripts/errors_in_variables_toy.py). After its first update a point's depth
/// comes mostly from the motion, linearised at the estimate the update just corrected, and
/// compensating those updates too overshoots (the baseline then 0.2 sigma short on the bench
/// above, yaw_r -0.75 sigma), so the filter compensates a point's first update only.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/filter/point_coordinates.h"

namespace osc {

/// A step that moves homogeneous points linearly, h -> M(x) h, as a function of its inputs x
/// (the global errors it depends on), near x = 0.
struct LinearStepMap {
  Eigen::Matrix4d at_zero = Eigen::Matrix4d::Identity();  ///< M(0)
  std::vector<Eigen::Matrix4d> derivatives;               ///< d M / d x_a at 0, per input a
};

/// The homogeneous point @p h moved by the step with inputs @p x; linear in @p h.
using HomogeneousStep =
    std::function<HomogeneousPoint(const Eigen::VectorXd& x, const HomogeneousPoint& h)>;

/// M(0) and its derivatives (central differences) for a step of @p inputs inputs.
LinearStepMap linearizeStep(const HomogeneousStep& step, int inputs);

/// d B / d p_k (k = 0, 1, 2) at the point @p point (in @p coordinates), with B = d coordinates
/// of the moved point / d x: each 3 x @p global_dim, input a in column @p columns[a], the
/// other columns zero.
std::array<Eigen::MatrixXd, 3> regressionGradient(const PointCoordinates& coordinates,
                                                  const LinearStepMap& map,
                                                  const Eigen::Vector3d& point,
                                                  const std::vector<int>& columns, int global_dim);

/// What the update's score J^T S0^-1 r lacks in expectation (see the file comment), for a
/// point with regression gradient @p gradient, measurement Jacobian @p H_p, residual
/// covariance given the global error @p S0 and @p own_error_cross = F_p D (the covariance of
/// the moved point's own error with the error it had before the step).
Eigen::VectorXd errorsInVariablesScore(const std::array<Eigen::MatrixXd, 3>& gradient,
                                       const Eigen::Matrix<double, 4, 3>& H_p,
                                       const Eigen::Matrix4d& S0,
                                       const Eigen::Matrix3d& own_error_cross);

}  // namespace osc
