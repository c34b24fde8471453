/// @file left_motion_matches.h
/// @brief Correspondences between two consecutive left images from their keypoints alone
/// (mutual nearest descriptors with a ratio test), without any calibration: what the hand-eye
/// start (mounting_from_motion.h) needs at image level when x_caml is so far off that the
/// front end's predicted windows lose every track.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"

namespace osc {

/// Mutual best matches between descriptor rows (Hamming if @p binary, else L2), each better
/// than @p ratio times the second best in both directions (Lowe's ratio test): pairs of
/// (row of @p previous, row of @p current). Rows of different types or lengths give none.
std::vector<std::pair<int, int>> matchDescriptors(const cv::Mat& previous, const cv::Mat& current,
                                                  bool binary, double ratio);

/// Matches the 500 strongest keypoints (detector response) of the previous left image to the
/// current one's 500: mutual best
/// descriptor matches, each better than @p ratio times the second best in both directions.
/// Outputs the matched keypoints' normalised undistorted coordinates (x/z, y/z, optical frame),
/// in the same order. Descriptors of different types give no match.
void matchLeftFeatures(const FeatureSet& previous, const FeatureSet& current,
                       const CameraModel& left, double ratio,
                       std::vector<Eigen::Vector2d>* previous_normalized,
                       std::vector<Eigen::Vector2d>* current_normalized);

}  // namespace osc
