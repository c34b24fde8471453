/// @file scenario_runner.h
/// @brief Runs the estimator over a measurement-level scenario, frame by frame, the way a
/// front end would: observations in, dropped tracks fed back to the simulated tracker.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {

/// One frame of a scenario run: estimate, its uncertainty and the truth.
struct ScenarioFrameResult {
  int frame = 0;
  double stamp = 0.0;
  Vector12d parameters = Vector12d::Zero();  ///< estimate, interface order
  Vector12d sigmas = Vector12d::Zero();      ///< 1 sigma of parameters
  Vector12d truth = Vector12d::Zero();       ///< true parameters
  /// Error on the manifold [dt_l, dtheta_l, dt_r, dtheta_r] (truth boxMinus estimate),
  /// meaningful for any mounting, also where RPY is singular.
  Vector12d tangent_error = Vector12d::Zero();
  Vector12d tangent_sigmas = Vector12d::Zero();  ///< 1 sigma of the tangent error
  double nees = 0.0;                             ///< tangent_error^T P^-1 tangent_error (12 dof)
  int tracked_points = 0;
  int new_points = 0;
  bool jump_detected = false;
  /// The step's update tempering factor (StepReport::tempering; 1 = untempered).
  double tempering = 1.0;
  /// The text of the frame's events (FrameReport::events: restarts, re-openings, re-seeds,
  /// rejected motion), for a run's event log.
  std::vector<std::string> warnings;
  /// isConverged(estimate, ConvergenceThresholds()) after this frame (convergence.h).
  bool converged = false;
  double time_ms = 0.0;  ///< estimator time for this frame
  /// Estimated camera-odometry time offset and its 1 sigma (s; sigma 0: not estimated).
  double time_offset = 0.0;
  double time_offset_sigma = 0.0;
  /// The odometry noise matcher's factors on the configured motion noise's variance,
  /// translation and rotation (1: as configured; odometry_noise_matcher.h).
  std::array<double, 2> odometry_noise_factor = {1.0, 1.0};
};

/// One frame's result from the estimate after it, the truth and the estimator's report.
ScenarioFrameResult makeFrameResult(const SimulatedFrame& frame,
                                    const CalibrationEstimate& estimate, const FrameReport& report,
                                    double time_ms);

/// Runs scenario through a StereoCalibrationEstimator starting from the scenario's initial
/// guess; calls on_frame after each frame if given. Each observation carries the scenario's
/// pixel_noise as its sigma, unless @p declare_config_pixel_noise: then it carries none and
/// the estimator assumes config.pixel_noise (as for a front end that declares none), so that
/// a configuration can be wrong about the noise the simulator adds.
/// @throws std::invalid_argument for an invalid scenario or config.
std::vector<ScenarioFrameResult> runMeasurementScenario(
    const MeasurementScenario& scenario, const FilterConfig& config,
    const std::function<void(const ScenarioFrameResult&)>& on_frame = {},
    bool declare_config_pixel_noise = false);

}  // namespace osc
