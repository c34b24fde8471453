/// @file orb_description.h
/// @brief ORB's rotated BRIEF descriptor of keypoints that cv::ORB detected on one pyramid
/// level, bit for bit what cv::ORB::compute gives them, in about a third of its time (the
/// pattern is rotated four points at a time; cv::ORB rotates point by point).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace osc {

/// The descriptor of cv::ORB::create(..., nlevels = 1, ..., WTA_K = 2, ..., patchSize) for
/// patchSize != 31 (its random test pattern; 31 is ORB's learned one, not reproduced here).
class OrbDescription {
 public:
  explicit OrbDescription(int patch_size);

  /// Least distance (px) of a keypoint from the image border that compute() accepts.
  int border() const { return border_; }

  /// One 32-byte row per keypoint (in order) of a mono8 image, from each keypoint's rounded
  /// position and its angle (degrees, as cv::ORB sets it). False (nothing written) if a
  /// keypoint is closer than border() to the image border or not on level 0.
  bool compute(const cv::Mat& mono, const std::vector<cv::KeyPoint>& keypoints,
               cv::Mat* descriptors) const;

 private:
  static constexpr int kPoints = 512;  ///< 256 tests of two points
  std::vector<float> pattern_x_, pattern_y_;
  int border_ = 0;
};

}  // namespace osc
