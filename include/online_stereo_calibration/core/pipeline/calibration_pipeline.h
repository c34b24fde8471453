/// @file calibration_pipeline.h
/// @brief Images in, calibration out: the image front end (detection, epipolar-guided
/// stereo matching, bucketing, tracking; seed Sec. II-A and II-C) feeding the estimator.
/// The one entry point for the ROS nodelet and the offline bag evaluator.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/pipeline/right_rotation_seed.h"

namespace osc {

class StereoFrontEnd;

/// Counts of what the front end did with one image pair.
struct FrontEndStatistics {
  int features_left = 0;   ///< keypoints detected in the left image
  int features_right = 0;  ///< keypoints detected in the right image
  int stereo_matches = 0;  ///< epipolar-guided matches before bucketing
  int new_candidates = 0;  ///< matches kept by bucketing and offered as new points
  int tracked = 0;         ///< tracked points found again in both images
  int track_failures = 0;  ///< tracked points not found (then removed, Sec. II-C)
};

/// What processing one image pair produced.
struct PipelineResult {
  /// False if the pair was not used (bad image, unsupported encoding, size mismatch...);
  /// the estimator is then untouched and status says why.
  bool processed = false;
  std::string status;
  FrameReport estimator;  ///< the estimator's report (valid if processed)
  FrontEndStatistics front_end;
  /// The stereo pairs of this image pair handed to the estimator (tracked points, then new
  /// candidates; raw pixels), e.g. for the rectification error (live_rectification.h).
  std::vector<StereoObservation> stereo_pairs;
  CalibrationEstimate estimate;  ///< the estimate after this pair
  /// A knocked right camera: (almost) no stereo pair tracked into this pair although both
  /// images had features and the pair's whole-image fit contradicts x_camr, or the
  /// refined pairs of this and the previous pair off their epipolar lines by far more than
  /// x_camr's sigma allows.
  /// x_camr's rotation was re-opened and tracking restarted (also when the estimator found
  /// the pairs off x_camr's epipolar lines: estimator's event kRightCameraOffEpipolarLines).
  bool right_camera_reopened = false;
  /// The whole-image stereo fit at a start was tried in this pair
  /// (FilterConfig::stereo_fit_start); stereo_fit is its seed (valid if the fit was), and
  /// the estimator's event kRightRotationFromStereoFit says whether x_camr's rotation was
  /// re-seeded.
  bool stereo_fit_tried = false;
  RightRotationSeed stereo_fit;
  double processing_time = 0.0;  ///< seconds spent on this pair (front end + filter)
};

/// The image pipeline. Not thread-safe: call from one thread.
class CalibrationPipeline {
 public:
  /// @throws std::invalid_argument naming the bad config value or camera field.
  CalibrationPipeline(const FilterConfig& filter_config, const FrontEndConfig& front_end_config,
                      const CameraIntrinsics& left, const CameraIntrinsics& right,
                      const StereoExtrinsics& initial_guess);
  ~CalibrationPipeline();
  CalibrationPipeline(const CalibrationPipeline&) = delete;
  CalibrationPipeline& operator=(const CalibrationPipeline&) = delete;

  /// Processes one synchronized stereo pair. Images: CV_8UC1, CV_16UC1, CV_8UC3 (BGR) or
  /// CV_8UC4 (BGRA), raw (distorted, as the camera models say) or rectified; the sizes must
  /// match the camera intrinsics.
  ///
  /// @p motion_since_last_processed is the vehicle motion between the stamp of the last pair
  /// this returned processed = true for and this pair's stamp (ignored for the first pair).
  /// A refused pair (processed = false) changes no state at all: the caller keeps its last
  /// processed stamp, so every motion handed to the estimator spans exactly the time between
  /// two processed pairs (a refused pair's motion is never counted twice).
  PipelineResult process(const cv::Mat& left, const cv::Mat& right,
                         const MotionIncrement& motion_since_last_processed);

  /// Forgets all tracks (e.g. time jumped back); the calibration is kept.
  void resetTracking();
  /// Starts over from a guess (config's initial sigmas) or from a saved covariance.
  void reset(const StereoExtrinsics& guess);
  void reset(const StereoExtrinsics& guess, const Matrix12d& tangent_covariance);

  CalibrationEstimate estimate() const;
  /// Tracked points in the left optical frame with their covariances.
  std::vector<PointEstimate> points() const;
  /// The last processed pair drawn side by side (BGR): tracks, new matches, search windows
  /// and epipolar bands. Rendering costs time: only call it when someone looks.
  cv::Mat debugImage() const;

  const StereoCalibrationEstimator& estimator() const;
  /// The front end, for diagnostics and tests (last pair's tracks, matches, windows).
  const StereoFrontEnd& frontEnd() const;
  /// Whole-image fits made by the knock test so far (wholeImageFitDue), for tests.
  int wholeImageFits() const { return whole_image_fits_; }

 private:
  /// Forgets the front end's tracks and the counts below (the estimator's points are the
  /// caller's to drop).
  void restartFrontEnd();
  /// The stereo fit at a start or after a re-opening of x_camr's rotation
  /// (FilterConfig::stereo_fit_start): fits the last pair over the whole images and, if
  /// x_camr's rotation is farther from the fit's than stereo_fit_restart_distance, or its
  /// epipolar band held (almost) no stereo match in that pair (@p stats; after a re-opening:
  /// always), re-seeds x_camr from the fit (rightRotationSeed). True if it did; @p message
  /// then says what changed. A valid fit ends the attempts.
  bool seedRightRotationFromFit(const FrontEndStatistics& stats, std::string* message);
  /// Arms the stereo fit for the next pairs (FilterConfig::stereo_fit_*): after a start, or
  /// @p after_reopening of x_camr's rotation.
  void armStereoFit(bool after_reopening);
  /// True for a pair into which (almost) no stereo pair was tracked although both images had
  /// features: a knocked right camera, or a view without usable texture (the whole-image fit
  /// tells).
  bool lostTheStereoGeometry(const FrontEndStatistics& stats) const;
  /// After lostTheStereoGeometry: fits the pair's epipolar geometry over the whole images
  /// (fitStereoGeometry) and counts fits whose rotation across the epipolar lines (about the
  /// optical x and z axes) is more than kKnockSigmas combined sigmas (and 0.05 deg) from
  /// x_camr's; true for such a fit, with 3 times that angle as the rotation sigma to re-open
  /// with. @p status says what was seen.
  bool wholeImageFitContradicts(double* rotation_sigma, std::string* status);
  /// Whether this pair without tracked pairs gets the whole-image fit (~100 ms on a 1242 px
  /// pair): the first such pair, then every kPairsBetweenAgreeingFits-th while the fits agree
  /// with x_camr (a start whose points cannot be initialised, a texture-poor stretch), so that
  /// a pair without points costs no more than one with them.
  bool wholeImageFitDue();
  /// Counts pairs whose refined pairs lie off their epipolar lines (EpipolarTrend) by an angle
  /// of more than kKnockSigmas x_camr rotation sigmas; true from the second in a row, with
  /// the rotation sigma that distance calls for.
  bool rightCameraMoved(double* rotation_sigma);

  std::unique_ptr<StereoCalibrationEstimator> estimator_;
  std::unique_ptr<StereoFrontEnd> front_end_;
  /// Consecutive processed pairs whose refined pairs lay off their lines (rightCameraMoved).
  int pairs_off_their_lines_ = 0;
  /// Consecutive whole-image fits contradicting x_camr (wholeImageFitContradicts).
  int fits_contradicting_ = 0;
  /// Pairs without tracked pairs since the last whole-image fit (wholeImageFitDue); -1: the
  /// next such pair gets one.
  int pairs_since_whole_image_fit_ = -1;
  int whole_image_fits_ = 0;
  GlobalStereoFit last_fit_;
  RightRotationSeed last_seed_;
  /// Pairs left in which the stereo fit at a start is tried (0: none pending).
  int stereo_fit_attempts_left_ = 0;
  /// The pending fit follows a re-opening of x_camr's rotation: its first valid fit re-seeds
  /// whatever the distance.
  bool stereo_fit_after_reopening_ = false;
  FilterConfig filter_config_;
  /// The previous processed pair's left keypoints, kept while the estimator's hand-eye start
  /// collects (feedHandEye).
  FeatureSet previous_left_features_;
  bool has_previous_left_features_ = false;
  /// The hand-eye start at image level: the left images' own keypoint matches when the
  /// estimator's tracks gave it no pair (StereoCalibrationEstimator::wantsLeftCameraMatches).
  void feedHandEye(const MotionIncrement& motion);
  /// The baseline's length from motion at image level: the front end keeps no track of pairs
  /// the filter refused, so while the estimator wants them (wantsStereoLinks) this pair's stereo
  /// matches are matched to the previous pair's by their left descriptors and handed over
  /// (before processFrame).
  void linkStereoMatchesToPreviousPair();
  /// After a pair: its stereo matches kept while the estimator wants links, else forgotten.
  void keepStereoMatchesForTheNextPair();
  /// The previous pair's stereo matches (raw pixels) and their left descriptors (one row each).
  std::vector<StereoObservation> previous_stereo_matches_;
  cv::Mat previous_stereo_match_descriptors_;
};

}  // namespace osc
