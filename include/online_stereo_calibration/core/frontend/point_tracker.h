/// @file point_tracker.h
/// @brief Tracking of the filter's points (seed Sec. II-C): each point is searched only in
/// a window around its predicted pixel in each image, sized from the filter's innovation
/// covariance S, and matched against its stored descriptors.
#pragma once

#include <functional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"

namespace osc {

/// Where to look for one tracked point in the raw images.
struct TrackWindow {
  PointId id = 0;
  Eigen::Vector2d left_center = Eigen::Vector2d::Zero();  ///< predicted raw pixel
  Eigen::Vector2d right_center = Eigen::Vector2d::Zero();
  Eigen::Vector2d left_half = Eigen::Vector2d::Zero();  ///< half-size (px) per axis
  Eigen::Vector2d right_half = Eigen::Vector2d::Zero();
  /// The prediction: [u_l, v_l, u_r, v_r] (undistorted px) and its innovation covariance.
  Eigen::Vector4d z = Eigen::Vector4d::Zero();
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
  /// How much larger the point's patch appears in this left image than in the previous one
  /// (PredictedObservation::depth_ratio).
  double scale = 1.0;
};

/// A tracked point's patch from the left image it was first seen in: the reference that
/// keeps its track on the same surface point (frame-to-frame alignment alone drifts, and
/// follows an outline sliding over the background).
struct TrackAnchor {
  cv::Mat crop;                                           ///< mono8 crop of that left image
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();        ///< the point's pixel in the crop
  Eigen::Vector2d image_pixel = Eigen::Vector2d::Zero();  ///< ... and in that left image (raw)
  double scale = 1.0;  ///< predicted growth of the point's patch since then
};

/// A tracked point found again in both images (indices into the FeatureSets).
struct TrackMatch {
  PointId id = 0;
  int left = -1;
  int right = -1;
};

/// Stored descriptors of the tracked points and the window search.
class PointTracker {
 public:
  explicit PointTracker(const FrontEndConfig& config);

  /// Starts tracking a point with the descriptors it was found with and its left raw pixel.
  void add(PointId id, const cv::Mat& left_descriptor, const cv::Mat& right_descriptor,
           const Eigen::Vector2d& left_pixel);
  /// The left raw pixel (sub-pixel) where the point was last seen; false for an unknown id.
  bool leftPixel(PointId id, Eigen::Vector2d* pixel) const;
  /// Records where the point was seen in the left image of this pair.
  void setLeftPixel(PointId id, const Eigen::Vector2d& pixel);
  /// Keeps `anchor` as the point's first patch (no-op for an unknown id).
  void setAnchor(PointId id, TrackAnchor anchor);
  /// The point's anchor, or nullptr if it has none.
  const TrackAnchor* anchor(PointId id) const;
  /// Multiplies the anchor's scale by this frame's predicted growth of the patch.
  void growAnchor(PointId id, double factor);
  void remove(PointId id);
  void clear() { tracks_.clear(); }
  bool has(PointId id) const { return tracks_.count(id) > 0; }
  size_t size() const { return tracks_.size(); }

  /// Search windows of the tracked points among the predictions: the predicted undistorted
  /// pixels mapped to raw pixels with the camera models, half-size track_window_sigmas times
  /// the raw-pixel sigma (S mapped through the distortion's Jacobian), clamped to
  /// [min_track_window, max_track_window]. Predictions of unknown ids are skipped.
  std::vector<TrackWindow> windows(const std::vector<PredictedObservation>& predictions,
                                   const CameraModel& left, const CameraModel& right) const;

  /// Finds each window's point in both images: the keypoint in the window and inside the
  /// Mahalanobis gate (track_gate_chi2_2dof; the right keypoint's gate conditioned on the
  /// left keypoint through S) closest in descriptor to the stored one, within
  /// max_track_descriptor_distance and passing the ratio test (track_ratio) against the
  /// runner-up; the left and right keypoints must also match each other
  /// (max_descriptor_distance). A keypoint serves one track at most (the better match wins). Found
  /// keypoints are flagged in *_used, and the stored descriptors are refreshed. Points not found in
  /// both images are not returned. If given, `consistent(left_index, right_index)` must accept the
  /// right keypoint for the chosen left one (e.g. the epipolar band of eq. 5-6).
  std::vector<TrackMatch> track(const std::vector<TrackWindow>& windows, const FeatureSet& left,
                                const FeatureSet& right, std::vector<char>* left_used,
                                std::vector<char>* right_used,
                                const std::function<bool(int, int)>& consistent = {});

 private:
  struct Track {
    cv::Mat left_descriptor;
    cv::Mat right_descriptor;
    Eigen::Vector2d left_pixel = Eigen::Vector2d::Zero();
    TrackAnchor anchor;  ///< empty crop: none
  };
  FrontEndConfig config_;
  std::unordered_map<PointId, Track> tracks_;
};

}  // namespace osc
