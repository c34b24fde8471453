#include "online_stereo_calibration/core/frontend/left_motion_matches.h"

#include <algorithm>

#include <Eigen/Geometry>
#include <opencv2/features2d.hpp>

namespace osc {
namespace {

/// Keypoints per image used, the strongest by detector response.
constexpr size_t kMaxKeypoints = 500;

}  // namespace

std::vector<std::pair<int, int>> matchDescriptors(const cv::Mat& previous, const cv::Mat& current,
                                                  bool binary, double ratio) {
  std::vector<std::pair<int, int>> matches;
  if (previous.rows < 1 || current.rows < 1 || previous.type() != current.type() ||
      previous.cols != current.cols) {
    return matches;
  }
  cv::BFMatcher matcher(binary ? cv::NORM_HAMMING : cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> forward, backward;
  matcher.knnMatch(previous, current, forward, 2);
  matcher.knnMatch(current, previous, backward, 2);
  auto unambiguous = [ratio](const std::vector<cv::DMatch>& m) {
    return m.size() == 2 ? m[0].distance < ratio * m[1].distance : m.size() == 1;
  };
  for (const std::vector<cv::DMatch>& m : forward) {
    if (m.empty() || !unambiguous(m)) continue;
    const int i = m[0].queryIdx, j = m[0].trainIdx;
    const std::vector<cv::DMatch>& back = backward[static_cast<size_t>(j)];
    if (back.empty() || back[0].trainIdx != i || !unambiguous(back)) continue;
    matches.emplace_back(i, j);
  }
  return matches;
}

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
  // The strongest keypoints only: brute force over 2000 x 2000 both ways took 110-130 ms a
  // pair; 500 x 500 gives a few hundred matches for the motion fit in a sixteenth of that.
  auto strongest = [](const FeatureSet& set, std::vector<int>* indices, cv::Mat* descriptors) {
    indices->resize(set.size());
    for (size_t i = 0; i < set.size(); ++i) (*indices)[i] = static_cast<int>(i);
    if (indices->size() > kMaxKeypoints) {
      std::nth_element(
          indices->begin(), indices->begin() + kMaxKeypoints, indices->end(), [&set](int a, int b) {
            return set.response[static_cast<size_t>(a)] > set.response[static_cast<size_t>(b)];
          });
      indices->resize(kMaxKeypoints);
    }
    descriptors->create(static_cast<int>(indices->size()), set.descriptors.cols,
                        set.descriptors.type());
    for (size_t k = 0; k < indices->size(); ++k) {
      set.descriptors.row((*indices)[k]).copyTo(descriptors->row(static_cast<int>(k)));
    }
  };
  std::vector<int> previous_index, current_index;
  cv::Mat previous_descriptors, current_descriptors;
  strongest(previous, &previous_index, &previous_descriptors);
  strongest(current, &current_index, &current_descriptors);
  const std::vector<std::pair<int, int>> matches =
      matchDescriptors(previous_descriptors, current_descriptors, previous.binary, ratio);
  const Eigen::Matrix3d K_inv = left.K().inverse();
  for (const auto& [i, j] : matches) {
    const size_t a = static_cast<size_t>(previous_index[static_cast<size_t>(i)]);
    const size_t b = static_cast<size_t>(current_index[static_cast<size_t>(j)]);
    previous_normalized->push_back((K_inv * previous.undistorted[a].homogeneous()).hnormalized());
    current_normalized->push_back((K_inv * current.undistorted[b].homogeneous()).hnormalized());
  }
}

}  // namespace osc
