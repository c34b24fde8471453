#include "online_stereo_calibration/core/frontend/stereo_front_end.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/frontend/bucketing.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

FrontEndConfig checked(const FrontEndConfig& config) {
  const std::vector<std::string> problems = config.validate();
  if (!problems.empty()) {
    std::string message = "invalid FrontEndConfig:";
    for (const std::string& p : problems) message += " " + p + ";";
    throw std::invalid_argument(message);
  }
  return config;
}

StereoObservation observation(PointId id, const Eigen::Vector2d& left,
                              const Eigen::Vector2d& right) {
  StereoObservation o;
  o.id = id;
  o.left_pixel = left;
  o.right_pixel = right;
  return o;
}

}  // namespace

StereoFrontEnd::StereoFrontEnd(const FrontEndConfig& config, const FilterConfig& filter_config,
                               const CameraModel& left, const CameraModel& right)
    : config_(checked(config)),
      filter_config_(filter_config),
      left_camera_(left),
      right_camera_(right),
      detector_(config_),
      matcher_(config_, filter_config.min_point_depth),
      tracker_(config_) {}

std::vector<StereoObservation> StereoFrontEnd::observe(const cv::Mat& left_mono,
                                                       const cv::Mat& right_mono,
                                                       const MotionIncrement& motion,
                                                       const CalibrationFilter& filter,
                                                       FrontEndStatistics* statistics) {
  FrontEndStatistics stats;
  last_left_ = left_mono;
  last_right_ = right_mono;
  last_tracked_.clear();
  last_new_.clear();
  last_matches_.clear();
  last_windows_.clear();
  pending_.clear();

  const FeatureSet left = detector_.detect(left_mono, left_camera_);
  const FeatureSet right = detector_.detect(right_mono, right_camera_);
  stats.features_left = static_cast<int>(left.size());
  stats.features_right = static_cast<int>(right.size());
  std::vector<char> left_used(left.size(), 0), right_used(right.size(), 0);

  // The current x_camr and its covariance: epipolar bands (eq. 5-6) for tracks and matches.
  const Matrix12d& P = filter.covariance();
  matcher_.setGeometry(left_camera_.K(), right_camera_.K(), filter.extrinsics().T_caml_camr,
                       P.bottomRightCorner<6, 6>());
  const Eigen::Matrix3d& F = matcher_.fundamental();
  auto on_band = [&](int l, int r) {
    const Eigen::Vector2d& ul = left.undistorted[static_cast<size_t>(l)];
    const Eigen::Vector2d& ur = right.undistorted[static_cast<size_t>(r)];
    return std::abs(epipolarLine(F, ul).dot(ur.homogeneous())) <= matcher_.bandHalfWidth(ul, ur);
  };

  // 1. Tracking (Sec. II-C): windows from the filter's predictions and S.
  std::vector<StereoObservation> observations;
  if (tracker_.size() > 0 && filter.pointCount() > 0) {
    last_windows_ =
        tracker_.windows(filter.predictObservations(motion), left_camera_, right_camera_);
    const std::vector<TrackMatch> found =
        tracker_.track(last_windows_, left, right, &left_used, &right_used, on_band);
    for (const TrackMatch& m : found) {
      observations.push_back(observation(m.id, left.raw[static_cast<size_t>(m.left)],
                                         right.raw[static_cast<size_t>(m.right)]));
    }
  }
  last_tracked_ = observations;
  stats.tracked = static_cast<int>(observations.size());
  stats.track_failures = static_cast<int>(tracker_.size()) - stats.tracked;

  // 2. New points: epipolar-guided matching with the current x_camr (eq. 5-6).
  const std::vector<StereoMatch> matches = matcher_.match(left, right, left_used, right_used);
  stats.stereo_matches = static_cast<int>(matches.size());

  // 3. Reject what cannot make a good point: behind, too close / far, too little parallax,
  // or where a tracked point already is.
  const Eigen::Isometry3d T_lopt_ropt = filter.extrinsics().leftToRightOptical();
  const Eigen::Matrix3d Kl_inv = left_camera_.K().inverse(), Kr_inv = right_camera_.K().inverse();
  std::vector<Eigen::Vector2d> tracked_pixels;
  for (const StereoObservation& o : last_tracked_) tracked_pixels.push_back(o.left_pixel);
  SpatialGrid tracked_grid;
  tracked_grid.build(tracked_pixels, left_mono.cols, left_mono.rows, 32.0);
  const double min_parallax = config_.min_parallax_deg * M_PI / 180.0;
  std::vector<Eigen::Vector2d> positions;
  std::vector<double> costs;
  std::vector<int> usable;
  std::vector<int> near;
  for (size_t k = 0; k < matches.size(); ++k) {
    const StereoMatch& m = matches[k];
    const Eigen::Vector2d& pl = left.raw[static_cast<size_t>(m.left)];
    const Eigen::Vector2d& pr = right.raw[static_cast<size_t>(m.right)];
    last_matches_.push_back(observation(0, pl, pr));
    const Eigen::Vector2d& ul = left.undistorted[static_cast<size_t>(m.left)];
    const Eigen::Vector2d& ur = right.undistorted[static_cast<size_t>(m.right)];
    const auto tri =
        triangulateMidpoint(Kl_inv * Eigen::Vector3d(ul.x(), ul.y(), 1.0),
                            Kr_inv * Eigen::Vector3d(ur.x(), ur.y(), 1.0), T_lopt_ropt);
    if (!tri) continue;
    const double depth = tri->point_left.z();
    if (depth < filter_config_.min_point_depth || depth > filter_config_.max_point_depth ||
        tri->parallax < min_parallax) {
      continue;
    }
    near.clear();
    const Eigen::Vector2d r = Eigen::Vector2d::Constant(config_.min_distance_to_track);
    tracked_grid.query(pl - r, pl + r, &near);
    bool too_close = false;
    for (int t : near) {
      too_close |=
          (tracked_pixels[static_cast<size_t>(t)] - pl).norm() < config_.min_distance_to_track;
    }
    if (too_close) continue;
    usable.push_back(static_cast<int>(k));
    positions.push_back(pl);
    costs.push_back(m.descriptor_distance);
  }

  // 4. Bucketing and the caps: per frame and in the state (FilterConfig::max_points).
  const int room = filter_config_.max_points - static_cast<int>(observations.size());
  const int max_new = std::max(0, std::min(config_.max_new_points_per_frame, room));
  const std::vector<int> kept =
      selectByBuckets(positions, costs, tracked_pixels, left_mono.cols, left_mono.rows,
                      config_.bucket_cols, config_.bucket_rows, max_new);
  for (int u : kept) {
    const StereoMatch& m = matches[static_cast<size_t>(usable[static_cast<size_t>(u)])];
    const PointId id = next_id_++;
    observations.push_back(observation(id, left.raw[static_cast<size_t>(m.left)],
                                       right.raw[static_cast<size_t>(m.right)]));
    last_new_.push_back(observations.back());
    pending_.push_back(
        {id, left.descriptors.row(m.left).clone(), right.descriptors.row(m.right).clone()});
  }
  stats.new_candidates = static_cast<int>(kept.size());
  if (statistics) *statistics = stats;
  return observations;
}

void StereoFrontEnd::commit(const FrameReport& report, const CalibrationFilter& filter) {
  for (PointId id : report.dropped) tracker_.remove(id);
  for (const StereoObservation& o : last_tracked_) {
    if (!filter.hasPoint(o.id)) tracker_.remove(o.id);
  }
  for (const Pending& p : pending_) {
    if (filter.hasPoint(p.id)) tracker_.add(p.id, p.left_descriptor, p.right_descriptor);
  }
  pending_.clear();
}

void StereoFrontEnd::reset() {
  tracker_.clear();
  pending_.clear();
}

cv::Mat StereoFrontEnd::debugImage() const {
  if (last_left_.empty() || last_right_.empty()) return cv::Mat();
  const int w = last_left_.cols;
  cv::Mat canvas(std::max(last_left_.rows, last_right_.rows), w + last_right_.cols, CV_8UC3,
                 cv::Scalar::all(0));
  cv::Mat left_roi = canvas(cv::Rect(0, 0, w, last_left_.rows));
  cv::Mat right_roi = canvas(cv::Rect(w, 0, last_right_.cols, last_right_.rows));
  cv::cvtColor(last_left_, left_roi, cv::COLOR_GRAY2BGR);
  cv::cvtColor(last_right_, right_roi, cv::COLOR_GRAY2BGR);
  auto pt = [](const Eigen::Vector2d& p, double dx = 0.0) {
    return cv::Point(static_cast<int>(std::lround(p.x() + dx)),
                     static_cast<int>(std::lround(p.y())));
  };
  const cv::Scalar grey(128, 128, 128), green(0, 220, 0), blue(255, 80, 0);
  const cv::Scalar yellow(0, 220, 220), cyan(220, 220, 0);
  for (const StereoObservation& o : last_matches_) {
    cv::circle(canvas, pt(o.left_pixel), 2, grey, 1);
    cv::circle(canvas, pt(o.right_pixel, w), 2, grey, 1);
  }
  for (const TrackWindow& win : last_windows_) {
    cv::rectangle(canvas, pt(win.left_center - win.left_half), pt(win.left_center + win.left_half),
                  yellow, 1);
    cv::rectangle(canvas, pt(win.right_center - win.right_half, w),
                  pt(win.right_center + win.right_half, w), cyan, 1);
  }
  for (const StereoObservation& o : last_new_) {
    cv::circle(canvas, pt(o.left_pixel), 4, blue, 2);
    cv::circle(canvas, pt(o.right_pixel, w), 4, blue, 2);
    cv::line(canvas, pt(o.left_pixel), pt(o.right_pixel, w), blue, 1);
  }
  for (const StereoObservation& o : last_tracked_) {
    cv::circle(canvas, pt(o.left_pixel), 4, green, 2);
    cv::circle(canvas, pt(o.right_pixel, w), 4, green, 2);
  }
  const std::string text = "tracked " + std::to_string(last_tracked_.size()) + "  new " +
                           std::to_string(last_new_.size()) + "  matches " +
                           std::to_string(last_matches_.size());
  cv::putText(canvas, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 255),
              2);
  return canvas;
}

}  // namespace osc
