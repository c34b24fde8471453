#include "online_stereo_calibration/core/frontend/left_motion_matches.h"

#include <Eigen/Geometry>
#include <opencv2/features2d.hpp>

namespace osc {

void matchLeftFeatures(const FeatureSet& previous, const FeatureSet& current,
                       const CameraModel& left, double ratio,
                       std::vector<Eigen::Vector2d>* previous_normalized,
                       std::vector<Eigen::Vector2d>* current_normalized) {
  previous_normalized->clear();
  current_normalized->clear();
  if (previous.size() < 2 || current.size() < 2 || previous.binary != current.binary ||
      previous.descriptors.type() != current.descriptors.type() ||
      previous.descriptors.cols != current.descriptors.cols) {
    return;
  }
  cv::BFMatcher matcher(previous.binary ? cv::NORM_HAMMING : cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> forward, backward;
  matcher.knnMatch(previous.descriptors, current.descriptors, forward, 2);
  matcher.knnMatch(current.descriptors, previous.descriptors, backward, 2);
  auto unambiguous = [ratio](const std::vector<cv::DMatch>& m) {
    return m.size() == 2 ? m[0].distance < ratio * m[1].distance : m.size() == 1;
  };
  const Eigen::Matrix3d K_inv = left.K().inverse();
  for (const std::vector<cv::DMatch>& m : forward) {
    if (m.empty() || !unambiguous(m)) continue;
    const int i = m[0].queryIdx, j = m[0].trainIdx;
    const std::vector<cv::DMatch>& back = backward[static_cast<size_t>(j)];
    if (back.empty() || back[0].trainIdx != i || !unambiguous(back)) continue;
    previous_normalized->push_back(
        (K_inv * previous.undistorted[static_cast<size_t>(i)].homogeneous()).hnormalized());
    current_normalized->push_back(
        (K_inv * current.undistorted[static_cast<size_t>(j)].homogeneous()).hnormalized());
  }
}

}  // namespace osc
