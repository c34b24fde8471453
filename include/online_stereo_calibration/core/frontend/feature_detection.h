/// @file feature_detection.h
/// @brief Image checks and conversion to mono8, keypoint detection + description
/// (ORB, FAST_ORB, AKAZE, SIFT) and a spatial grid index over keypoint positions.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"

namespace cv {
class Feature2D;
}

namespace osc {

class OrbDescription;

/// Converts a CV_8UC1, CV_16UC1 (scaled by its bit depth), CV_8UC3 (BGR) or CV_8UC4 (BGRA)
/// image to mono8 and checks it: not empty, at least config.min_image_size, the size the
/// intrinsics say, some contrast (not all black / saturated). Returns "" if usable, else a
/// message starting with `which` (e.g. "left image") naming the problem.
std::string toCheckedMono8(const cv::Mat& image, const CameraIntrinsics& intrinsics,
                           const FrontEndConfig& config, const std::string& which, cv::Mat* mono);

/// Buckets of point indices on a regular grid, for window queries.
class SpatialGrid {
 public:
  /// Indexes points (px) of an image of the given size with square cells.
  void build(const std::vector<Eigen::Vector2d>& points, int width, int height, double cell);
  /// Appends to `out` the indices of points inside [min, max] (box, px): cell by cell, row
  /// by row, and in increasing index within a cell.
  void query(const Eigen::Vector2d& min, const Eigen::Vector2d& max, std::vector<int>* out) const;

 private:
  // The points sorted by cell (row-major, stable): the cells of one grid row that a box
  // covers are one contiguous range, scanned without indirection.
  std::vector<int> cell_start_;                 ///< cols_ * rows_ + 1 offsets into the two below
  std::vector<int> sorted_index_;               ///< point index, in cell order
  std::vector<Eigen::Vector2d> sorted_points_;  ///< its position
  int cols_ = 0, rows_ = 0;
  double cell_ = 1.0;
};

/// Number of differing bits between two binary descriptors of `bytes` bytes.
double hammingDistance(const unsigned char* a, const unsigned char* b, int bytes);

/// The sub-pixel corner near a keypoint `pixel` of a mono8 image: cv::cornerSubPix over a
/// (2 half_size + 1)^2 window, the point where the window's gradients meet (e.g. the junction
/// of two outlines, not a detector's pixel beside it). False, *corner untouched, if it lies
/// farther than `max_shift` px from `pixel` or is not finite.
bool cornerNear(const cv::Mat& image, const Eigen::Vector2d& pixel, int half_size, double max_shift,
                Eigen::Vector2d* corner);

/// The keypoints of one image with their descriptors, raw and undistorted positions.
struct FeatureSet {
  std::vector<Eigen::Vector2d> raw;          ///< raw (distorted) pixel positions
  std::vector<Eigen::Vector2d> undistorted;  ///< undistorted pixels (the filter's space)
  std::vector<float> response;               ///< detector response (larger = stronger)
  cv::Mat descriptors;                       ///< one row per keypoint
  std::vector<float> descriptor_norms;       ///< L2 norms (float descriptors only)
  bool binary = true;                        ///< Hamming (binary) or L2 (float) descriptors
  SpatialGrid raw_grid;                      ///< index over raw positions
  SpatialGrid undistorted_grid;              ///< index over undistorted positions

  size_t size() const { return raw.size(); }
  /// Normalised distance (see FrontEndConfig::max_descriptor_distance) between keypoint i
  /// and a descriptor row of the same type.
  double distance(int i, const cv::Mat& descriptor) const;
  /// The same between keypoint i and keypoint j of `other` (same descriptor type).
  double distance(int i, const FeatureSet& other, int j) const;
};

/// Detects and describes keypoints with the configured detector.
class FeatureDetector {
 public:
  /// @throws std::invalid_argument for an unknown detector name.
  explicit FeatureDetector(const FrontEndConfig& config);
  ~FeatureDetector();

  /// Keypoints of a mono8 image, spread over the detection grid, with raw and undistorted
  /// positions (camera model of that image).
  FeatureSet detect(const cv::Mat& mono, const CameraModel& camera) const;

 private:
  FrontEndConfig config_;
  cv::Ptr<cv::Feature2D> detector_;
  cv::Ptr<cv::Feature2D> describer_;
  /// ORB on one level: its descriptors computed by OrbDescription (the same bits, faster).
  std::unique_ptr<OrbDescription> orb_description_;
};

}  // namespace osc
