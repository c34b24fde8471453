#include "online_stereo_calibration/core/frontend/point_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace osc {
namespace {

/// Raw pixel of an undistorted pixel.
Eigen::Vector2d toRaw(const CameraModel& camera, const Eigen::Vector2d& undistorted) {
  const Eigen::Matrix3d& K = camera.K();
  const Eigen::Vector2d normalized((undistorted.x() - K(0, 2)) / K(0, 0),
                                   (undistorted.y() - K(1, 2)) / K(1, 1));
  return camera.normalizedToPixel(normalized);
}

/// Window of one image: S (undistorted px^2) mapped to raw pixels through the numerical
/// Jacobian of the distortion.
void window(const CameraModel& camera, const Eigen::Vector2d& z, const Eigen::Matrix2d& S,
            const FrontEndConfig& config, Eigen::Vector2d* center, Eigen::Vector2d* half) {
  *center = toRaw(camera, z);
  Eigen::Matrix2d J;
  const double h = 0.5;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d dz = Eigen::Vector2d::Zero();
    dz(k) = h;
    J.col(k) = (toRaw(camera, z + dz) - toRaw(camera, z - dz)) / (2.0 * h);
  }
  const Eigen::Matrix2d S_raw = J * S * J.transpose();
  for (int k = 0; k < 2; ++k) {
    const double sigma = std::sqrt(std::max(0.0, S_raw(k, k)));
    (*half)(k) = std::clamp(config.track_window_sigmas * sigma, config.min_track_window,
                            config.max_track_window);
  }
}

struct Candidate {
  int index = -1;
  double distance = std::numeric_limits<double>::infinity();
};

Candidate bestInWindow(const FeatureSet& set, const Eigen::Vector2d& center,
                       const Eigen::Vector2d& half, const cv::Mat& descriptor,
                       std::vector<int>* scratch, const std::function<bool(int)>& accept = {}) {
  scratch->clear();
  set.raw_grid.query(center - half, center + half, scratch);
  Candidate best;
  for (int j : *scratch) {
    if (accept && !accept(j)) continue;
    const double d = set.distance(j, descriptor);
    if (d < best.distance) best = {j, d};
  }
  return best;
}

}  // namespace

PointTracker::PointTracker(const FrontEndConfig& config) : config_(config) {}

void PointTracker::add(PointId id, const cv::Mat& left_descriptor,
                       const cv::Mat& right_descriptor) {
  tracks_[id] = Track{left_descriptor.clone(), right_descriptor.clone()};
}

void PointTracker::remove(PointId id) { tracks_.erase(id); }

std::vector<TrackWindow> PointTracker::windows(const std::vector<PredictedObservation>& predictions,
                                               const CameraModel& left,
                                               const CameraModel& right) const {
  std::vector<TrackWindow> result;
  result.reserve(predictions.size());
  for (const PredictedObservation& p : predictions) {
    if (!has(p.id) || !p.z.allFinite() || !p.S.allFinite()) continue;
    TrackWindow w;
    w.id = p.id;
    window(left, p.z.head<2>(), p.S.topLeftCorner<2, 2>(), config_, &w.left_center, &w.left_half);
    window(right, p.z.tail<2>(), p.S.bottomRightCorner<2, 2>(), config_, &w.right_center,
           &w.right_half);
    if (!w.left_center.allFinite() || !w.right_center.allFinite()) continue;
    result.push_back(w);
  }
  return result;
}

std::vector<TrackMatch> PointTracker::track(const std::vector<TrackWindow>& windows,
                                            const FeatureSet& left, const FeatureSet& right,
                                            std::vector<char>* left_used,
                                            std::vector<char>* right_used,
                                            const std::function<bool(int, int)>& consistent) {
  struct Proposal {
    TrackMatch match;
    double cost;
  };
  std::vector<Proposal> proposals;
  std::vector<int> scratch;
  for (const TrackWindow& w : windows) {
    const auto it = tracks_.find(w.id);
    if (it == tracks_.end() || left.size() == 0 || right.size() == 0) continue;
    const Candidate l =
        bestInWindow(left, w.left_center, w.left_half, it->second.left_descriptor, &scratch);
    if (l.index < 0 || l.distance > config_.max_track_descriptor_distance) continue;
    std::function<bool(int)> accept;
    if (consistent) accept = [&](int j) { return consistent(l.index, j); };
    const Candidate r = bestInWindow(right, w.right_center, w.right_half,
                                     it->second.right_descriptor, &scratch, accept);
    if (r.index < 0 || r.distance > config_.max_track_descriptor_distance) continue;
    proposals.push_back({{w.id, l.index, r.index}, l.distance + r.distance});
  }
  // One keypoint per track: the better proposals first.
  std::sort(proposals.begin(), proposals.end(),
            [](const Proposal& a, const Proposal& b) { return a.cost < b.cost; });
  std::vector<TrackMatch> found;
  for (const Proposal& p : proposals) {
    char& lu = (*left_used)[static_cast<size_t>(p.match.left)];
    char& ru = (*right_used)[static_cast<size_t>(p.match.right)];
    if (lu || ru) continue;
    lu = ru = 1;
    Track& t = tracks_[p.match.id];
    left.descriptors.row(p.match.left).copyTo(t.left_descriptor);
    right.descriptors.row(p.match.right).copyTo(t.right_descriptor);
    found.push_back(p.match);
  }
  std::sort(found.begin(), found.end(),
            [](const TrackMatch& a, const TrackMatch& b) { return a.id < b.id; });
  return found;
}

}  // namespace osc
