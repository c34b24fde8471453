#include "online_stereo_calibration/core/frontend/feature_detection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <opencv2/core/version.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/frontend/orb_description.h"

namespace osc {
namespace {

std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

/// Keypoints the detector keeps before the grid spreading (1.5x max_features).
int candidateCount(const FrontEndConfig& config) { return 3 * config.max_features / 2; }

std::string typeText(int type) {
  return "type " + std::to_string(type) + " (depth " + std::to_string(CV_MAT_DEPTH(type)) + ", " +
         std::to_string(CV_MAT_CN(type)) + " channel(s))";
}

}  // namespace

std::string toCheckedMono8(const cv::Mat& image, const CameraIntrinsics& intrinsics,
                           const FrontEndConfig& config, const std::string& which, cv::Mat* mono) {
  if (image.empty()) return which + " is empty";
  if (image.dims != 2) return which + " is not a 2D image";
  const int type = image.type();
  if (type != CV_8UC1 && type != CV_16UC1 && type != CV_8UC3 && type != CV_8UC4) {
    return which + " has unsupported " + typeText(type) +
           "; supported: CV_8UC1 (mono8), CV_16UC1 (mono16), CV_8UC3 (bgr8), CV_8UC4 (bgra8)";
  }
  if (image.cols < config.min_image_size || image.rows < config.min_image_size) {
    return which + " is too small (" + sizeText(image.cols, image.rows) + ", least " +
           std::to_string(config.min_image_size) + " px per axis)";
  }
  if (image.cols != intrinsics.width || image.rows != intrinsics.height) {
    return which + " size " + sizeText(image.cols, image.rows) +
           " does not match the camera intrinsics (" +
           sizeText(intrinsics.width, intrinsics.height) + ")";
  }
  switch (type) {
    case CV_8UC1:
      *mono = image;
      break;
    case CV_8UC3:
      cv::cvtColor(image, *mono, cv::COLOR_BGR2GRAY);
      break;
    case CV_8UC4:
      cv::cvtColor(image, *mono, cv::COLOR_BGRA2GRAY);
      break;
    case CV_16UC1: {
      // Scale by the bit depth the data uses (10, 12, 16 bit ...), not by the frame's range,
      // so that the brightness of consecutive frames stays comparable.
      double max_value = 0.0;
      cv::minMaxLoc(image, nullptr, &max_value);
      int bits = 8;
      while (bits < 16 && max_value > std::pow(2.0, bits) - 1.0) ++bits;
      image.convertTo(*mono, CV_8U, 255.0 / (std::pow(2.0, bits) - 1.0));
      break;
    }
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(*mono, mean, stddev);
  if (stddev[0] < config.min_contrast) {
    const char* what = mean[0] < 16.0 ? "all black" : mean[0] > 239.0 ? "saturated" : "uniform";
    return which + " has no contrast (" + what + ": mean " + std::to_string(mean[0]) + ", std " +
           std::to_string(stddev[0]) + " grey levels, least " +
           std::to_string(config.min_contrast) + ")";
  }
  return "";
}

void SpatialGrid::build(const std::vector<Eigen::Vector2d>& points, int width, int height,
                        double cell) {
  cell_ = std::max(cell, 1.0);
  cols_ = std::max(1, static_cast<int>(std::ceil(width / cell_)));
  rows_ = std::max(1, static_cast<int>(std::ceil(height / cell_)));
  // Counting sort by cell.
  std::vector<int> cell_of(points.size());
  cell_start_.assign(static_cast<size_t>(cols_ * rows_ + 1), 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const int c = std::clamp(static_cast<int>(std::floor(points[i].x() / cell_)), 0, cols_ - 1);
    const int r = std::clamp(static_cast<int>(std::floor(points[i].y() / cell_)), 0, rows_ - 1);
    cell_of[i] = r * cols_ + c;
    ++cell_start_[static_cast<size_t>(cell_of[i] + 1)];
  }
  for (size_t k = 1; k < cell_start_.size(); ++k) cell_start_[k] += cell_start_[k - 1];
  std::vector<int> next(cell_start_.begin(), cell_start_.end() - 1);
  sorted_index_.resize(points.size());
  sorted_points_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t slot = static_cast<size_t>(next[static_cast<size_t>(cell_of[i])]++);
    sorted_index_[slot] = static_cast<int>(i);
    sorted_points_[slot] = points[i];
  }
}

void SpatialGrid::query(const Eigen::Vector2d& min, const Eigen::Vector2d& max,
                        std::vector<int>* out) const {
  if (sorted_index_.empty() || !min.allFinite() || !max.allFinite()) return;
  const int c0 = std::clamp(static_cast<int>(std::floor(min.x() / cell_)), 0, cols_ - 1);
  const int c1 = std::clamp(static_cast<int>(std::floor(max.x() / cell_)), 0, cols_ - 1);
  const int r0 = std::clamp(static_cast<int>(std::floor(min.y() / cell_)), 0, rows_ - 1);
  const int r1 = std::clamp(static_cast<int>(std::floor(max.y() / cell_)), 0, rows_ - 1);
  const double x_min = min.x(), x_max = max.x(), y_min = min.y(), y_max = max.y();
  for (int r = r0; r <= r1; ++r) {
    const int first = cell_start_[static_cast<size_t>(r * cols_ + c0)];
    const int last = cell_start_[static_cast<size_t>(r * cols_ + c1 + 1)];
    for (int k = first; k < last; ++k) {
      const Eigen::Vector2d& p = sorted_points_[static_cast<size_t>(k)];
      if (p.x() >= x_min && p.x() <= x_max && p.y() >= y_min && p.y() <= y_max) {
        out->push_back(sorted_index_[static_cast<size_t>(k)]);
      }
    }
  }
}

bool cornerNear(const cv::Mat& image, const Eigen::Vector2d& pixel, int half_size, double max_shift,
                Eigen::Vector2d* corner) {
  std::vector<cv::Point2f> at = {
      cv::Point2f(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()))};
  cv::cornerSubPix(image, at, cv::Size(half_size, half_size), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01));
  const Eigen::Vector2d found(at[0].x, at[0].y);
  if (!found.allFinite() || (found - pixel).norm() > max_shift) return false;
  *corner = found;
  return true;
}

// The x86-64 baseline has no popcount instruction (GCC calls a library routine, ~2 % of a
// frame): a second version for CPUs with POPCNT, chosen at load time.
#if defined(__x86_64__) && defined(__GNUC__) && defined(__GLIBC__)  // ifunc: glibc
#define OSC_WITH_POPCNT_CLONE __attribute__((target_clones("popcnt", "default")))
#else
#define OSC_WITH_POPCNT_CLONE
#endif

OSC_WITH_POPCNT_CLONE double hammingDistance(const unsigned char* a, const unsigned char* b,
                                             int bytes) {
  int bits = 0;
  int k = 0;
  for (; k + 8 <= bytes; k += 8) {
    std::uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    bits += __builtin_popcountll(x ^ y);
  }
  for (; k < bytes; ++k) bits += __builtin_popcount(static_cast<unsigned>(a[k] ^ b[k]));
  return static_cast<double>(bits);
}

double FeatureSet::distance(int i, const cv::Mat& descriptor) const {
  if (binary) {
    return hammingDistance(descriptors.ptr<unsigned char>(i), descriptor.ptr<unsigned char>(0),
                           descriptors.cols) /
           (8.0 * descriptors.cols);
  }
  const cv::Mat row = descriptors.row(i);
  const double n2 = static_cast<double>(descriptor_norms[static_cast<size_t>(i)]) *
                        descriptor_norms[static_cast<size_t>(i)] +
                    cv::norm(descriptor, cv::NORM_L2SQR);
  if (n2 <= 0.0) return 1.0;
  return cv::norm(row, descriptor, cv::NORM_L2) / std::sqrt(n2);
}

double FeatureSet::distance(int i, const FeatureSet& other, int j) const {
  if (binary && other.binary) {
    return hammingDistance(descriptors.ptr<unsigned char>(i),
                           other.descriptors.ptr<unsigned char>(j), descriptors.cols) /
           (8.0 * descriptors.cols);
  }
  return distance(i, other.descriptors.row(j));
}

FeatureDetector::FeatureDetector(const FrontEndConfig& config) : config_(config) {
  const int candidates = candidateCount(config);
  if (config.detector == "ORB") {
    constexpr int kPatchSize = 19, kEdgeThreshold = 19;
    auto orb = cv::ORB::create(candidates, static_cast<float>(config.orb_scale_factor),
                               config.orb_levels, kEdgeThreshold, 0, 2, cv::ORB::FAST_SCORE,
                               kPatchSize, config.fast_threshold);
    detector_ = orb;
    describer_ = orb;
    if (config.orb_levels == 1) {
      orb_description_ =
          std::make_unique<OrbDescription>(kPatchSize, kEdgeThreshold, config.fast_threshold);
    }
  } else if (config.detector == "FAST_ORB") {
    detector_ = cv::FastFeatureDetector::create(config.fast_threshold, true);
    describer_ = cv::ORB::create(candidates, 1.2f, 1, 19, 0, 2, cv::ORB::FAST_SCORE, 19,
                                 config.fast_threshold);
  } else if (config.detector == "AKAZE") {
    auto akaze = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, 0.0005f);
    detector_ = akaze;
    describer_ = akaze;
  } else if (config.detector == "SIFT") {
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 4)
    auto sift = cv::SIFT::create(candidates);
    detector_ = sift;
    describer_ = sift;
#else  // Ubuntu 20.04 ships OpenCV 4.2, where SIFT lives in the contrib module xfeatures2d.
    throw std::invalid_argument(
        "FrontEndConfig.detector: SIFT needs OpenCV >= 4.4 (this build has " CV_VERSION
        "); use ORB, FAST_ORB or AKAZE");
#endif
  } else {
    throw std::invalid_argument("FrontEndConfig.detector: unknown detector '" + config.detector +
                                "' (ORB, FAST_ORB, AKAZE, SIFT)");
  }
}

FeatureDetector::~FeatureDetector() = default;

FeatureSet FeatureDetector::detect(const cv::Mat& mono, const CameraModel& camera) const {
  std::vector<cv::KeyPoint> all;
  if (orb_description_) {
    // ORB's keypoints without their orientation: only the ones kept below get one.
    orb_description_->detect(mono, candidateCount(config_), &all);
  } else {
    detector_->detect(mono, all);
  }
  const float border = static_cast<float>(config_.border);
  all.erase(std::remove_if(all.begin(), all.end(),
                           [&](const cv::KeyPoint& k) {
                             return k.pt.x < border || k.pt.y < border ||
                                    k.pt.x > mono.cols - 1 - border ||
                                    k.pt.y > mono.rows - 1 - border;
                           }),
            all.end());
  std::sort(all.begin(), all.end(),
            [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });

  // Spread: each grid cell first gets its quota of its strongest keypoints, the rest of the
  // budget goes to the strongest remaining ones.
  const int grid = config_.detection_grid;
  const size_t budget = static_cast<size_t>(config_.max_features);
  std::vector<cv::KeyPoint> selected;
  if (all.size() <= budget || grid <= 1) {
    all.resize(std::min(all.size(), budget));
    selected = all;
  } else {
    const int quota = std::max(1, config_.max_features / (grid * grid));
    std::vector<int> count(static_cast<size_t>(grid * grid), 0);
    std::vector<char> taken(all.size(), 0);
    for (size_t i = 0; i < all.size() && selected.size() < budget; ++i) {
      const int c = std::min(grid - 1, static_cast<int>(all[i].pt.x * grid / mono.cols));
      const int r = std::min(grid - 1, static_cast<int>(all[i].pt.y * grid / mono.rows));
      int& n = count[static_cast<size_t>(r * grid + c)];
      if (n < quota) {
        ++n;
        taken[i] = 1;
        selected.push_back(all[i]);
      }
    }
    for (size_t i = 0; i < all.size() && selected.size() < budget; ++i) {
      if (!taken[i]) selected.push_back(all[i]);
    }
  }

  FeatureSet set;
  cv::Mat descriptors;
  // A keypoint the lens model has no ray for (beyond the fold of a strong distortion
  // polynomial, camera_model.h) cannot be measured: dropped before it is described.
  Eigen::Vector2d unused;
  selected.erase(std::remove_if(selected.begin(), selected.end(),
                                [&](const cv::KeyPoint& k) {
                                  return !camera.undistortPixel(Eigen::Vector2d(k.pt.x, k.pt.y),
                                                                &unused);
                                }),
                 selected.end());
  if (orb_description_) orb_description_->orient(mono, &selected);
  if (!selected.empty() &&
      !(orb_description_ && orb_description_->compute(mono, selected, &descriptors))) {
    describer_->compute(mono, selected, descriptors);
  }
  set.descriptors = descriptors;
  set.binary = descriptors.empty() || descriptors.depth() == CV_8U;
  set.raw.reserve(selected.size());
  set.undistorted.reserve(selected.size());
  set.response.reserve(selected.size());
  for (const cv::KeyPoint& k : selected) {
    const Eigen::Vector2d raw(k.pt.x, k.pt.y);
    set.raw.push_back(raw);
    set.undistorted.push_back(camera.undistortPixel(raw));
    set.response.push_back(k.response);
  }
  if (!set.binary) {
    set.descriptor_norms.resize(selected.size());
    for (size_t i = 0; i < selected.size(); ++i) {
      set.descriptor_norms[i] = static_cast<float>(cv::norm(descriptors.row(static_cast<int>(i))));
    }
  }
  set.raw_grid.build(set.raw, mono.cols, mono.rows, 16.0);
  set.undistorted_grid.build(set.undistorted, mono.cols, mono.rows, 16.0);
  return set;
}

}  // namespace osc
