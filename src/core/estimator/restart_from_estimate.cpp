#include "online_stereo_calibration/core/estimator/restart_from_estimate.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace osc {

RestartFromEstimateOptions RestartFromEstimateOptions::from(const FilterConfig& config) {
  RestartFromEstimateOptions o;
  o.frames = config.relinearization_frames;
  o.threshold = config.relinearization_threshold;
  o.nis = config.relinearization_nis;
  o.far_threshold = config.relinearization_far_threshold;
  o.far_nis = config.relinearization_far_nis;
  o.max_restarts = config.max_relinearizations;
  return o;
}

void RestartFromEstimate::anchorHere(const CalibrationFilter& filter, JumpBlock block,
                                     const Vector6d& reopened_sigma) {
  anchor_ = Anchor();
  anchor_.extrinsics = filter.extrinsics();
  anchor_.covariance = filter.covariance();
  anchor_.blocks = {{block != JumpBlock::kLeftToRight, block != JumpBlock::kVehicleToLeft}};
  anchor_.reopened_sigma = reopened_sigma;
}

void RestartFromEstimate::anchorReopening(const CalibrationFilter& filter, JumpBlock block,
                                          const Vector6d& reopened_sigma) {
  const bool start_is_live = anchorIsLive() && anchor_.blocks[0] && anchor_.blocks[1];
  if (!start_is_live) anchorHere(filter, block, reopened_sigma);
}

double RestartFromEstimate::movedSinceAnchor(const CalibrationFilter& filter, int block) const {
  if (!anchor_.blocks[static_cast<size_t>(block)]) return 0.0;
  const StereoExtrinsics& now = filter.extrinsics();
  const Vector6d moved = block == 0 ? boxMinus(now.T_veh_caml, anchor_.extrinsics.T_veh_caml)
                                    : boxMinus(now.T_caml_camr, anchor_.extrinsics.T_caml_camr);
  // After a start every component is checked; after a re-opening only those re-opened (a
  // rotation-only re-opening keeps the block's converged translation, whose small sigma any
  // ordinary update moves it by).
  const bool whole_start = anchor_.blocks[0] && anchor_.blocks[1];
  double largest = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double variance = anchor_.covariance(6 * block + k, 6 * block + k);
    if (!(variance > 0.0) || (!whole_start && !(anchor_.reopened_sigma(k) > 0.0))) continue;
    largest = std::max(largest, std::abs(moved(k)) / std::sqrt(variance));
  }
  return largest;
}

bool RestartFromEstimate::anchorIsLive() const {
  return options_.frames > 0 && anchor_.restarts < options_.max_restarts &&
         anchor_.steps < (options_.max_restarts + 1) * options_.frames;
}

RestartDecision RestartFromEstimate::checkAfterStep(CalibrationFilter* filter,
                                                    const StepReport& step) {
  RestartDecision decision;
  if (!anchorIsLive()) return decision;
  ++anchor_.steps;
  anchor_.nis_sum += step.mean_nis * step.measurements_used;
  anchor_.nis_count += step.measurements_used;
  if (++anchor_.frames < options_.frames) return decision;
  // A move alone is what any start within its prior does as it converges (the largest of 12
  // components is often 1-2 sigmas); a linearisation far off also shows in the innovations:
  // measured mean NIS per stereo measurement over frames 1-15, 4 dof: 3.7-4.0 from a good
  // guess, 4.5-6.5 from the paper's start errors, 8-9.5 with x_camr's angles 3-5 deg off.
  const double nis_per_dof =
      anchor_.nis_count > 0 ? anchor_.nis_sum / (4.0 * anchor_.nis_count) : 0.0;
  anchor_.frames = 0;
  anchor_.nis_sum = 0.0;
  anchor_.nis_count = 0;
  const std::array<double, 2> moved = {movedSinceAnchor(*filter, 0), movedSinceAnchor(*filter, 1)};
  // A block that moved far from the guess lowers the innovation gate for both: the points of
  // either were linearised at the far-off start. After a first restart the estimate is the
  // linearisation point, and a further far move is convergence from it (a sideways camera
  // guessed forward, restarted again at frame 31: xl 3-3.3 sigma off for 30 frames).
  const bool far = options_.far_threshold > 0.0 && anchor_.restarts == 0 &&
                   std::max(moved[0], moved[1]) > options_.far_threshold;
  if (!(nis_per_dof > (far ? options_.far_nis : options_.nis))) return decision;
  const std::array<bool, 2> restart = {moved[0] > options_.threshold,
                                       moved[1] > options_.threshold};
  if (!restart[0] && !restart[1]) return decision;
  // Restart at the current estimate: the points were initialised and the first updates
  // linearised at a calibration now known to be far off, so their regressions on it (and
  // the sigma they gave) do not hold. The moved block's uncertainty at the anchor comes back
  // (the other block keeps what it learned), and the data shrink it again from a
  // linearisation point near the truth.
  // The odometry states (time offset, velocity bias, x_camr's drift rate) keep what they
  // learned: a reset threw away, e.g., default campaign run 25's time offset (19.3 +- 0.5 ms
  // -> 0 +- 20 ms at a restart in frame 30).
  for (const PointEstimate& p : filter->points()) decision.dropped.push_back(p.id);
  const bool whole_start = anchor_.blocks[0] && anchor_.blocks[1];
  if (whole_start && restart[0] && restart[1]) {
    filter->restartCalibration(anchor_.covariance);
  } else {
    for (int block = 0; block < 2; ++block) {
      if (!restart[static_cast<size_t>(block)]) continue;
      Vector6d sigma = anchor_.reopened_sigma;
      if (whole_start) {  // the start's own sigmas of this block
        const Vector6d variance = anchor_.covariance.diagonal().segment<6>(6 * block);
        sigma = uniformBlockSigmas(std::sqrt(variance.head<3>().maxCoeff()),
                                   std::sqrt(variance.tail<3>().maxCoeff()));
      }
      filter->reopen(block == 0 ? JumpBlock::kVehicleToLeft : JumpBlock::kLeftToRight, sigma);
    }
  }
  anchor_.extrinsics = filter->extrinsics();
  ++anchor_.restarts;
  decision.restarted = true;
  std::ostringstream message;
  message << "restarted from the current estimate (re-linearised): "
          << (restart[0] && restart[1] ? "x_caml and x_camr"
              : restart[0]             ? "x_caml"
                                       : "x_camr")
          << " moved " << std::max(restart[0] ? moved[0] : 0.0, restart[1] ? moved[1] : 0.0)
          << " start sigmas from where the filter was started, innovations at " << nis_per_dof
          << " of their expected size (restart " << anchor_.restarts << " of at most "
          << options_.max_restarts << "); tracks reset";
  decision.warning = message.str();
  return decision;
}

}  // namespace osc
