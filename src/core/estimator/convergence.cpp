/// @file convergence.cpp
/// @brief ConvergenceThresholds, undeterminedParameters, isConverged.
#include "online_stereo_calibration/core/estimator/convergence.h"

#include <algorithm>
#include <array>

#include "online_stereo_calibration/core/filter/motion_excitation.h"

namespace osc {

double convergenceBound(const ConvergenceThresholds& thresholds, int index) {
  const bool translation = (index % 6) < 3;
  if (index < 6) return translation ? thresholds.caml_translation : thresholds.caml_rotation;
  return translation ? thresholds.camr_translation : thresholds.camr_rotation;
}

std::vector<int> undeterminedParameters(const CalibrationEstimate& estimate,
                                        const ConvergenceThresholds& thresholds) {
  const std::array<bool, 3> unexcited = unexcitedTranslationAxes(estimate.excitation);
  const Vector12d sigma = estimate.sigmas();
  std::vector<int> undetermined;
  for (int i = 0; i < 3; ++i) {
    if (unexcited[static_cast<size_t>(i)] && !(3.0 * sigma(i) <= convergenceBound(thresholds, i))) {
      undetermined.push_back(i);
    }
  }
  for (int i : scaleLimitedParameters(estimate, thresholds)) {
    if (std::find(undetermined.begin(), undetermined.end(), i) == undetermined.end())
      undetermined.push_back(i);
  }
  std::sort(undetermined.begin(), undetermined.end());
  return undetermined;
}

std::vector<int> scaleLimitedParameters(const CalibrationEstimate& estimate,
                                        const ConvergenceThresholds& thresholds) {
  const Vector12d sigma = estimate.sigmas();
  const Vector12d sigma_given_scale =
      (estimate.parameter_covariance - estimate.odometry_scale_covariance)
          .diagonal()
          .cwiseMax(0.0)
          .cwiseSqrt();
  std::vector<int> limited;
  for (int i = 0; i < 12; ++i) {
    const double bound = convergenceBound(thresholds, i);
    if (estimate.odometry_scale_covariance(i, i) > 0.0 && !(3.0 * sigma(i) <= bound) &&
        3.0 * sigma_given_scale(i) <= bound) {
      limited.push_back(i);
    }
  }
  return limited;
}

bool isConverged(const CalibrationEstimate& estimate, const ConvergenceThresholds& thresholds) {
  const Vector12d sigma = estimate.sigmas();
  const std::vector<int> excused = undeterminedParameters(estimate, thresholds);
  for (int i = 0; i < 12; ++i) {
    if (std::find(excused.begin(), excused.end(), i) != excused.end()) continue;
    if (!(3.0 * sigma(i) <= convergenceBound(thresholds, i))) return false;
  }
  return true;
}

}  // namespace osc
