/// @file stereo_front_end_tracks.cpp
/// @brief StereoFrontEnd's tracks between frames: lost ones reacquired over the whole image,
/// the filter's verdict committed (dropped points forgotten, accepted candidates adopted),
/// reset.
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"

#include <functional>
#include <unordered_set>
#include <vector>

namespace osc {

void StereoFrontEnd::reacquireLostTracks(const FeatureSet& left, const FeatureSet& right,
                                         const std::function<bool(int, int)>& consistent,
                                         std::vector<char>* left_used,
                                         std::vector<char>* right_used,
                                         std::vector<TrackMatch>* found) {
  constexpr size_t kMinTracks = 10;
  const size_t expected = last_windows_.size();
  if (config_.reacquire_below_fraction <= 0.0 || expected < kMinTracks ||
      found->size() >= config_.reacquire_below_fraction * expected) {
    return;
  }
  std::unordered_set<PointId> tracked;
  for (const TrackMatch& m : *found) tracked.insert(m.id);
  // The whole image as the window; the gate widened by the image diagonal so that only the
  // descriptor (with its ratio test) and the epipolar band decide.
  const CameraIntrinsics& in = left_camera_.intrinsics();
  const Eigen::Vector2d half(0.5 * in.width, 0.5 * in.height);
  const double diagonal2 = 4.0 * half.squaredNorm();
  std::vector<TrackWindow> everywhere;
  for (const TrackWindow& w : last_windows_) {
    if (tracked.count(w.id)) continue;
    TrackWindow wide = w;
    wide.left_center = wide.right_center = half;
    wide.left_half = wide.right_half = half;
    wide.S.diagonal().array() += diagonal2;
    everywhere.push_back(wide);
  }
  const std::vector<TrackMatch> more =
      tracker_.track(everywhere, left, right, left_used, right_used, consistent);
  found->insert(found->end(), more.begin(), more.end());
}

void StereoFrontEnd::commit(const FrameReport& report, const CalibrationFilter& filter) {
  for (PointId id : report.dropped) tracker_.remove(id);
  for (const StereoObservation& o : last_tracked_) {
    if (!filter.hasPoint(o.id)) tracker_.remove(o.id);
  }
  for (const Pending& p : pending_) {
    if (filter.hasPoint(p.id)) {
      tracker_.add(p.id, p.left_descriptor, p.right_descriptor, p.left_pixel);
      tracker_.setAnchor(p.id, p.anchor);
    }
  }
  pending_.clear();
}

void StereoFrontEnd::reset() {
  tracker_.clear();
  epipolar_trend_ = EpipolarTrend();
  pending_.clear();
  previous_left_.release();
  current_left_.release();
}

}  // namespace osc
