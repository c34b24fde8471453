#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "online_stereo_calibration/core/estimator/epipolar_consistency.h"
#include "online_stereo_calibration/core/estimator/hand_eye_start.h"
#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Pairs in a row with every tracked point measured and none predictable before a warning:
/// a pair or two is a start's or a re-opening's transient, ten (1 s at 10 Hz) is a stall.
constexpr int kUnmeasurablePairsToWarn = 10;
/// Fewest refused stereo pairs for which "no point could be initialised" is worth a warning.
constexpr int kFewestPairsToExplain = 10;
HandEyeRotationConfig handEyeConfig(const FilterConfig& config) {
  HandEyeRotationConfig h;
  h.max_sigma = config.hand_eye_max_sigma;
  // Five times the odometry's rotation noise per axis per step: below, no excitation.
  h.min_rotation = 5.0 * config.motion_rotation_noise;
  return h;
}

}  // namespace

StereoCalibrationEstimator::StereoCalibrationEstimator(const FilterConfig& config,
                                                       const CameraIntrinsics& left,
                                                       const CameraIntrinsics& right,
                                                       const StereoExtrinsics& initial_guess)
    : config_(config),
      left_(left),
      right_(right),
      filter_(config, StereoIntrinsics{left_.K(), right_.K()}),
      restart_(RestartFromEstimateOptions::from(config)),
      jump_test_(JumpTestOptions::from(config)),
      score_test_(RightCameraScoreOptions::from(config)),
      gap_check_(LeftCameraGapCheckOptions::from(config)),
      knock_test_(EpipolarKnockOptions::from(config)),
      guess_(initial_guess),
      mounting_(left_, handEyeConfig(config)),
      baseline_restart_(config, left_.K(), right_.K()),
      monitor_(config),
      noise_matcher_(OdometryNoiseMatcherOptions::from(config)) {
  filter_.reset(initial_guess);
  followFilter();
  guess_covariance_ = filter_.covariance();
  restart_.anchorHere(filter_, JumpBlock::kNone, Vector6d::Zero());
}

void StereoCalibrationEstimator::followFilter() {
  if (filter_.starts() != monitor_starts_) {
    monitor_starts_ = filter_.starts();
    monitor_reopenings_ = filter_.reopenings();
    monitor_.reset();
  } else if (filter_.reopenings() != monitor_reopenings_) {
    monitor_reopenings_ = filter_.reopenings();
    monitor_.forgetEvidence();  // the evidence was the re-opened block's old calibration
  }
  setFilterDriftInflation();
}

void StereoCalibrationEstimator::setFilterDriftInflation() {
  // Set as soon as the monitor changes: the front end's predictObservations before the next
  // step predicts with them, and the step reuses that prediction.
  filter_.setDriftInflation(monitor_.inflation());
}

void StereoCalibrationEstimator::learnOdometryNoise(const MotionIncrement& motion,
                                                    FrameReport* report) {
  const std::string before = noise_matcher_.status().message();
  const double caml_rotation_variance =
      filter_.covariance().diagonal().segment<3>(layout::kCaml + layout::kRotation).maxCoeff();
  noise_matcher_.addUpdate(motion.dt, filter_.lastMotionNoiseEvidence(),
                           std::sqrt(std::max(caml_rotation_variance, 0.0)));
  filter_.setMotionNoiseFactors(noise_matcher_.factors());
  const std::string after = noise_matcher_.status().message();
  if (before.empty() != after.empty()) {
    report->events.add(FrameEvent::kOdometryNoiseLearned,
                       after.empty() ? "odometry noise as configured again" : after);
  }
}

bool StereoCalibrationEstimator::restartIfLinearizedFarOff(FrameReport* report) {
  const RestartDecision decision = restart_.checkAfterStep(&filter_, report->step);
  followFilter();
  if (!decision.restarted) return false;
  report->dropped.insert(report->dropped.end(), decision.dropped.begin(), decision.dropped.end());
  report->events.add(FrameEvent::kRelinearized, decision.warning);
  return true;
}

bool StereoCalibrationEstimator::restartFromMotion(
    const MotionIncrement& motion, const std::vector<StereoObservation>& observations,
    FrameReport* report) {
  using namespace layout;
  mounting_.addFrame(motion, has_previous_frame_, observations);
  MountingRestart restart;
  const StereoExtrinsics now = filter_.extrinsics();
  auto covariance = filter_.covariance();
  if (!mounting_.checkFilter(now.T_veh_caml.linear(),
                             covariance.template block<3, 3>(kCaml + kRotation, kCaml + kRotation),
                             config_.hand_eye_restart_distance, config_.hand_eye_min_restart_sigma,
                             &restart)) {
    return false;
  }
  for (const PointEstimate& p : filter_.points()) report->dropped.push_back(p.id);
  const HandEyeStart start = handEyeStart(
      restart, now, guess_, Matrix12d(guess_covariance_),
      std::max(config_.initial_caml_translation_sigma, config_.hand_eye_restart_translation_sigma));
  filter_.reset(start.extrinsics, start.covariance);
  followFilter();
  // A start: both blocks re-linearised as after one.
  restart_.anchorHere(filter_, JumpBlock::kNone, Vector6d::Zero());
  report->events.add(FrameEvent::kMountingRotationFromMotion, start.message);
  return true;
}

bool StereoCalibrationEstimator::wantsLeftCameraMatches() const {
  return handEyeActive() && mounting_.lastMotionUsable() && !mounting_.lastFramePaired();
}

void StereoCalibrationEstimator::addLeftCameraMatches(const MotionIncrement& motion,
                                                      const std::vector<Eigen::Vector2d>& previous,
                                                      const std::vector<Eigen::Vector2d>& current) {
  if (wantsLeftCameraMatches()) mounting_.addMatches(motion, previous, current);
}

bool StereoCalibrationEstimator::toMeasurement(const StereoObservation& o,
                                               PointMeasurement* m) const {
  if (!o.left_pixel.allFinite() || !o.right_pixel.allFinite() || !std::isfinite(o.sigma_left) ||
      !std::isfinite(o.sigma_right)) {
    return false;
  }
  m->id = o.id;
  Eigen::Vector2d left_undistorted, right_undistorted;
  if (!left_.undistortPixel(o.left_pixel, &left_undistorted) ||
      !right_.undistortPixel(o.right_pixel, &right_undistorted)) {
    return false;  // beyond what the lens model maps to a ray (camera_model.h)
  }
  m->z << left_undistorted, right_undistorted;
  const double sl = o.sigma_left > 0.0 ? o.sigma_left : config_.pixel_noise;
  const double sr = o.sigma_right > 0.0 ? o.sigma_right : config_.pixel_noise;
  // The sigmas are the raw images'; the filter measures undistorted pixels. Without the
  // lens's stretch, wide-angle runs' stereo pairs lay off x_camr's epipolar lines by up to 40
  // times what their stated noise allows (default campaign runs 123, 180; RESULTS Session 21).
  const double vl = left_.undistortedPixelVariance(left_undistorted, sl);
  const double vr = right_.undistortedPixelVariance(right_undistorted, sr);
  m->variance << vl, vl, vr, vr;
  return m->z.allFinite() && m->variance.allFinite();
}

FrameReport StereoCalibrationEstimator::processFrame(
    const MotionIncrement& motion, const std::vector<StereoObservation>& observations) {
  FrameReport report;
  if (handEyeActive() && restartFromMotion(motion, observations, &report)) {
    has_previous_frame_ = false;  // tracking starts afresh with this pair, as after a start
  }
  const bool follows_previous_pair = has_previous_frame_;
  std::vector<PointMeasurement> tracked, candidates;
  for (const StereoObservation& o : observations) {
    PointMeasurement m;
    if (!toMeasurement(o, &m)) {
      ++report.invalid_observations;
      continue;
    }
    (filter_.hasPoint(o.id) ? tracked : candidates).push_back(m);
  }
  if (report.invalid_observations > 0) {
    report.events.add(
        FrameEvent::kObservationsIgnored,
        std::to_string(report.invalid_observations) +
            " observation(s) ignored: NaN/Inf pixel or sigma, or a pixel no ray of the lens "
            "model reaches");
  }

  // Before the update: after a knock the tracked points would pull x_camr with its old
  // sigma, or gate out and be blamed on x_caml.
  reopenIfOffEpipolarLines(&tracked, &candidates, &report);

  if (has_previous_frame_) {
    // Too few points to update (a dim stretch of 1-4 points walked roll_l 1.9 -> 3.5 sigma
    // off): predict only, those points start afresh. The new candidates count: few tracked of
    // many pairs is a start's thin evidence (tempering's), not a texture-poor view.
    const int needed = config_.min_points_to_update,
              seen = static_cast<int>(tracked.size() + candidates.size());
    report.too_few_points = !tracked.empty() && seen < needed;
    if (report.too_few_points) {
      if (!held_for_few_points_) {
        report.events.add(FrameEvent::kTooFewPoints,
                          "too few points: " + std::to_string(seen) +
                              " stereo pairs, fewer than min_points_to_update " +
                              std::to_string(needed) +
                              "; the calibration is kept, not updated, until more are seen");
      }
      candidates.insert(candidates.end(), tracked.begin(), tracked.end());
      tracked.clear();
    }
    held_for_few_points_ = report.too_few_points;
    gap_check_.beforeStep(&monitor_, !tracked.empty());
    report.step = filter_.step(motion, tracked, [this](const GateOutcome& gate) {
      return jump_test_.decide(gate, filter_);
    });
    gap_check_.countAfterStep(motion, report.step);
    if (!report.step.accepted) {
      // Without a usable motion the points cannot be predicted: start tracking afresh.
      report.events.add(FrameEvent::kMotionRejected, "motion rejected: " + report.step.message);
      report.dropped = resetTracking();
      candidates.insert(candidates.end(), tracked.begin(), tracked.end());
    } else {
      followFilter();  // a jump's re-opening ends the monitor's window before its update
      monitor_.addUpdate(motion.dt, filter_.lastUpdateScores());
      report.consistency = monitor_.status();
      setFilterDriftInflation();
      learnOdometryNoise(motion, &report);
      report.dropped = report.step.lost;
      report.dropped.insert(report.dropped.end(), report.step.outliers.begin(),
                            report.step.outliers.end());
      if (report.step.jump != JumpBlock::kNone) {
        report.events.add(FrameEvent::kJump, report.step.message);
        candidates.insert(candidates.end(), tracked.begin(), tracked.end());
        restart_.anchorReopening(filter_, report.step.jump, report.step.jump_sigma);
        // x_caml was re-opened on its own evidence: the check after a stretch without points
        // has its answer (left armed, it could re-open the axes a fitted turn kept to
        // jump_rotation_sigma_deg on the next frames' transient).
        if (report.step.jump == JumpBlock::kVehicleToLeft) gap_check_.disarm();
      } else {
        // A widening is not a re-opening: the points stay, and the checks below count the
        // frame as any other.
        const ScoreWidening widening = score_test_.afterStep(&filter_);
        if (widening.widened)
          report.events.add(FrameEvent::kRightRotationWidened, widening.warning);
        if (reopenLeftCameraAfterGap(motion, &report)) {
          candidates.insert(candidates.end(), tracked.begin(), tracked.end());
        } else if (restartIfLinearizedFarOff(&report)) {
          // Tracking starts afresh with the next pair, as after a start.
          candidates.clear();
          has_previous_frame_ = false;
        }
      }
      if (report.step.covariance_repaired) {
        report.events.add(FrameEvent::kCovarianceRepaired,
                          "calibration covariance was not positive definite and was repaired");
      }
    }
    warnIfNoPointMeasurable(tracked, &report);
  }
  if (!report.has(FrameEvent::kRelinearized)) has_previous_frame_ = true;

  // New points after the correction, so they start from the best calibration (Sec. II-A).
  for (const PointMeasurement& m : candidates) {
    if (filter_.pointCount() >= static_cast<size_t>(config_.max_points)) break;
    if (filter_.hasPoint(m.id)) continue;
    if (filter_.addPoint(m)) {
      ++report.new_points;
    } else {
      ++report.rejected_new_points;
    }
  }
  // Stereo pairs but not one point: the filter cannot learn anything (issue 14: an 11 cm rig
  // guessed at 1 cm stayed at 0 points for 800 frames with no other sign). Say why.
  const bool no_point_initialised = filter_.pointCount() == 0 &&
                                    report.rejected_new_points >= kFewestPairsToExplain &&
                                    report.new_points == 0;
  if (no_point_initialised) {
    const CalibrationEstimate e = estimate();
    std::ostringstream message;
    message << "no point could be initialised: none of " << report.rejected_new_points
            << " stereo pairs triangulates within [" << config_.min_point_depth << ", "
            << config_.max_point_depth << "] m with the current left->right estimate "
            << "(baseline yr " << e.parameters(7) << " m, 1 sigma " << e.sigmas()(7)
            << " m); check the baseline guess and initial_camr_translation_sigma_m";
    if (config_.baseline_from_motion != 0) {
      message << "; measuring the baseline's length from the left camera's motion ("
              << baseline_restart_.progress() << ")";
    }
    report.events.add(FrameEvent::kNoPointInitialised, message.str());
  }
  if (config_.baseline_from_motion != 0 && no_point_initialised) {
    learnBaselineLength(motion, follows_previous_pair && !report.has(FrameEvent::kMotionRejected),
                        candidates, &report);
  } else {
    baseline_restart_.forget();
  }
  // A point re-initialised from this pair (after a jump or a motion reset) is not dropped.
  std::vector<PointId> still_dropped;
  for (PointId id : report.dropped) {
    if (!filter_.hasPoint(id)) still_dropped.push_back(id);
  }
  report.dropped.swap(still_dropped);
  return report;
}

bool StereoCalibrationEstimator::reopenIfOffEpipolarLines(std::vector<PointMeasurement>* tracked,
                                                          std::vector<PointMeasurement>* candidates,
                                                          FrameReport* report) {
  std::vector<PointMeasurement> pairs = *tracked;
  pairs.insert(pairs.end(), candidates->begin(), candidates->end());
  const EpipolarKnock knock = knock_test_.test(pairs, left_.K(), right_.K(), filter_);
  if (!knock.knocked) return false;
  const std::vector<PointId> forgotten = reopenRightCameraRotation(knock.rotation_sigma);
  report->dropped.insert(report->dropped.end(), forgotten.begin(), forgotten.end());
  candidates->insert(candidates->end(), tracked->begin(), tracked->end());
  tracked->clear();
  report->events.add(FrameEvent::kRightCameraOffEpipolarLines, knock.warning);
  return true;
}

void StereoCalibrationEstimator::linkStereoMatches(
    const std::vector<std::pair<StereoObservation, StereoObservation>>& links) {
  std::vector<std::pair<PointMeasurement, PointMeasurement>> measured;
  for (const auto& [previous, now] : links) {
    PointMeasurement a, b;
    if (toMeasurement(previous, &a) && toMeasurement(now, &b)) measured.emplace_back(a, b);
  }
  baseline_restart_.setLinks(std::move(measured), !links.empty());
}

void StereoCalibrationEstimator::learnBaselineLength(
    const MotionIncrement& motion, bool motion_links_pairs,
    const std::vector<PointMeasurement>& candidates, FrameReport* report) {
  const BaselineReseed reseed =
      baseline_restart_.afterPair(motion, motion_links_pairs, candidates, filter_);
  if (!reseed.reseed) return;
  for (PointId id : reseedRightCamera(reseed.T_caml_camr, reseed.covariance, true))
    report->dropped.push_back(id);
  report->events.add(FrameEvent::kBaselineFromMotion, reseed.message);
}

bool StereoCalibrationEstimator::reopenLeftCameraAfterGap(const MotionIncrement& motion,
                                                          FrameReport* report) {
  const GapDecision decision =
      gap_check_.checkAfterStep(&filter_, motion, report->step, report->consistency);
  followFilter();
  if (!decision.reopened) return false;
  report->dropped.insert(report->dropped.end(), decision.dropped.begin(), decision.dropped.end());
  restart_.anchorReopening(filter_, JumpBlock::kVehicleToLeft, decision.sigma);
  report->events.add(FrameEvent::kLeftCameraReopenedAfterGap, decision.warning);
  return true;
}

std::vector<PointId> StereoCalibrationEstimator::resetTracking() {
  std::vector<PointId> dropped;
  for (const PointEstimate& p : filter_.points()) dropped.push_back(p.id);
  for (PointId id : dropped) filter_.removePoint(id);
  has_previous_frame_ = false;
  mounting_.forgetFrame();
  return dropped;
}

std::vector<PointId> StereoCalibrationEstimator::reopenRightCameraRotation(double rotation_sigma) {
  has_previous_frame_ = false;
  const Vector6d sigma = uniformBlockSigmas(0.0, rotation_sigma);
  std::vector<PointId> dropped = filter_.reopen(JumpBlock::kLeftToRight, sigma);
  followFilter();
  restart_.anchorReopening(filter_, JumpBlock::kLeftToRight, sigma);
  return dropped;
}

namespace {

/// @p covariance with x_camr's block replaced by @p block and its correlations with x_caml
/// dropped.
Matrix12d withRightCamera(Matrix12d covariance, const Matrix6d& block) {
  using namespace layout;
  covariance.middleRows<kPoseDim>(kCamr).setZero();
  covariance.middleCols<kPoseDim>(kCamr).setZero();
  covariance.block<kPoseDim, kPoseDim>(kCamr, kCamr) = block;
  return covariance;
}

}  // namespace

std::vector<PointId> StereoCalibrationEstimator::reseedRightCamera(
    const Eigen::Isometry3d& T_caml_camr, const Matrix6d& covariance, bool start) {
  std::vector<PointId> dropped;
  for (const PointEstimate& p : filter_.points()) dropped.push_back(p.id);
  StereoExtrinsics seeded = filter_.extrinsics();
  seeded.T_caml_camr = T_caml_camr;
  filter_.reset(seeded, withRightCamera(filter_.covariance(), covariance));
  followFilter();
  // Only a start's seed becomes the guess a hand-eye restart returns to. One after a
  // re-opening keeps the translation the filter learned before it, which, before the hand-eye
  // has found x_caml's rotation, was learned with x_caml far off: a backward camera guessed
  // forward had yr 9 sigma off when its first pair off the epipolar lines re-opened x_camr,
  // and the restart two pairs later kept it (HandEyeStart image-level test).
  if (start) {
    guess_.T_caml_camr = T_caml_camr;
    guess_covariance_ = withRightCamera(Matrix12d(guess_covariance_), covariance);
  }
  baseline_restart_.forget();  // its disparities were measured with the old x_camr
  has_previous_frame_ = false;
  mounting_.forgetFrame();
  if (start) {
    restart_.anchorHere(filter_, JumpBlock::kNone, Vector6d::Zero());
  } else {
    restart_.anchorReopening(
        filter_, JumpBlock::kLeftToRight,
        uniformBlockSigmas(std::sqrt(covariance.diagonal().head<3>().maxCoeff()),
                           std::sqrt(covariance.diagonal().tail<3>().maxCoeff())));
  }
  return dropped;
}

void StereoCalibrationEstimator::warnIfNoPointMeasurable(
    const std::vector<PointMeasurement>& tracked, FrameReport* report) {
  // Without this the filter waited in silence: default campaign run 92 with a drawn steering
  // phase had x_camr's rotation re-opened to 8.5 deg, and 40 new points a pair were each
  // dropped at their second pair for 76 pairs (7.6 s at 14 m/s) while x_caml sat 3 sigma off.
  const bool none_measurable = report->step.accepted &&
                               static_cast<int>(tracked.size()) >= config_.jump_min_points &&
                               report->step.measurements_used == 0 && report->step.outliers.empty();
  unmeasurable_pairs_ = none_measurable ? unmeasurable_pairs_ + 1 : 0;
  if (unmeasurable_pairs_ != kUnmeasurablePairsToWarn) return;
  using namespace layout;
  const double rotation_sigma =
      std::sqrt(filter_.covariance().diagonal().segment<3>(kCamr + kRotation).maxCoeff());
  std::ostringstream message;
  message << "no tracked point could be predicted in " << kUnmeasurablePairsToWarn
          << " pairs in a row: all " << tracked.size()
          << " measured in both images were dropped as not measurable (some sigma point "
             "behind a camera; x_camr's rotation 1 sigma "
          << rotation_sigma * 180.0 / M_PI
          << " deg); the calibration is predicted, not updated, until points can be "
             "predicted again";
  report->events.add(FrameEvent::kNoPointMeasurable, message.str());
}

void StereoCalibrationEstimator::forgetDriveEvidence() {
  baseline_restart_.forget();
  held_for_few_points_ = false;
  unmeasurable_pairs_ = 0;
  knock_test_.reset();
  mounting_.clear();
  gap_check_.reset();
  noise_matcher_.reset();
  filter_.setMotionNoiseFactors(noise_matcher_.factors());
}

void StereoCalibrationEstimator::reset(const StereoExtrinsics& guess) {
  guess_ = guess;
  forgetDriveEvidence();
  filter_.reset(guess);
  followFilter();
  guess_covariance_ = filter_.covariance();
  has_previous_frame_ = false;
  restart_.anchorHere(filter_, JumpBlock::kNone, Vector6d::Zero());
}

void StereoCalibrationEstimator::reset(const StereoExtrinsics& guess,
                                       const Matrix12d& tangent_covariance) {
  guess_ = guess;
  forgetDriveEvidence();
  // The given covariance is one as estimate() reports it (a saved calibration): take out what
  // the odometry's scale adds there, so that save -> restore -> estimate() gives it back. If
  // that leaves it indefinite (a prior sharper than the odometry's scale allows, e.g. sigmas
  // only), the filter starts from it as given and reports it widened by the scale.
  const Matrix12d scale = odometryScaleCovariance(config_, guess);
  const Matrix12d internal = tangent_covariance - scale;
  filter_.reset(guess, scale.isZero() || internal.llt().info() != Eigen::Success
                           ? tangent_covariance
                           : Matrix12d(0.5 * (internal + internal.transpose())));
  followFilter();
  guess_covariance_ = filter_.covariance();
  has_previous_frame_ = false;
  restart_.anchorHere(filter_, JumpBlock::kNone, Vector6d::Zero());
}

CalibrationEstimate StereoCalibrationEstimator::estimate() const {
  CalibrationEstimate e;
  e.extrinsics = filter_.extrinsics();
  e.parameters = e.extrinsics.toParameters();
  e.tangent_covariance = filter_.covariance();
  e.parameter_covariance = filter_.parameterCovariance();
  e.odometry_scale_covariance = odometryScaleCovariance(config_, e.extrinsics);
  e.tangent_covariance += e.odometry_scale_covariance;
  e.parameter_covariance += e.odometry_scale_covariance;
  e.tracked_points = filter_.pointCount();
  e.excitation = filter_.excitationGains();
  e.consistency = monitor_.status();
  e.odometry_noise = noise_matcher_.status();
  e.time_offset = filter_.timeOffset();
  e.time_offset_sigma = filter_.timeOffsetSigma();
  e.camr_drift_rate = filter_.camrDriftRate();
  e.camr_drift_rate_sigma = filter_.camrDriftRateSigma();
  return e;
}

}  // namespace osc
