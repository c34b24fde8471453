/// @file restart_from_estimate.h
/// @brief Linearisation guard: a start (or a re-opened block) far from the truth is restarted
/// from the current estimate with its start covariance, as an iterated filter re-linearises
/// (issue 14; docs/design.md, "linearisation guard").
///
/// The points of a start are initialised, and its first updates linearised, at the guess. A
/// guess far off (a few prior sigmas) can lock the filter onto a wrong answer with a small
/// sigma (x_camr's angles 5 deg off: 176 sigma wrong). Every `frames` accepted steps the
/// estimate is compared with the anchor, the state the filter was started or re-opened at: a
/// block that moved more than `threshold` anchor sigmas, while the updates' innovations were
/// larger than `nis` times their expected size, restarts from its estimate with the anchor's
/// uncertainty; its points are dropped. The odometry states keep what they learned.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// The restart's options (FilterConfig's relinearization_* keys).
struct RestartFromEstimateOptions {
  int frames = 15;             ///< relinearization_frames: steps between checks; 0 = off
  double threshold = 0.5;      ///< relinearization_threshold: move (anchor sigmas) to restart
  double nis = 1.05;           ///< relinearization_nis: mean NIS per coordinate to restart
  double far_threshold = 2.0;  ///< relinearization_far_threshold: a far move (0 = off) ...
  double far_nis = 0.95;       ///< relinearization_far_nis: ... restarts at this lower gate
  int max_restarts = 4;        ///< max_relinearizations after one start or re-opening

  static RestartFromEstimateOptions from(const FilterConfig& config);
};

/// What one check did.
struct RestartDecision {
  bool restarted = false;
  std::vector<PointId> dropped;  ///< the filter's points, all dropped by a restart
  std::string warning;           ///< the event's line (empty when nothing was done)
};

/// The anchor and the restart check (one per estimator).
class RestartFromEstimate {
 public:
  explicit RestartFromEstimate(const RestartFromEstimateOptions& options) : options_(options) {}

  /// Anchors at @p filter's state now: after a start (@p block kNone: both blocks checked),
  /// or after @p block was re-opened to @p reopened_sigma ([dt (3), dtheta (3)]; only the
  /// re-opened components are checked, and a restart widens them to it again).
  void anchorHere(const CalibrationFilter& filter, JumpBlock block, const Vector6d& reopened_sigma);
  /// anchorHere after a re-opening of @p block, unless a start's anchor is still live: a
  /// re-opening while a start is still being re-linearised is part of that start (a guess far
  /// off gates many points out, or moves the pairs off x_camr's epipolar band), and the
  /// start's anchor covers both blocks.
  void anchorReopening(const CalibrationFilter& filter, JumpBlock block,
                       const Vector6d& reopened_sigma);
  /// After an accepted step @p step: counts it and, every `frames` steps, restarts each
  /// anchored block that moved beyond the threshold if the innovations were beyond the gate.
  RestartDecision checkAfterStep(CalibrationFilter* filter, const StepReport& step);

 private:
  /// Where the filter was last started or a block re-opened (its linearisation point) and
  /// with which covariance.
  struct Anchor {
    StereoExtrinsics extrinsics;
    Matrix12d covariance = Matrix12d::Identity();
    /// Blocks checked and restarted: both after a start, one after a re-opening.
    std::array<bool, 2> blocks{{true, true}};
    /// The re-opened block's sigmas [dt (3), dtheta (3)] (m, rad), to widen it again on a
    /// restart; 0: that component was not re-opened (and is not checked).
    Vector6d reopened_sigma = Vector6d::Zero();
    int frames = 0;    ///< accepted steps since the anchor or the last check
    int steps = 0;     ///< accepted steps since the start or re-opening (over restarts)
    int restarts = 0;  ///< restarts since the start or re-opening
    /// Sum of NIS and number of measurements used since the last check.
    double nis_sum = 0.0;
    int nis_count = 0;
  };

  /// Largest move since the anchor of a tangent component of @p block (0 x_caml, 1 x_camr)
  /// that the anchor checks (all after a start, the re-opened ones after a re-opening), in
  /// the anchor's 1 sigmas; 0 for a block the anchor does not check.
  double movedSinceAnchor(const CalibrationFilter& filter, int block) const;
  /// The anchor is still checked: fewer than max_restarts restarts and
  /// (max_restarts + 1) * frames steps since the start or re-opening.
  bool anchorIsLive() const;

  RestartFromEstimateOptions options_;
  Anchor anchor_;
};

}  // namespace osc
