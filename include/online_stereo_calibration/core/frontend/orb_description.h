/// @file orb_description.h
/// @brief ORB's rotated BRIEF descriptor of keypoints that cv::ORB detected on one pyramid
/// level, bit for bit what cv::ORB::compute gives them, in about a third of its time (the
/// pattern is rotated four points at a time; cv::ORB rotates point by point).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace osc {

/// cv::ORB::create(nfeatures, scale, nlevels = 1, edgeThreshold, 0, WTA_K = 2, FAST_SCORE,
/// patchSize != 31 (its random test pattern; 31 is ORB's learned one, not reproduced here),
/// fastThreshold) in three steps, so that the orientation is only computed for the keypoints
/// kept: detect() gives its keypoints, in its order, without orientation; orient() gives
/// them its angle; compute() its descriptors.
class OrbDescription {
 public:
  OrbDescription(int patch_size, int edge_threshold, int fast_threshold);

  /// cv::ORB's keypoints of one level, best max_keypoints of the FAST corners (score order is
  /// not guaranteed; ties as cv::ORB keeps them), angle -1 until orient().
  void detect(const cv::Mat& mono, int max_keypoints, std::vector<cv::KeyPoint>* keypoints) const;

  /// cv::ORB's angle (intensity centroid over the circular patch, degrees) of each keypoint.
  void orient(const cv::Mat& mono, std::vector<cv::KeyPoint>* keypoints) const;

  /// Least distance (px) of a keypoint from the image border that compute() accepts.
  int border() const { return border_; }

  /// One 32-byte row per keypoint (in order) of a mono8 image, from each keypoint's rounded
  /// position and its angle (degrees, as cv::ORB sets it). False (nothing written) if a
  /// keypoint is closer than border() to the image border or not on level 0.
  bool compute(const cv::Mat& mono, const std::vector<cv::KeyPoint>& keypoints,
               cv::Mat* descriptors) const;

 private:
  static constexpr int kPoints = 512;  ///< 256 tests of two points
  int patch_size_;
  int edge_threshold_;
  int fast_threshold_;
  std::vector<float> pattern_x_, pattern_y_;
  std::vector<int> half_width_;  ///< of the circular patch per row offset 0..patch_size/2
  int border_ = 0;
};

}  // namespace osc
