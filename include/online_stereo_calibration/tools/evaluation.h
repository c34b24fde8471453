/// @file evaluation.h
/// @brief The figures we report: RMSE and consistency over a frame window (the seed's
/// Table I), convergence time, and the paper's own numbers to compare with.
///
/// Errors are estimate - reference per parameter, angles wrapped to (-pi, pi]. Estimate and
/// reference rows are matched by frame number; frames without a reference are not used.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/estimates_csv.h"

namespace osc {

/// Whether parameter @p index of the interface order [xl..yaw_l, xr..yaw_r] is an angle.
bool isAngleParameter(int index);
/// estimate - truth of parameter @p index, an angle wrapped to (-pi, pi] (wrapAngle).
double parameterError(const Vector12d& estimate, const Vector12d& truth, int index);
/// All 12 of them.
Vector12d parameterErrors(const Vector12d& estimate, const Vector12d& truth);

/// Statistics of one parameter over the window (m or rad).
struct ParameterStatistics {
  double rmse = 0;           ///< sqrt(mean of error^2)
  double within_2sigma = 0;  ///< fraction of frames with |error| <= 2 sigma (0.954 if consistent)
  double sigma_at_last = 0;  ///< the filter's 1 sigma at the last frame used
  double max_abs_error = 0;  ///< largest |error|
};

/// Result of evaluateWindow.
struct EvaluationReport {
  int first_frame = 0;  ///< window start as requested (inclusive)
  int last_frame = 0;   ///< window end as requested (inclusive)
  int frames_used = 0;  ///< frames in the window with both an estimate and a reference
  /// Per parameter, in the interface order [xl..yaw_l, xr..yaw_r].
  std::array<ParameterStatistics, 12> parameters{};
  /// Diagonal normalised estimation error squared, per parameter:
  /// mean over frames of sum_k (e_k / sigma_k)^2 / 12. About 1 for a consistent filter,
  /// >> 1 for an overconfident one. Ignores correlations between parameters.
  double mean_nees = 0;
};

/// Statistics over the frames in [first_frame, last_frame] (inclusive). Throws
/// std::invalid_argument if first_frame > last_frame, a frame number repeats in either list,
/// or no frame in the window has both an estimate and a reference.
EvaluationReport evaluateWindow(const std::vector<EstimateRow>& estimates,
                                const std::vector<ReferenceRow>& reference, int first_frame,
                                int last_frame);

/// The first frame f >= @p from_frame such that |error of parameter @p parameter_index| <=
/// @p tolerance at f and at every later matched frame (up to the last row); -1 if the error
/// is out of tolerance at the last matched frame or there are no matched frames. A NaN
/// error counts as out of tolerance. Throws std::invalid_argument for an index outside 0..11.
int framesToConverge(const std::vector<EstimateRow>& estimates,
                     const std::vector<ReferenceRow>& reference, int parameter_index,
                     double tolerance, int from_frame);

/// The seed's Table I (algorithm.md): RMSE over frames 1000-1150 on the real vehicle, in the
/// interface order, m and rad.
const std::array<double, 12>& paperTableRmse();
/// The seed's Table I: the filter's 1 sigma at frame 1150, m and rad.
const std::array<double, 12>& paperTableSigma();

/// The report as a text table in the seed's Table I layout (x_caml beside x_camr), m and deg:
/// our RMSE, the paper's RMSE, whether ours is below (yes/no), our 1 sigma at the last frame,
/// the fraction within 2 sigma, then the mean diagonal NEES.
std::string formatTableI(const EvaluationReport& report);

}  // namespace osc
