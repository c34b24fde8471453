#include "online_stereo_calibration/core/frontend/point_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/LU>

namespace osc {
namespace {

/// Raw pixel of an undistorted pixel.
Eigen::Vector2d toRaw(const CameraModel& camera, const Eigen::Vector2d& undistorted) {
  const Eigen::Matrix3d& K = camera.K();
  const Eigen::Vector2d normalized((undistorted.x() - K(0, 2)) / K(0, 0),
                                   (undistorted.y() - K(1, 2)) / K(1, 1));
  return camera.normalizedToPixel(normalized);
}

/// Window of one image: S (undistorted px^2) mapped to raw pixels through the lens's
/// Jacobian.
void window(const CameraModel& camera, const Eigen::Vector2d& z, const Eigen::Matrix2d& S,
            const FrontEndConfig& config, Eigen::Vector2d* center, Eigen::Vector2d* half) {
  *center = toRaw(camera, z);
  const Eigen::Matrix2d J = camera.lensJacobian(z);
  const Eigen::Matrix2d S_raw = J * S * J.transpose();
  for (int k = 0; k < 2; ++k) {
    const double sigma = std::sqrt(std::max(0.0, S_raw(k, k)));
    (*half)(k) = std::clamp(config.track_window_sigmas * sigma, config.min_track_window,
                            config.max_track_window);
  }
}

/// Squared Mahalanobis distance of a 2-vector under covariance S (infinite if singular).
double mahalanobis2(const Eigen::Vector2d& e, const Eigen::Matrix2d& S) {
  const double det = S.determinant();
  if (!(det > 0.0)) return std::numeric_limits<double>::infinity();
  return e.dot(S.inverse() * e);
}

}  // namespace

PointTracker::PointTracker(const FrontEndConfig& config) : config_(config) {}

void PointTracker::add(PointId id, const cv::Mat& left_descriptor, const cv::Mat& right_descriptor,
                       const Eigen::Vector2d& left_pixel) {
  tracks_[id] = Track{left_descriptor.clone(), right_descriptor.clone(), left_pixel, TrackAnchor()};
}

bool PointTracker::leftPixel(PointId id, Eigen::Vector2d* pixel) const {
  const auto it = tracks_.find(id);
  if (it == tracks_.end()) return false;
  *pixel = it->second.left_pixel;
  return true;
}

void PointTracker::setLeftPixel(PointId id, const Eigen::Vector2d& pixel) {
  const auto it = tracks_.find(id);
  if (it != tracks_.end()) it->second.left_pixel = pixel;
}

void PointTracker::setAnchor(PointId id, TrackAnchor anchor) {
  const auto it = tracks_.find(id);
  if (it != tracks_.end()) it->second.anchor = std::move(anchor);
}

const TrackAnchor* PointTracker::anchor(PointId id) const {
  const auto it = tracks_.find(id);
  if (it == tracks_.end() || it->second.anchor.crop.empty()) return nullptr;
  return &it->second.anchor;
}

void PointTracker::growAnchor(PointId id, double factor) {
  const auto it = tracks_.find(id);
  if (it != tracks_.end()) it->second.anchor.scale *= factor;
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
    w.z = p.z;
    w.S = p.S;
    w.scale = p.depth_ratio;
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
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Proposal> proposals;
  std::vector<int> scratch;
  for (const TrackWindow& w : windows) {
    const auto it = tracks_.find(w.id);
    if (it == tracks_.end() || left.size() == 0 || right.size() == 0) continue;
    const Track& t = it->second;
    // Left image: the keypoint in the window (and inside the Mahalanobis gate of the
    // predicted left pixel) closest to the stored descriptor, and the runner-up.
    scratch.clear();
    left.raw_grid.query(w.left_center - w.left_half, w.left_center + w.left_half, &scratch);
    const Eigen::Matrix2d S_ll = w.S.topLeftCorner<2, 2>();
    int l = -1;
    double l_best = inf, l_second = inf;
    for (int j : scratch) {
      const Eigen::Vector2d e = left.undistorted[static_cast<size_t>(j)] - w.z.head<2>();
      if (mahalanobis2(e, S_ll) > config_.track_gate_chi2_2dof) continue;
      const double d = left.distance(j, t.left_descriptor);
      if (d < l_best) {
        l_second = l_best;
        l_best = d;
        l = j;
      } else if (d < l_second) {
        l_second = d;
      }
    }
    if (l < 0 || l_best > config_.max_track_descriptor_distance) continue;
    if (l_second < inf && l_best >= config_.track_ratio * l_second) continue;
    // Right image: the same within the window, the epipolar band of the chosen left
    // keypoint and the gate of the right pixel conditioned on the left one (4-dof
    // innovation).
    const Eigen::Vector2d el = left.undistorted[static_cast<size_t>(l)] - w.z.head<2>();
    const Eigen::Matrix2d S_rr = w.S.bottomRightCorner<2, 2>();
    const Eigen::Matrix2d S_rl = w.S.bottomLeftCorner<2, 2>();
    const Eigen::Matrix2d gain = S_rl * S_ll.inverse();
    const Eigen::Vector2d r_mean = w.z.tail<2>() + gain * el;
    const Eigen::Matrix2d r_cov = S_rr - gain * S_rl.transpose();
    scratch.clear();
    right.raw_grid.query(w.right_center - w.right_half, w.right_center + w.right_half, &scratch);
    int r = -1;
    double r_best = inf, r_second = inf;
    for (int j : scratch) {
      if (consistent && !consistent(l, j)) continue;
      const Eigen::Vector2d e = right.undistorted[static_cast<size_t>(j)] - r_mean;
      if (mahalanobis2(e, r_cov) > config_.track_gate_chi2_2dof) continue;
      const double d = right.distance(j, t.right_descriptor);
      if (d < r_best) {
        r_second = r_best;
        r_best = d;
        r = j;
      } else if (d < r_second) {
        r_second = d;
      }
    }
    if (r < 0 || r_best > config_.max_track_descriptor_distance) continue;
    if (r_second < inf && r_best >= config_.track_ratio * r_second) continue;
    // The pair must also be a stereo match of this frame.
    if (left.distance(l, right, r) > config_.max_descriptor_distance) continue;
    proposals.push_back({{w.id, l, r}, l_best + r_best});
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
