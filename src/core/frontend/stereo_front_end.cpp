/// @file stereo_front_end.cpp
/// @brief StereoFrontEnd: construction and observe() (tracking, epipolar matching, the new
/// points' selection); the tracks between frames in stereo_front_end_tracks.cpp, the debug
/// image in stereo_front_end_debug.cpp.
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/LU>

#include "online_stereo_calibration/core/frontend/bucketing.h"
#include "online_stereo_calibration/core/frontend/patch_alignment.h"
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

/// A predicted growth of a patch as a template scale, bounded so that a badly estimated
/// point cannot ask for an absurd resampling (the anchor's crop allows down to 0.5).
double templateScale(double growth) {
  return std::isfinite(growth) ? std::clamp(growth, 0.5, 2.0) : 1.0;
}

/// PatchAlignmentConfig::template_sampling for a patch seen at raw pixel `from` and looked
/// for at raw pixel `to` of the same camera, grown by `growth` in between: a step in the target
/// is undone by the lens's stretch at `to`, shrunk by the growth, and stretched by the lens at
/// `from` (under a distorted lens a patch also changes shape as it crosses the image).
Eigen::Matrix2d templateSampling(const CameraModel& camera, const Eigen::Vector2d& from,
                                 const Eigen::Vector2d& to, double growth) {
  return camera.lensJacobian(camera.undistortPixel(from)) * (1.0 / templateScale(growth)) *
         camera.lensJacobian(camera.undistortPixel(to)).inverse();
}

/// A refined pair against its epipolar line: the right pixel's signed distance from the line
/// (px) and the half-width that its own noise and x_camr's spread allow
/// (EpipolarMatcher::refinedBandHalfWidth).
struct LineFit {
  double distance = 0.0;
  double band = 0.0;
};

/// A refined pair waiting for the frame's epipolar trend.
struct RefinedPair {
  PointId id = 0;  ///< tracked point; unused for new matches
  int match = -1;  ///< index of the stereo match; unused for tracks
  Eigen::Vector2d left_raw, right_raw, left_und, right_und;
  LineFit line;
};

EpipolarResidual residualOf(const RefinedPair& pair) {
  return {pair.line.distance, pair.right_und};
}

/// The anchor of a new point: a crop of its left image around the pixel, wide enough for its
/// patch resampled at half the size (radius 2 (half_size + 1) + 1), clipped at the border.
TrackAnchor makeAnchor(const cv::Mat& image, const Eigen::Vector2d& pixel, int half_size) {
  const int radius = 2 * (half_size + 1) + 1;
  const cv::Rect wanted(static_cast<int>(std::lround(pixel.x())) - radius,
                        static_cast<int>(std::lround(pixel.y())) - radius, 2 * radius + 1,
                        2 * radius + 1);
  const cv::Rect inside = wanted & cv::Rect(0, 0, image.cols, image.rows);
  TrackAnchor anchor;
  if (inside.area() == 0) return anchor;
  anchor.crop = image(inside).clone();
  anchor.pixel = pixel - Eigen::Vector2d(inside.x, inside.y);
  anchor.image_pixel = pixel;
  return anchor;
}

}  // namespace

StereoFrontEnd::StereoFrontEnd(const FrontEndConfig& config, const FilterConfig& filter_config,
                               const CameraModel& left, const CameraModel& right)
    : config_(checked(config)),
      filter_config_(filter_config),
      left_camera_(left),
      right_camera_(right),
      detector_(config_),
      matcher_(config_, filter_config.min_point_depth, filter_config.max_point_depth),
      tracker_(config_) {}

std::vector<StereoObservation> StereoFrontEnd::observe(const cv::Mat& left_mono,
                                                       const cv::Mat& right_mono,
                                                       const MotionIncrement& motion,
                                                       const CalibrationFilter& filter,
                                                       FrontEndStatistics* statistics) {
  FrontEndStatistics stats;
  // The previous left image, kept as a copy (the caller may reuse its buffers).
  std::swap(previous_left_, current_left_);
  left_mono.copyTo(current_left_);
  last_left_ = left_mono;
  last_right_ = right_mono;
  last_tracked_.clear();
  last_new_.clear();
  last_matches_.clear();
  last_match_keypoints_.clear();
  last_windows_.clear();
  last_bands_.clear();
  pending_.clear();

  left_features_ = detector_.detect(left_mono, left_camera_);
  right_features_ = detector_.detect(right_mono, right_camera_);
  const FeatureSet& left = left_features_;
  const FeatureSet& right = right_features_;
  stats.features_left = static_cast<int>(left.size());
  stats.features_right = static_cast<int>(right.size());
  std::vector<char> left_used(left.size(), 0), right_used(right.size(), 0);

  // The current x_camr and its covariance: epipolar bands (eq. 5-6) for tracks and matches.
  const Matrix12d& P = filter.covariance();
  matcher_.setGeometry(left_camera_.K(), right_camera_.K(), filter.extrinsics().T_caml_camr,
                       P.bottomRightCorner<6, 6>());
  // Midpoint triangulation of a pair of undistorted pixels with the current x_camr.
  const Eigen::Isometry3d T_lopt_ropt = filter.extrinsics().leftToRightOptical();
  const Eigen::Matrix3d Kl_inv = left_camera_.K().inverse(), Kr_inv = right_camera_.K().inverse();
  auto triangulate = [&](const Eigen::Vector2d& ul, const Eigen::Vector2d& ur) {
    return triangulateMidpoint(Kl_inv * ul.homogeneous(), Kr_inv * ur.homogeneous(), T_lopt_ropt);
  };
  // PointTracker::track asks about one left keypoint against many right ones (the whole
  // image when reacquiring): its seven lines are computed once, not per right keypoint.
  int left_lines_of = -1;
  EpipolarMatcher::Lines left_lines;
  auto on_band = [&](int l, int r) {
    if (l != left_lines_of) {
      left_lines = matcher_.lines(left.undistorted[static_cast<size_t>(l)]);
      left_lines_of = l;
    }
    const Eigen::Vector2d& ur = right.undistorted[static_cast<size_t>(r)];
    return std::abs(left_lines.nominal.dot(ur.homogeneous())) <=
           matcher_.bandHalfWidth(left_lines, ur);
  };
  // Sub-pixel right pixel of a pair: the left keypoint's patch aligned into the right image;
  // false if the alignment is unreliable (edge, occlusion, different content) or leaves the
  // keypoints' epipolar band. Its own, much narrower band is checked once the frame's common
  // distance from the lines is known (onTrend).
  PatchAlignmentConfig alignment;
  alignment.half_size = config_.patch_half_size;
  alignment.max_shift = config_.max_refinement_shift;
  alignment.min_ncc = config_.min_patch_ncc;
  alignment.min_eigenvalue = config_.min_patch_eigen_ratio;
  auto refine = [&](const Eigen::Vector2d& left_raw, const Eigen::Vector2d& left_und,
                    const Eigen::Vector2d& right_guess, Eigen::Vector2d* right_raw,
                    Eigen::Vector2d* right_und, LineFit* line) {
    const PatchAlignment a = alignPatch(left_mono, left_raw, right_mono, right_guess, alignment);
    if (!a.ok) return false;
    *right_raw = a.position;
    *right_und = right_camera_.undistortPixel(a.position);
    const EpipolarMatcher::Lines lines = matcher_.lines(left_und);
    line->distance = lines.nominal.dot(right_und->homogeneous());
    line->band = matcher_.refinedBandHalfWidth(lines, *right_und, config_.refined_pixel_sigma);
    return std::abs(line->distance) <= std::max(config_.min_band, line->band);
  };
  // The refined pair's own band, about the frame's common distance from the lines.
  auto onTrend = [](const EpipolarTrend& trend, const RefinedPair& pair) {
    return std::abs(pair.line.distance - trend.at(pair.right_und)) <= pair.line.band;
  };
  auto fitTrend = [&](const std::vector<const std::vector<RefinedPair>*>& sets,
                      const EpipolarTrend& fallback) {
    std::vector<EpipolarResidual> residuals;
    for (const std::vector<RefinedPair>* set : sets) {
      for (const RefinedPair& pair : *set) residuals.push_back(residualOf(pair));
    }
    if (static_cast<int>(residuals.size()) < EpipolarTrend::kMinResiduals) return fallback;
    return EpipolarTrend::fit(residuals, right_camera_.K()(0, 2), right_camera_.K()(0, 0));
  };
  // Pairs handed to the filter (tracked and new) are also checked for a depth discontinuity
  // across their patch (costly, so not every match is).
  auto continuous = [&](const Eigen::Vector2d& left_raw, const Eigen::Vector2d& left_und,
                        const Eigen::Vector2d& right_raw, const Eigen::Vector2d& right_und) {
    if (config_.discontinuity_search <= 0) return true;
    // The epipolar direction at the right pixel (raw image, along the line).
    const Eigen::Vector3d line = matcher_.lines(left_und).nominal;
    const Eigen::Vector2d ahead = right_camera_.normalizedToPixel(
        (right_camera_.K().inverse() *
         (right_und + Eigen::Vector2d(line.y(), -line.x())).homogeneous())
            .head<2>());
    const Eigen::Vector2d dir = ahead - right_raw;
    return !(dir.norm() > 1e-9 && straddlesDepthDiscontinuity(
                                      left_mono, left_raw, right_mono, right_raw, dir.normalized(),
                                      config_.patch_half_size, config_.discontinuity_search));
  };

  // A track's left pixel checked against its anchor (the point's first patch, resampled by
  // its predicted growth since): moved to where the anchor aligns, or false if the anchor no
  // longer aligns near it (the track slid off its point).
  auto anchored = [&](PointId id, Eigen::Vector2d* left_raw) {
    const TrackAnchor* anchor = tracker_.anchor(id);
    if (config_.max_anchor_shift <= 0.0 || anchor == nullptr) return true;
    PatchAlignmentConfig c = alignment;
    c.max_shift = config_.max_anchor_shift;
    c.template_sampling =
        templateSampling(left_camera_, anchor->image_pixel, *left_raw, anchor->scale);
    const PatchAlignment a = alignPatch(anchor->crop, anchor->pixel, left_mono, *left_raw, c);
    if (!a.ok) return false;
    *left_raw = a.position;
    return true;
  };

  // The anchor is only resampled in scale (and the lens's stretch); a surface seen obliquely (the
  // ground) also shears and foreshortens as it nears, so once its patch has grown or shrunk by more
  // than kMaxAnchorGrowth the anchor is taken anew from this image (a small, rare restart of drift
  // instead of a biased alignment).
  auto reanchorIfDeformed = [&](PointId id, const Eigen::Vector2d& left_raw) {
    constexpr double kMaxAnchorGrowth = 1.25;
    const TrackAnchor* anchor = tracker_.anchor(id);
    if (anchor == nullptr ||
        (anchor->scale <= kMaxAnchorGrowth && anchor->scale >= 1.0 / kMaxAnchorGrowth)) {
      return;
    }
    tracker_.setAnchor(id, makeAnchor(left_mono, left_raw, config_.patch_half_size));
  };

  // 1. Tracking (Sec. II-C): windows from the filter's predictions and S.
  std::vector<StereoObservation> observations;
  std::vector<RefinedPair> tracked_pairs;  // before the epipolar trend's check
  if (tracker_.size() > 0 && filter.pointCount() > 0) {
    last_windows_ =
        tracker_.windows(filter.predictObservations(motion), left_camera_, right_camera_);
    std::vector<TrackMatch> found =
        tracker_.track(last_windows_, left, right, &left_used, &right_used, on_band);
    // Reacquired pairs come from the whole image: besides the band, no nearer than
    // min_point_depth (a descriptor match across the image can pair unrelated keypoints on one
    // epipolar line at an absurd disparity). Far and parallel rays pass: after a knocked
    // camera the current x_camr may not triangulate them.
    auto reacquirable = [&](int l, int r) {
      if (!on_band(l, r)) return false;
      const auto tri = triangulate(left.undistorted[static_cast<size_t>(l)],
                                   right.undistorted[static_cast<size_t>(r)]);
      return !tri || tri->point_left.z() >= filter_config_.min_point_depth;
    };
    reacquireLostTracks(left, right, reacquirable, &left_used, &right_used, &found);
    // Sub-pixel: the point's patch in the previous left image is aligned into this one from
    // the keypoint found (so the track stays on the same surface point instead of following
    // the detector's pixel-grid jitter), then into the right image.
    PatchAlignmentConfig temporal = alignment;
    temporal.max_shift = config_.max_temporal_shift;
    std::unordered_map<PointId, double> scale_of;
    for (const TrackWindow& w : last_windows_) {
      scale_of[w.id] = templateScale(w.scale);
      tracker_.growAnchor(w.id, scale_of[w.id]);
    }
    const auto scaleOf = [&](PointId id) {
      const auto it = scale_of.find(id);
      return it == scale_of.end() ? 1.0 : it->second;
    };
    for (const TrackMatch& m : found) {
      Eigen::Vector2d left_raw = left.raw[static_cast<size_t>(m.left)];
      Eigen::Vector2d previous;
      if (!previous_left_.empty() && tracker_.leftPixel(m.id, &previous)) {
        temporal.template_sampling =
            templateSampling(left_camera_, previous, left_raw, scaleOf(m.id));
        const PatchAlignment a =
            alignPatch(previous_left_, previous, left_mono, left_raw, temporal);
        if (!a.ok) continue;
        left_raw = a.position;
      }
      if (!anchored(m.id, &left_raw)) continue;
      const Eigen::Vector2d left_und = left_camera_.undistortPixel(left_raw);
      RefinedPair pair;
      pair.id = m.id;
      pair.left_raw = left_raw;
      pair.left_und = left_und;
      if (!refine(left_raw, left_und, right.raw[static_cast<size_t>(m.right)], &pair.right_raw,
                  &pair.right_und, &pair.line) ||
          !continuous(left_raw, left_und, pair.right_raw, pair.right_und)) {
        continue;
      }
      tracked_pairs.push_back(pair);
    }
  }
  // Tracks whose keypoint was not detected again (or not confirmed): the point's patch of
  // the previous left image is searched directly around its predicted pixel (Lucas-Kanade
  // from the prediction, Sec. II-C's window and the filter's S as the gate), then in the
  // right image around the right prediction moved by the left innovation.
  if (config_.search_lost_tracks && !previous_left_.empty()) {
    std::unordered_set<PointId> observed;
    for (const RefinedPair& pair : tracked_pairs) observed.insert(pair.id);
    for (const TrackWindow& w : last_windows_) {
      if (observed.count(w.id)) continue;
      Eigen::Vector2d previous;
      if (!tracker_.leftPixel(w.id, &previous)) continue;
      PatchAlignmentConfig search = alignment;
      search.max_shift = w.left_half.maxCoeff();
      search.min_ncc = config_.min_search_ncc;
      search.template_sampling = templateSampling(left_camera_, previous, w.left_center, w.scale);
      const PatchAlignment a =
          alignPatch(previous_left_, previous, left_mono, w.left_center, search);
      if (!a.ok) continue;
      // Forward-backward: the found patch aligned back must land where the point was.
      PatchAlignmentConfig backward = search;
      backward.template_sampling =
          templateSampling(left_camera_, a.position, previous, 1.0 / templateScale(w.scale));
      const PatchAlignment back =
          alignPatch(left_mono, a.position, previous_left_, previous, backward);
      if (!back.ok || (back.position - previous).norm() > config_.max_forward_backward) continue;
      Eigen::Vector2d left_raw = a.position;
      if (!anchored(w.id, &left_raw)) continue;
      const Eigen::Vector2d left_und = left_camera_.undistortPixel(left_raw);
      const Eigen::Vector2d el = left_und - w.z.head<2>();
      const Eigen::Matrix2d S_ll = w.S.topLeftCorner<2, 2>();
      if (!(S_ll.determinant() > 0.0) ||
          el.dot(S_ll.inverse() * el) > config_.track_gate_chi2_2dof) {
        continue;
      }
      // The right prediction conditioned on the left pixel found (S's cross terms).
      const Eigen::Matrix2d S_rl = w.S.bottomLeftCorner<2, 2>();
      const Eigen::Matrix2d gain = S_rl * S_ll.inverse();
      const Eigen::Vector2d r_mean = w.z.tail<2>() + gain * el;
      const Eigen::Matrix2d r_cov = w.S.bottomRightCorner<2, 2>() - gain * S_rl.transpose();
      const Eigen::Vector2d r_guess = right_camera_.normalizedToPixel(
          (right_camera_.K().inverse() * r_mean.homogeneous()).head<2>());
      RefinedPair pair;
      pair.id = w.id;
      pair.left_raw = left_raw;
      pair.left_und = left_und;
      if (!refine(left_raw, left_und, r_guess, &pair.right_raw, &pair.right_und, &pair.line) ||
          !continuous(left_raw, left_und, pair.right_raw, pair.right_und)) {
        continue;
      }
      const Eigen::Vector2d er = pair.right_und - r_mean;
      if (!(r_cov.determinant() > 0.0) ||
          er.dot(r_cov.inverse() * er) > config_.track_gate_chi2_2dof) {
        continue;
      }
      tracked_pairs.push_back(pair);
    }
  }
  // The tracked pairs within their own noise of the frame's common distance from the lines
  // (the last frame's where too few were tracked to fit one).
  const EpipolarTrend tracked_trend = fitTrend({&tracked_pairs}, epipolar_trend_);
  for (const RefinedPair& pair : tracked_pairs) {
    if (!onTrend(tracked_trend, pair)) continue;
    tracker_.setLeftPixel(pair.id, pair.left_raw);
    reanchorIfDeformed(pair.id, pair.left_raw);
    observations.push_back(observation(pair.id, pair.left_raw, pair.right_raw));
  }
  last_tracked_ = observations;
  stats.tracked = static_cast<int>(observations.size());
  stats.track_failures = static_cast<int>(tracker_.size()) - stats.tracked;

  // 2. New points: epipolar-guided matching with the current x_camr (eq. 5-6), only of the
  // left keypoints that could become one (not in a bucket holding a tracked point: the
  // bucketing below would refuse them) and only if the state has room.
  const int room = filter_config_.max_points - static_cast<int>(observations.size());
  const int max_new = std::max(0, std::min(config_.max_new_points_per_frame, room));
  std::vector<char> left_excluded = left_used;
  {
    const int cols = config_.bucket_cols, rows = config_.bucket_rows;
    auto cellOf = [&](const Eigen::Vector2d& p) {
      const int c =
          std::clamp(static_cast<int>(std::floor(p.x() * cols / left_mono.cols)), 0, cols - 1);
      const int r =
          std::clamp(static_cast<int>(std::floor(p.y() * rows / left_mono.rows)), 0, rows - 1);
      return static_cast<size_t>(r * cols + c);
    };
    std::vector<char> blocked(static_cast<size_t>(cols * rows), 0);
    for (const StereoObservation& o : observations) blocked[cellOf(o.left_pixel)] = 1;
    for (size_t i = 0; i < left.size(); ++i) {
      if (max_new == 0 || blocked[cellOf(left.raw[i])]) left_excluded[i] = 1;
    }
  }
  const std::vector<StereoMatch> matches = matcher_.match(left, right, left_excluded, right_used);

  // 3. Reject what cannot make a good point: behind, too close / far, too little parallax,
  // not confirmed by the sub-pixel alignment, or where a tracked point already is.
  std::vector<Eigen::Vector2d> tracked_pixels;
  for (const StereoObservation& o : last_tracked_) tracked_pixels.push_back(o.left_pixel);
  SpatialGrid tracked_grid;
  tracked_grid.build(tracked_pixels, left_mono.cols, left_mono.rows, 32.0);
  const double min_parallax = config_.min_parallax_deg * M_PI / 180.0;
  // While no point is held, any depth over x_camr's length within 3 sigma: a 1 cm guess for
  // 11 cm rejected every pair in a room before the filter and the baseline from motion saw it
  // (widened with points held too, it cost image campaign run 10 41 frames beyond 5 sigma).
  const DepthScaleRange scale =
      filter.pointCount() > 0
          ? DepthScaleRange()
          : baselineDepthScaleRange(filter.extrinsics().T_caml_camr.translation(),
                                    P.bottomRightCorner<6, 6>().topLeftCorner<3, 3>(), 3.0);
  auto plausible = [&](const Eigen::Vector2d& ul, const Eigen::Vector2d& ur) {
    const auto tri = triangulate(ul, ur);
    if (!tri) return false;
    const double depth = tri->point_left.z();
    return depth * scale.longest >= filter_config_.min_point_depth &&
           depth * scale.shortest <= filter_config_.max_point_depth &&
           tri->parallax >= min_parallax;
  };
  std::vector<Eigen::Vector2d> positions, right_positions;
  std::vector<double> costs;
  std::vector<int> usable;
  std::vector<int> near;
  std::vector<RefinedPair> matched_pairs;  // before the epipolar trend's check
  for (size_t k = 0; k < matches.size(); ++k) {
    const StereoMatch& m = matches[k];
    RefinedPair pair;
    pair.match = static_cast<int>(k);
    pair.left_raw = left.raw[static_cast<size_t>(m.left)];
    pair.left_und = left.undistorted[static_cast<size_t>(m.left)];
    if (!plausible(pair.left_und, right.undistorted[static_cast<size_t>(m.right)])) continue;
    if (!refine(pair.left_raw, pair.left_und, right.raw[static_cast<size_t>(m.right)],
                &pair.right_raw, &pair.right_und, &pair.line) ||
        !plausible(pair.left_und, pair.right_und)) {
      continue;
    }
    matched_pairs.push_back(pair);
  }
  // The frame's common distance from the lines, from every refined pair of the frame.
  const EpipolarTrend trend = fitTrend({&tracked_pairs, &matched_pairs}, tracked_trend);
  epipolar_trend_ = trend;
  for (const RefinedPair& pair : matched_pairs) {
    if (!onTrend(trend, pair)) continue;
    const Eigen::Vector2d& pl = pair.left_raw;
    last_matches_.push_back(observation(0, pl, pair.right_raw));
    last_match_keypoints_.push_back(matches[static_cast<size_t>(pair.match)].left);
    near.clear();
    const Eigen::Vector2d r = Eigen::Vector2d::Constant(config_.min_distance_to_track);
    tracked_grid.query(pl - r, pl + r, &near);
    bool too_close = false;
    for (int t : near) {
      too_close |=
          (tracked_pixels[static_cast<size_t>(t)] - pl).norm() < config_.min_distance_to_track;
    }
    if (too_close) continue;
    usable.push_back(pair.match);
    positions.push_back(pl);
    right_positions.push_back(pair.right_raw);
    costs.push_back(matches[static_cast<size_t>(pair.match)].descriptor_distance);
  }
  stats.stereo_matches = static_cast<int>(last_matches_.size());

  // 4. Bucketing and the caps: per frame and in the state (FilterConfig::max_points).
  const std::vector<int> kept =
      selectByBuckets(positions, costs, tracked_pixels, left_mono.cols, left_mono.rows,
                      config_.bucket_cols, config_.bucket_rows, max_new);
  // A new pair's left keypoint moved to its sub-pixel corner, and the right pixel aligned
  // again from there (FrontEndConfig::corner_half_size); the pair stays as matched where the
  // corner lies too far or the right pixel does not align from it.
  auto moveToCorner = [&](Eigen::Vector2d* left_raw, Eigen::Vector2d* right_raw) {
    Eigen::Vector2d at;
    if (config_.corner_half_size <= 0 || !cornerNear(left_mono, *left_raw, config_.corner_half_size,
                                                     config_.max_corner_shift, &at)) {
      return;
    }
    RefinedPair pair;
    pair.left_raw = at;
    pair.left_und = left_camera_.undistortPixel(at);
    if (!refine(at, pair.left_und, *right_raw, &pair.right_raw, &pair.right_und, &pair.line) ||
        !onTrend(trend, pair) || !plausible(pair.left_und, pair.right_und)) {
      return;
    }
    *left_raw = at;
    *right_raw = pair.right_raw;
  };
  for (int u : kept) {
    const StereoMatch& m = matches[static_cast<size_t>(usable[static_cast<size_t>(u)])];
    Eigen::Vector2d left_raw = positions[static_cast<size_t>(u)];
    Eigen::Vector2d right_raw = right_positions[static_cast<size_t>(u)];
    moveToCorner(&left_raw, &right_raw);
    const Eigen::Vector2d left_und = left_camera_.undistortPixel(left_raw);
    const Eigen::Vector2d right_und = right_camera_.undistortPixel(right_raw);
    if (!continuous(left_raw, left_und, right_raw, right_und)) continue;
    const PointId id = next_id_++;
    observations.push_back(observation(id, left_raw, right_raw));
    last_new_.push_back(observations.back());
    last_bands_.push_back(bandPolylines(left_und, right_und));
    pending_.push_back(
        {id, left.descriptors.row(m.left).clone(), right.descriptors.row(m.right).clone(), left_raw,
         config_.max_anchor_shift > 0.0 ? makeAnchor(left_mono, left_raw, config_.patch_half_size)
                                        : TrackAnchor()});
  }
  stats.new_candidates = static_cast<int>(last_new_.size());
  if (statistics) *statistics = stats;
  return observations;
}

cv::Mat StereoFrontEnd::lastStereoMatchDescriptors() const {
  cv::Mat rows;
  for (int k : last_match_keypoints_) rows.push_back(left_features_.descriptors.row(k));
  return rows;
}

}  // namespace osc
