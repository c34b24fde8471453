#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/frontend/left_motion_matches.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Pairs in a row whose refined stereo pairs must lie off their epipolar lines before x_camr
/// is re-opened: one pair may be a glitch (blur, an occlusion, a bad exposure).
constexpr int kKnockedPairsBeforeReopening = 2;
/// Whole-image fits in a row contradicting x_camr before it is re-opened. One: the fit
/// (hundreds of RANSAC inliers over the whole images) is the evidence, and waiting for a
/// second pair kept the knock's own pair 50-180 sigma off (images campaign runs 2, 4, 8, 17 of
/// session 13).
constexpr int kContradictingFitsBeforeReopening = 1;
/// Stereo pairs (tracked, or matched in the epipolar band) in a pair that count as "none".
constexpr int kNoPairs = 5;
/// While the whole-image fits agree with x_camr, one fit in this many pairs without tracked
/// pairs (CalibrationPipeline::wholeImageFitDue).
constexpr int kPairsBetweenAgreeingFits = 5;

}  // namespace

CalibrationPipeline::CalibrationPipeline(const FilterConfig& filter_config,
                                         const FrontEndConfig& front_end_config,
                                         const CameraIntrinsics& left,
                                         const CameraIntrinsics& right,
                                         const StereoExtrinsics& initial_guess)
    : estimator_(
          std::make_unique<StereoCalibrationEstimator>(filter_config, left, right, initial_guess)),
      front_end_(std::make_unique<StereoFrontEnd>(
          front_end_config, filter_config, estimator_->leftCamera(), estimator_->rightCamera())),
      filter_config_(filter_config) {
  armStereoFit(false);
}

CalibrationPipeline::~CalibrationPipeline() = default;

PipelineResult CalibrationPipeline::process(const cv::Mat& left, const cv::Mat& right,
                                            const MotionIncrement& motion_since_last_processed) {
  const auto start = std::chrono::steady_clock::now();
  PipelineResult result;
  const FrontEndConfig& config = front_end_->config();
  cv::Mat left_mono, right_mono;
  std::string problem =
      toCheckedMono8(left, estimator_->leftCamera().intrinsics(), config, "left image", &left_mono);
  if (problem.empty()) {
    problem = toCheckedMono8(right, estimator_->rightCamera().intrinsics(), config, "right image",
                             &right_mono);
  }
  if (problem.empty() && left.size() != right.size()) {
    problem = "left and right images differ in size";
  }
  if (!problem.empty()) {
    // Refused: nothing changes, so the caller's next motion (since the last processed pair)
    // is exactly what the estimator needs.
    result.processed = false;
    result.status = problem;
    result.estimate = estimator_->estimate();
    result.processing_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  }
  result.stereo_pairs = front_end_->observe(left_mono, right_mono, motion_since_last_processed,
                                            estimator_->filter(), &result.front_end);
  std::string seeded;
  if (stereo_fit_attempts_left_ > 0) {
    result.stereo_fit_tried = true;
    if (seedRightRotationFromFit(result.front_end, &seeded)) {
      // The pairs were matched in the epipolar band of the old rotation: again in the fit's.
      front_end_->reset();
      result.stereo_pairs = front_end_->observe(left_mono, right_mono, motion_since_last_processed,
                                                estimator_->filter(), &result.front_end);
    }
    result.stereo_fit = last_seed_;
  }
  linkStereoMatchesToPreviousPair();
  result.estimator = estimator_->processFrame(motion_since_last_processed, result.stereo_pairs);
  front_end_->commit(result.estimator, estimator_->filter());
  keepStereoMatchesForTheNextPair();
  feedHandEye(motion_since_last_processed);
  if (!seeded.empty()) {
    result.estimator.events.addFirst(FrameEvent::kRightRotationFromStereoFit, seeded);
  }
  result.processed = true;
  result.status = result.estimator.has(FrameEvent::kMotionRejected)
                      ? "processed (motion rejected, tracks reset)"
                  : result.estimator.has(FrameEvent::kRelinearized)
                      ? "processed (restarted from the current estimate: re-linearised, tracks "
                        "reset)"
                  : !seeded.empty() ? "processed (" + seeded + ")"
                                    : "ok";
  // A knocked right camera. Beyond the epipolar band of a converged x_camr no pair reaches
  // the filter, so its own jump test never sees one; within it the pairs reach it but, off
  // their lines by tens of its sigmas, are followed only through x_camr's slow drift noise.
  // Re-opening x_camr's rotation widens the band and lets the filter re-converge at once.
  double rotation_sigma = 0.0;
  std::string why;
  const bool reopened_by_estimator = result.estimator.has(FrameEvent::kRightCameraOffEpipolarLines);
  const bool lost = !reopened_by_estimator && lostTheStereoGeometry(result.front_end);
  if (!lost) pairs_since_whole_image_fit_ = -1;  // the next pair without pairs is fitted at once
  if (reopened_by_estimator) {
    // The estimator's own test of the pairs against the epipolar lines (its warning says how
    // far off they were); it re-opened x_camr already.
    why = "the stereo pairs left x_camr's epipolar lines";
  } else if (lost) {
    // No pair may mean a knocked camera or merely a view without usable texture (sky, a
    // wall, darkness, blur): only a whole-image fit that contradicts x_camr re-opens it.
    if (wholeImageFitDue() && wholeImageFitContradicts(&rotation_sigma, &result.status)) {
      why = "no tracked stereo pair, and the whole-image fit contradicts x_camr (" + result.status +
            ")";
    }
  } else if (rightCameraMoved(&rotation_sigma)) {
    why = "the stereo pairs of 2 pairs off their epipolar lines by " +
          std::to_string(front_end_->lastEpipolarTrend().rms()) + " px";
  }
  if (reopened_by_estimator) {
    // It re-initialised this pair's points with the re-opened x_camr, and the front end tracks
    // them on; the pipeline's own knock tests count afresh. A rotation re-opened wide is
    // re-seeded by the next pair's whole-image fit, as below: re-opened to 11 deg at a start
    // (3 times what the pairs indicated, mostly along the lines), image run 15 initialised no
    // point for 40 pairs without it. A small knock is not: the fit's re-seed (and restarting
    // tracking) cost a 0.1 deg knock's image run 7 % of its frames within 3 sigma.
    constexpr double kWideRotation = 1.0 * M_PI / 180.0;  // rad, 1 sigma
    const double reopened_sigma = std::sqrt(estimator_->filter()
                                                .covariance()
                                                .diagonal()
                                                .segment<3>(layout::kCamr + layout::kRotation)
                                                .maxCoeff());
    if (reopened_sigma > kWideRotation) armStereoFit(true);
    pairs_off_their_lines_ = fits_contradicting_ = 0;
    result.right_camera_reopened = true;
    result.status = why +
                    ": x_camr's rotation re-opened (a knocked right camera?), points "
                    "re-initialised";
  } else if (!why.empty()) {
    estimator_->reopenRightCameraRotation(rotation_sigma);
    restartFrontEnd();
    result.right_camera_reopened = true;
    // The next pairs' whole-image fit re-seeds the re-opened rotation (its wide sigma is no
    // evidence for the old mean, and the fit linearises the filter near the new one).
    armStereoFit(true);
    result.status = why +
                    ": x_camr's rotation re-opened (a knocked right camera?), tracking "
                    "restarted";
  }
  result.estimate = estimator_->estimate();
  result.processing_time =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void CalibrationPipeline::linkStereoMatchesToPreviousPair() {
  constexpr double kRatio = 0.8;  // Lowe's ratio test
  if (!estimator_->wantsStereoLinks() || previous_stereo_matches_.empty()) return;
  const std::vector<StereoObservation>& matches = front_end_->lastStereoMatches();
  std::vector<std::pair<StereoObservation, StereoObservation>> links;
  for (const auto& [i, j] : matchDescriptors(previous_stereo_match_descriptors_,
                                             front_end_->lastStereoMatchDescriptors(),
                                             front_end_->lastLeftFeatures().binary, kRatio)) {
    links.emplace_back(previous_stereo_matches_[static_cast<size_t>(i)],
                       matches[static_cast<size_t>(j)]);
  }
  estimator_->linkStereoMatches(std::move(links));
}

void CalibrationPipeline::keepStereoMatchesForTheNextPair() {
  if (estimator_->keepsStereoLinkReference()) return;  // the next pair links to the same one
  if (estimator_->wantsStereoLinks()) {
    previous_stereo_matches_ = front_end_->lastStereoMatches();
    previous_stereo_match_descriptors_ = front_end_->lastStereoMatchDescriptors();
  } else {
    previous_stereo_matches_.clear();
    previous_stereo_match_descriptors_.release();
  }
}

void CalibrationPipeline::feedHandEye(const MotionIncrement& motion) {
  constexpr double kRatio = 0.8;  // Lowe's ratio test
  if (!estimator_->handEyeActive()) {
    has_previous_left_features_ = false;
    previous_left_features_ = FeatureSet();
    return;
  }
  if (has_previous_left_features_ && estimator_->wantsLeftCameraMatches()) {
    std::vector<Eigen::Vector2d> previous, current;
    matchLeftFeatures(previous_left_features_, front_end_->lastLeftFeatures(),
                      estimator_->leftCamera(), kRatio, &previous, &current);
    estimator_->addLeftCameraMatches(motion, previous, current);
  }
  previous_left_features_ = front_end_->lastLeftFeatures();
  has_previous_left_features_ = true;
}

bool CalibrationPipeline::lostTheStereoGeometry(const FrontEndStatistics& stats) const {
  constexpr int kMinFeatures = 200;  // per image: enough texture to expect pairs
  const bool textured = stats.features_left >= kMinFeatures && stats.features_right >= kMinFeatures;
  // Counted are the pairs tracked into this one, not the new matches: after a knock the
  // epipolar band of the old x_camr still holds a few dozen chance matches per pair, but none
  // of them is found again in the next pair (image run 1 of session 13: 20-47 matches and 0
  // tracked for 130 pairs, the filter without a single update). The whole-image fit decides.
  const bool none = stats.tracked <= kNoPairs;
  return textured && none;
}

bool CalibrationPipeline::wholeImageFitDue() {
  // After a contradicting fit every pair is fitted until the next one decides.
  if (fits_contradicting_ > 0 || pairs_since_whole_image_fit_ < 0 ||
      pairs_since_whole_image_fit_ + 1 >= kPairsBetweenAgreeingFits) {
    pairs_since_whole_image_fit_ = 0;
    return true;
  }
  ++pairs_since_whole_image_fit_;
  return false;
}

bool CalibrationPipeline::rightCameraMoved(double* rotation_sigma) {
  constexpr double kMinDistance = 0.3;  // px: three times a refined pair's own noise
  constexpr double kKnockSigmas = 5.0;
  const double focal = estimator_->rightCamera().K()(0, 0);
  const double angle = front_end_->lastEpipolarTrend().rms() / focal;  // rad, small-angle
  const double sigma = std::sqrt(estimator_->filter()
                                     .covariance()
                                     .diagonal()
                                     .segment<3>(layout::kCamr + layout::kRotation)
                                     .maxCoeff());
  const bool moved =
      front_end_->lastEpipolarTrend().rms() >= kMinDistance && angle > kKnockSigmas * sigma;
  pairs_off_their_lines_ = moved ? pairs_off_their_lines_ + 1 : 0;
  *rotation_sigma = 3.0 * angle;
  return pairs_off_their_lines_ >= kKnockedPairsBeforeReopening;
}

bool CalibrationPipeline::wholeImageFitContradicts(double* rotation_sigma, std::string* status) {
  constexpr double kKnockSigmas = 5.0;
  constexpr double kMinAngle = 0.05 * M_PI / 180.0;  // rad: below, not worth a re-opening
  const Eigen::Isometry3d T_lopt_ropt = estimator_->filter().extrinsics().leftToRightOptical();
  ++whole_image_fits_;
  last_fit_ = fitStereoGeometry(front_end_->lastLeftFeatures(), front_end_->lastRightFeatures(),
                                estimator_->leftCamera(), estimator_->rightCamera(),
                                T_lopt_ropt.translation().normalized());
  // Only the rotation about the optical x and z axes (pitch_r, roll_r) moves pixels across
  // the horizontal epipolar lines and starves the matching. The rotation about the optical y
  // axis (yaw_r) only slides them along the lines: one pair barely determines it (on KITTI
  // the fit's is 0.4-0.6 deg off, its sigma 0.03-0.1 deg), and the filter follows it anyway.
  const Eigen::Vector3d& rotation_sigma2 =
      estimator_->filter().covariance().diagonal().segment<3>(layout::kCamr + layout::kRotation);
  const double estimate_sigma = std::sqrt(std::max(rotation_sigma2(0), rotation_sigma2(1)));
  double angle = 0.0;
  bool contradicts = false;
  if (last_fit_.valid) {
    const Eigen::Vector3d difference =
        logSO3(T_lopt_ropt.linear().transpose() * last_fit_.R_lopt_ropt);  // optical axes
    angle = std::hypot(difference.x(), difference.z());
    const Eigen::Matrix3d& C = last_fit_.rotation_covariance;
    const double fit_sigma = std::sqrt(std::max(C(0, 0), C(2, 2)));
    contradicts = angle > kMinAngle && angle > kKnockSigmas * std::hypot(estimate_sigma, fit_sigma);
  }
  fits_contradicting_ = contradicts ? fits_contradicting_ + 1 : 0;
  *rotation_sigma = 3.0 * angle;
  *status = last_fit_.valid ? "whole-image fit " + std::to_string(angle * 180.0 / M_PI) +
                                  " deg from x_camr, " + last_fit_.why
                            : "no whole-image fit: " + last_fit_.why;
  if (!contradicts) {
    *status = "too few tracked stereo pairs (" + *status + "): x_camr kept";
  }
  return fits_contradicting_ >= kContradictingFitsBeforeReopening;
}

bool CalibrationPipeline::seedRightRotationFromFit(const FrontEndStatistics& stats,
                                                   std::string* message) {
  const StereoExtrinsics estimate = estimator_->filter().extrinsics();
  const Eigen::Isometry3d T_lopt_ropt = estimate.leftToRightOptical();
  const Matrix12d covariance = estimator_->filter().covariance();
  GlobalStereoFitConfig fit_config;
  fit_config.baseline_direction_covariance = baselineDirectionCovariance(estimate, covariance);
  last_fit_ = fitStereoGeometry(front_end_->lastLeftFeatures(), front_end_->lastRightFeatures(),
                                estimator_->leftCamera(), estimator_->rightCamera(),
                                T_lopt_ropt.translation().normalized(), fit_config);
  last_seed_ =
      rightRotationSeed(last_fit_, estimate, covariance, filter_config_.stereo_fit_min_sigma,
                        filter_config_.stereo_fit_min_sigma_along_lines);
  --stereo_fit_attempts_left_;
  if (!last_seed_.valid) return false;
  stereo_fit_attempts_left_ = 0;  // one valid fit per start
  const bool after_reopening = stereo_fit_after_reopening_;
  stereo_fit_after_reopening_ = false;
  // Within the guess's uncertainty the fit adds little, unless the guess's epipolar band held
  // (almost) no match: then the fit is the only evidence of x_camr there is (image run 1 of
  // session 14: pitch_r guessed 4.6 deg off at 1 sigma 2 deg, the fit 2.5 sigmas away, and
  // 1-4 matches per pair for 60 pairs).
  const bool band_empty = stats.tracked + stats.stereo_matches <= kNoPairs;
  if (!after_reopening && !band_empty &&
      !(last_seed_.distance > filter_config_.stereo_fit_restart_distance)) {
    return false;
  }
  const Eigen::Vector3d before = rpyFromRotation(estimate.T_caml_camr.linear()) * 180.0 / M_PI;
  const Eigen::Vector3d after = rpyFromRotation(last_seed_.T_caml_camr.linear()) * 180.0 / M_PI;
  const Eigen::Vector3d sigma =
      last_seed_.covariance.diagonal().tail<3>().cwiseSqrt() * 180.0 / M_PI;
  estimator_->reseedRightCamera(last_seed_.T_caml_camr, last_seed_.covariance, !after_reopening);
  std::ostringstream text;
  text.precision(3);
  text << "right camera rotation from the stereo fit: x_camr's roll/pitch/yaw re-seeded "
       << (after_reopening ? "after its re-opening " : "") << "at " << after(0) << "/" << after(1)
       << "/" << after(2) << " deg (1 sigma " << sigma(0) << "/" << sigma(1) << "/" << sigma(2)
       << " deg; was " << before(0) << "/" << before(1) << "/" << before(2) << " deg, "
       << last_seed_.distance << " sigmas and " << last_seed_.angle * 180.0 / M_PI
       << " deg apart; whole-image fit " << last_fit_.why
       << "); baseline direction refined with the guess's as prior, its length kept; tracks "
          "reset";
  *message = text.str();
  return true;
}

void CalibrationPipeline::armStereoFit(bool after_reopening) {
  stereo_fit_attempts_left_ =
      filter_config_.stereo_fit_start ? filter_config_.stereo_fit_attempts : 0;
  stereo_fit_after_reopening_ = after_reopening;
}

void CalibrationPipeline::restartFrontEnd() {
  front_end_->reset();
  pairs_off_their_lines_ = fits_contradicting_ = 0;
  pairs_since_whole_image_fit_ = -1;
}

void CalibrationPipeline::resetTracking() {
  estimator_->resetTracking();
  restartFrontEnd();
}

void CalibrationPipeline::reset(const StereoExtrinsics& guess) {
  estimator_->reset(guess);
  restartFrontEnd();
  armStereoFit(false);
}

void CalibrationPipeline::reset(const StereoExtrinsics& guess,
                                const Matrix12d& tangent_covariance) {
  estimator_->reset(guess, tangent_covariance);
  restartFrontEnd();
  armStereoFit(false);
}

CalibrationEstimate CalibrationPipeline::estimate() const { return estimator_->estimate(); }

std::vector<PointEstimate> CalibrationPipeline::points() const {
  return estimator_->filter().points();
}

cv::Mat CalibrationPipeline::debugImage() const { return front_end_->debugImage(); }

const StereoCalibrationEstimator& CalibrationPipeline::estimator() const { return *estimator_; }

const StereoFrontEnd& CalibrationPipeline::frontEnd() const { return *front_end_; }

}  // namespace osc
