#include "online_stereo_calibration/core/frontend/front_end_config.h"

#include <cmath>
#include <sstream>
#include <utility>

namespace osc {
namespace {

using Type = FrontEndParameterSpec::Type;

FrontEndParameterSpec text(const char* name, std::string FrontEndConfig::*field,
                           std::vector<std::string> allowed, const char* section, bool advanced,
                           const char* doc) {
  FrontEndParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.section = section;
  s.advanced = advanced;
  s.type = Type::kString;
  s.allowed_values = std::move(allowed);
  s.string_field = field;
  return s;
}

FrontEndParameterSpec integer(const char* name, int FrontEndConfig::*field, int lo, int hi,
                              const char* section, bool advanced, const char* doc) {
  FrontEndParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.section = section;
  s.advanced = advanced;
  s.type = Type::kInteger;
  s.min_value = lo;
  s.max_value = hi;
  s.integer_field = field;
  return s;
}

/// A real in [lo, hi], or (lo, hi] if @p lo_open.
FrontEndParameterSpec real(const char* name, double FrontEndConfig::*field, double lo, double hi,
                           bool lo_open, const char* section, bool advanced, const char* doc) {
  FrontEndParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.section = section;
  s.advanced = advanced;
  s.type = Type::kReal;
  s.min_value = lo;
  s.max_value = hi;
  s.min_open = lo_open;
  s.real_field = field;
  return s;
}

/// A real in [config.*lo_field, hi].
FrontEndParameterSpec realAbove(const char* name, double FrontEndConfig::*field,
                                double FrontEndConfig::*lo_field, double hi, const char* section,
                                bool advanced, const char* doc) {
  FrontEndParameterSpec s = real(name, field, 0.0, hi, false, section, advanced, doc);
  s.min_from_field = lo_field;
  return s;
}

FrontEndParameterSpec boolean(const char* name, bool FrontEndConfig::*field, const char* section,
                              bool advanced, const char* doc) {
  FrontEndParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.section = section;
  s.advanced = advanced;
  s.type = Type::kBool;
  s.bool_field = field;
  return s;
}

constexpr bool kOpen = true;
constexpr bool kClosed = false;

// The sections, by the part of the front end that uses the keys (frontEndParameterSections()
// gives their order in the files and a line on each).
constexpr const char* kDetection = "detection";
constexpr const char* kStereoMatching = "stereo matching";
constexpr const char* kRefinement = "sub-pixel refinement";
constexpr const char* kNewPoints = "new points";
constexpr const char* kTracking = "tracking";
constexpr const char* kImageChecks = "image checks";

// The audience: a user's key (camera, scene, time budget) or an internal threshold tuned on
// measurements.
constexpr bool kUser = false;
constexpr bool kAdvanced = true;

}  // namespace

double FrontEndParameterSpec::getNumber(const FrontEndConfig& config) const {
  switch (type) {
    case Type::kInteger:
      return static_cast<double>(config.*integer_field);
    case Type::kReal:
      return config.*real_field;
    case Type::kBool:
      return config.*bool_field ? 1.0 : 0.0;
    case Type::kString:
      break;
  }
  return 0.0;
}

void FrontEndParameterSpec::setNumber(FrontEndConfig* config, double value) const {
  switch (type) {
    case Type::kInteger:
      config->*integer_field = static_cast<int>(std::lround(value));
      break;
    case Type::kReal:
      config->*real_field = value;
      break;
    case Type::kBool:
      config->*bool_field = value != 0.0;
      break;
    case Type::kString:
      break;
  }
}

const std::string& FrontEndParameterSpec::getString(const FrontEndConfig& config) const {
  return config.*string_field;
}

void FrontEndParameterSpec::setString(FrontEndConfig* config, const std::string& value) const {
  config->*string_field = value;
}

bool FrontEndParameterSpec::getBool(const FrontEndConfig& config) const {
  return config.*bool_field;
}

void FrontEndParameterSpec::setBool(FrontEndConfig* config, bool value) const {
  config->*bool_field = value;
}

std::string FrontEndParameterSpec::format(const FrontEndConfig& config) const {
  std::ostringstream out;
  out.precision(12);
  switch (type) {
    case Type::kString:
      out << config.*string_field;
      break;
    case Type::kInteger:
      out << config.*integer_field;
      break;
    case Type::kReal:
      out << config.*real_field;
      break;
    case Type::kBool:
      out << (config.*bool_field ? "true" : "false");
      break;
  }
  return out.str();
}

std::string FrontEndParameterSpec::allowedText() const {
  std::ostringstream out;
  switch (type) {
    case Type::kString:
      out << "{";
      for (size_t i = 0; i < allowed_values.size(); ++i) {
        out << (i ? ", " : "") << allowed_values[i];
      }
      out << "}";
      break;
    case Type::kBool:
      out << "{true, false}";
      break;
    case Type::kInteger:
    case Type::kReal: {
      out << (min_open ? "(" : "[");
      if (min_from_field != nullptr) {
        for (const FrontEndParameterSpec& other : frontEndParameterTable()) {
          if (other.real_field == min_from_field) out << other.name;
        }
      } else {
        out << min_value;
      }
      out << ", " << max_value << "]";
      break;
    }
  }
  return out.str();
}

std::string FrontEndParameterSpec::check(const FrontEndConfig& config) const {
  std::ostringstream s;
  if (type == Type::kString) {
    if (allowed_values.empty()) return "";
    for (const std::string& v : allowed_values) {
      if (config.*string_field == v) return "";
    }
    s << name << " = '" << config.*string_field << "' is not one of ";
    for (size_t i = 0; i < allowed_values.size(); ++i) s << (i ? ", " : "") << allowed_values[i];
    return s.str();
  }
  if (type == Type::kBool) return "";
  const double value = getNumber(config);
  const double low = min_from_field != nullptr ? config.*min_from_field : min_value;
  const bool ok =
      std::isfinite(value) && (min_open ? value > low : value >= low) && value <= max_value;
  if (ok) return "";
  s << name << " = " << value << " is outside " << (min_open ? "(" : "[") << low << ", "
    << max_value << "]";
  return s.str();
}

const std::vector<FrontEndParameterSpec>& frontEndParameterTable() {
  using C = FrontEndConfig;
  static const std::vector<FrontEndParameterSpec> table = {
      // --- detection and description ---
      text("detector", &C::detector, {"ORB", "FAST_ORB", "AKAZE", "SIFT"}, kDetection, kUser,
           "feature detector and descriptor: ORB (FAST + ORB pyramid), FAST_ORB (FAST on the full "
           "image, ORB on one level: the fastest), AKAZE or SIFT"),
      integer("max_features", &C::max_features, 50, 50000, kDetection, kUser,
              "most keypoints kept per image"),
      integer("fast_threshold", &C::fast_threshold, 1, 255, kDetection, kUser,
              "FAST corner threshold (grey levels) of ORB / FAST_ORB: lower finds more corners in "
              "low-contrast images"),
      integer("orb_levels", &C::orb_levels, 1, 16, kDetection, kAdvanced, "pyramid levels of ORB"),
      real("orb_scale_factor", &C::orb_scale_factor, 1.0, 2.0, kOpen, kDetection, kAdvanced,
           "scale factor between ORB pyramid levels"),
      integer("detection_grid", &C::detection_grid, 1, 64, kDetection, kAdvanced,
              "keypoints spread over this many grid cells per axis (1 = no spreading)"),
      real("border", &C::border, 0.0, 100.0, kClosed, kDetection, kUser,
           "keypoints closer than this to the image border are ignored (px)"),
      // --- epipolar-guided stereo matching (eq. 5-6) ---
      real("band_sigmas", &C::band_sigmas, 0.0, 10.0, kOpen, kStereoMatching, kAdvanced,
           "half-width of the epipolar band in sigmas of the line distance"),
      real("min_band", &C::min_band, 0.1, 50.0, kClosed, kStereoMatching, kAdvanced,
           "least half-width of the band (px)"),
      realAbove("max_band", &C::max_band, &C::min_band, 500.0, kStereoMatching, kAdvanced,
                "largest half-width of the band (px); bounds the search when very uncertain"),
      real("pixel_sigma", &C::pixel_sigma, 0.0, 10.0, kClosed, kStereoMatching, kUser,
           "pixel noise (px) per image added to the epipolar search band (the filter's own is "
           "pixel_noise_px)"),
      real("max_descriptor_distance", &C::max_descriptor_distance, 0.0, 1.0, kOpen, kStereoMatching,
           kAdvanced, "largest normalised descriptor distance of a stereo match"),
      real("ratio", &C::ratio, 0.0, 1.0, kOpen, kStereoMatching, kAdvanced,
           "Lowe's ratio: best distance < ratio * second best among the candidates"),
      // --- sub-pixel refinement and verification ---
      integer("patch_half_size", &C::patch_half_size, 1, 15, kRefinement, kAdvanced,
              "half-size (px) of the patch aligned into the other image (sub-pixel refinement)"),
      real("max_refinement_shift", &C::max_refinement_shift, 0.0, 20.0, kOpen, kRefinement,
           kAdvanced, "largest move (px) of the stereo alignment from the matched right keypoint"),
      real("max_temporal_shift", &C::max_temporal_shift, 0.0, 20.0, kOpen, kTracking, kAdvanced,
           "largest move (px) of a track's alignment from the keypoint found"),
      real("max_anchor_shift", &C::max_anchor_shift, 0.0, 20.0, kClosed, kTracking, kAdvanced,
           "tracks: largest move (px) of the alignment of the point's first patch, resampled by "
           "its predicted growth, from the frame-to-frame position; beyond, or below "
           "min_patch_ncc, the track has slid off its point and is dropped (0 = off)"),
      real("min_patch_ncc", &C::min_patch_ncc, -1.0, 1.0, kClosed, kRefinement, kAdvanced,
           "least normalised cross-correlation of the aligned patches"),
      boolean("search_lost_tracks", &C::search_lost_tracks, kTracking, kUser,
              "search tracks whose keypoint was not detected again by aligning their patch (more "
              "tracks survive, at some precision)"),
      real("min_search_ncc", &C::min_search_ncc, -1.0, 1.0, kClosed, kTracking, kAdvanced,
           "search_lost_tracks: least NCC of the aligned patch"),
      real("max_forward_backward", &C::max_forward_backward, 0.0, 10.0, kOpen, kTracking, kAdvanced,
           "search_lost_tracks: largest forward-backward alignment error (px)"),
      integer("discontinuity_search", &C::discontinuity_search, 0, 20, kRefinement, kAdvanced,
              "depth-discontinuity check: half-patch shifts searched (px, 0 = off)"),
      real("min_patch_eigen_ratio", &C::min_patch_eigen_ratio, 0.0, 1.0, kClosed, kRefinement,
           kAdvanced,
           "least small/large eigenvalue ratio of the patch's structure tensor (edges fail)"),
      real("refined_pixel_sigma", &C::refined_pixel_sigma, 0.0, 10.0, kOpen, kRefinement, kAdvanced,
           "pixel noise (px) per image of the epipolar check of a sub-pixel pair (no min_band "
           "floor)"),
      // --- spatial sampling ---
      integer("bucket_cols", &C::bucket_cols, 1, 64, kNewPoints, kAdvanced,
              "bucketing grid columns for new points"),
      integer("bucket_rows", &C::bucket_rows, 1, 64, kNewPoints, kAdvanced,
              "bucketing grid rows for new points"),
      integer("max_new_points_per_frame", &C::max_new_points_per_frame, 0, 10000, kNewPoints, kUser,
              "most new points offered to the filter per frame"),
      real("min_distance_to_track", &C::min_distance_to_track, 0.0, 200.0, kClosed, kNewPoints,
           kAdvanced, "no new point within this distance (px, left image) of a tracked one"),
      real("min_parallax_deg", &C::min_parallax_deg, 0.0, 30.0, kClosed, kNewPoints, kAdvanced,
           "least angle between the two rays of a new point (deg)"),
      integer("corner_half_size", &C::corner_half_size, 0, 15, kNewPoints, kAdvanced,
              "new points: half-size (px) of the window in which the left keypoint is moved to "
              "its sub-pixel corner (cv::cornerSubPix) before the right pixel is aligned again "
              "(0 = off)"),
      real("max_corner_shift", &C::max_corner_shift, 0.0, 20.0, kOpen, kNewPoints, kAdvanced,
           "new points: a corner farther (px) than this from the keypoint is not taken (the "
           "pair stays as matched)"),
      // --- tracking (Sec. II-C) ---
      real("track_window_sigmas", &C::track_window_sigmas, 0.0, 10.0, kOpen, kTracking, kAdvanced,
           "track search window half-size in sigmas of the predicted pixel"),
      real("min_track_window", &C::min_track_window, 0.5, 100.0, kClosed, kTracking, kAdvanced,
           "least half-size of the track search window (px)"),
      realAbove("max_track_window", &C::max_track_window, &C::min_track_window, 500.0, kTracking,
                kAdvanced, "largest half-size of the track search window (px)"),
      real("max_track_descriptor_distance", &C::max_track_descriptor_distance, 0.0, 1.0, kOpen,
           kTracking, kAdvanced,
           "largest normalised descriptor distance of a track to its stored descriptor"),
      real("track_ratio", &C::track_ratio, 0.0, 1.0, kOpen, kTracking, kAdvanced,
           "ratio test of a track within its window (1 = off)"),
      real("track_gate_chi2_2dof", &C::track_gate_chi2_2dof, 0.0, 1000.0, kOpen, kTracking,
           kAdvanced,
           "gate on a track's squared Mahalanobis distance from its prediction (13.8 = 99.9 %)"),
      real("reacquire_below_fraction", &C::reacquire_below_fraction, 0.0, 1.0, kClosed, kTracking,
           kAdvanced,
           "below this fraction of tracks found, the lost ones are searched over the whole "
           "image (a sudden calibration change; 0 = off)"),
      // --- input checks ---
      integer("min_image_size", &C::min_image_size, 8, 10000, kImageChecks, kUser,
              "least image size accepted (px, each axis)"),
      real("min_contrast", &C::min_contrast, 0.0, 100.0, kClosed, kImageChecks, kUser,
           "least grey-level standard deviation; below it an image is rejected as all black, "
           "saturated or uniform"),
  };
  static const bool sections_checked =
      (requireKnownSections(table, frontEndParameterSections(), "frontEndParameterTable"), true);
  (void)sections_checked;
  return table;
}

const std::vector<ParameterSection>& frontEndParameterSections() {
  static const std::vector<ParameterSection> sections = {
      {kDetection, "keypoints in each image"},
      {kStereoMatching, "left-right matches within the epipolar band of x_camr (seed eq. 5-6)"},
      {kRefinement, "every stereo pair aligned to sub-pixel precision and verified"},
      {kNewPoints, "where, and how many, new points are offered to the filter"},
      {kTracking, "the filter's points found again in the next pair (seed Sec. II-C)"},
      {kImageChecks, "images rejected as unusable"},
  };
  return sections;
}

std::vector<std::string> FrontEndConfig::validate() const {
  std::vector<std::string> problems;
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    std::string problem = spec.check(*this);
    if (!problem.empty()) problems.push_back(std::move(problem));
  }
  return problems;
}

}  // namespace osc
