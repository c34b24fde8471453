/// @file stereo_front_end.h
/// @brief The image front end of one stereo stream (seed Sec. II-A, II-C): per pair,
/// predicted windows for the tracked points -> tracking -> detection and epipolar-guided
/// matching of new points -> bucketing; then the estimator's report closes the frame.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/estimator/stereo_calibration_estimator.h"
#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/frontend/epipolar_matcher.h"
#include "online_stereo_calibration/core/frontend/epipolar_trend.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/frontend/point_tracker.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"

namespace osc {

/// Front end of one stereo camera pair. Not thread-safe.
class StereoFrontEnd {
 public:
  /// @throws std::invalid_argument listing FrontEndConfig::validate() problems.
  StereoFrontEnd(const FrontEndConfig& config, const FilterConfig& filter_config,
                 const CameraModel& left, const CameraModel& right);

  /// First half of a frame: tracks the filter's points (windows from
  /// filter.predictObservations(motion)), detects and matches new ones with the filter's
  /// current x_camr and its covariance. Returns the observations for
  /// StereoCalibrationEstimator::processFrame: the tracked points with their ids, then the
  /// new candidates with fresh ids. Images: mono8 of the cameras' sizes.
  std::vector<StereoObservation> observe(const cv::Mat& left_mono, const cv::Mat& right_mono,
                                         const MotionIncrement& motion,
                                         const CalibrationFilter& filter,
                                         FrontEndStatistics* statistics);

  /// Second half: forgets the dropped points, adopts the new candidates the filter took.
  void commit(const FrameReport& report, const CalibrationFilter& filter);

  /// Forgets every track.
  void reset();

  /// Tracked points found in the last pair (raw pixels, with ids).
  const std::vector<StereoObservation>& lastTracked() const { return last_tracked_; }
  /// New candidates offered in the last pair (raw pixels, with their fresh ids).
  const std::vector<StereoObservation>& lastNewCandidates() const { return last_new_; }
  /// The epipolar-guided matches of the last pair that passed every check of a new point
  /// (mutual descriptor match, depth range and parallax, sub-pixel alignment) before the
  /// distance to tracks and bucketing select among them (raw pixels, refined right pixel,
  /// id 0).
  const std::vector<StereoObservation>& lastStereoMatches() const { return last_matches_; }
  /// The left keypoints' descriptors of lastStereoMatches(), one row each in the same order.
  cv::Mat lastStereoMatchDescriptors() const;
  /// Search windows of the last pair.
  const std::vector<TrackWindow>& lastWindows() const { return last_windows_; }
  /// The last pair's common distance of refined pairs from their epipolar lines.
  const EpipolarTrend& lastEpipolarTrend() const { return epipolar_trend_; }
  /// Points being tracked.
  size_t trackCount() const { return tracker_.size(); }
  /// The keypoints detected in the last pair's left and right images.
  const FeatureSet& lastLeftFeatures() const { return left_features_; }
  const FeatureSet& lastRightFeatures() const { return right_features_; }

  /// The last pair side by side (BGR): tracks green, new candidates blue with their
  /// epipolar bands (centre line and band edges, eq. 5-6) magenta in the right image, other
  /// stereo matches grey, search windows yellow (left) / cyan (right). Empty before the
  /// first pair.
  cv::Mat debugImage() const;

  const FrontEndConfig& config() const { return config_; }

 private:
  FrontEndConfig config_;
  FilterConfig filter_config_;
  CameraModel left_camera_, right_camera_;
  FeatureDetector detector_;
  EpipolarMatcher matcher_;
  PointTracker tracker_;
  PointId next_id_ = 1;

  /// Polylines (raw right pixels) of one epipolar band: lower edge, centre, upper edge.
  struct EpipolarBand {
    std::vector<cv::Point2f> lines[3];
  };
  EpipolarBand bandPolylines(const Eigen::Vector2d& left_undistorted,
                             const Eigen::Vector2d& right_undistorted) const;
  /// After a sudden change most tracks are far from their windows: when fewer than
  /// reacquire_below_fraction of them were found, the lost ones are searched over the whole
  /// image by descriptor and appended to *found (the filter then gates them as outliers).
  void reacquireLostTracks(const FeatureSet& left, const FeatureSet& right,
                           const std::function<bool(int, int)>& consistent,
                           std::vector<char>* left_used, std::vector<char>* right_used,
                           std::vector<TrackMatch>* found);

  struct Pending {
    PointId id;
    cv::Mat left_descriptor, right_descriptor;
    Eigen::Vector2d left_pixel;
    TrackAnchor anchor;
  };
  std::vector<Pending> pending_;
  cv::Mat last_left_, last_right_;
  FeatureSet left_features_, right_features_;  ///< of the last pair
  cv::Mat previous_left_, current_left_;       ///< copies: the left images of the last two pairs
  /// The last pair's common epipolar distance of refined pairs, for a frame with too few
  /// tracked pairs to fit its own.
  EpipolarTrend epipolar_trend_;
  std::vector<StereoObservation> last_tracked_, last_new_, last_matches_;
  std::vector<int> last_match_keypoints_;  ///< left keypoint of each of last_matches_
  std::vector<TrackWindow> last_windows_;
  std::vector<EpipolarBand> last_bands_;
};

}  // namespace osc
