#include "online_stereo_calibration/core/sim/scenario_runner.h"

#include <chrono>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/estimator/convergence.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {

ScenarioFrameResult makeFrameResult(const SimulatedFrame& frame,
                                    const CalibrationEstimate& estimate, const FrameReport& report,
                                    double time_ms) {
  ScenarioFrameResult r;
  r.frame = frame.index;
  r.stamp = frame.stamp;
  r.parameters = estimate.parameters;
  r.sigmas = estimate.sigmas();
  r.truth = frame.truth.toParameters();
  r.tangent_error.head<6>() = boxMinus(frame.truth.T_veh_caml, estimate.extrinsics.T_veh_caml);
  r.tangent_error.tail<6>() = boxMinus(frame.truth.T_caml_camr, estimate.extrinsics.T_caml_camr);
  r.tangent_sigmas = estimate.tangent_covariance.diagonal().cwiseSqrt();
  r.nees = r.tangent_error.dot(estimate.tangent_covariance.ldlt().solve(r.tangent_error));
  r.tracked_points = static_cast<int>(estimate.tracked_points);
  r.new_points = report.new_points;
  r.jump_detected = report.step.jump != JumpBlock::kNone;
  r.tempering = report.step.tempering;
  r.warnings = report.events.texts();
  r.converged = isConverged(estimate, ConvergenceThresholds());
  r.time_ms = time_ms;
  r.time_offset = estimate.time_offset;
  r.time_offset_sigma = estimate.time_offset_sigma;
  r.odometry_noise_factor = estimate.odometry_noise.factor;
  return r;
}

std::vector<ScenarioFrameResult> runMeasurementScenario(
    const MeasurementScenario& scenario, const FilterConfig& config,
    const std::function<void(const ScenarioFrameResult&)>& on_frame,
    bool declare_config_pixel_noise) {
  MeasurementSimulator simulator(scenario);
  StereoCalibrationEstimator estimator(config, scenario.left, scenario.right,
                                       simulator.initialGuess());
  std::vector<ScenarioFrameResult> results;
  results.reserve(scenario.frames);
  SimulatedFrame frame;
  while (true) {
    // The odometry read where the estimator believes the images were (its time offset).
    simulator.setOdometryTimeShift(estimator.odometryTimeShift());
    if (!simulator.nextFrame(&frame)) break;
    if (declare_config_pixel_noise) {
      for (auto& observation : frame.observations) {
        observation.sigma_left = observation.sigma_right = 0.0;
      }
    }
    const auto start = std::chrono::steady_clock::now();
    const FrameReport report = estimator.processFrame(frame.measured_motion, frame.observations);
    const CalibrationEstimate estimate = estimator.estimate();
    const auto stop = std::chrono::steady_clock::now();
    simulator.dropTracks(report.dropped);

    const ScenarioFrameResult r = makeFrameResult(
        frame, estimate, report, std::chrono::duration<double, std::milli>(stop - start).count());
    if (on_frame) on_frame(r);
    results.push_back(r);
  }
  return results;
}

}  // namespace osc
