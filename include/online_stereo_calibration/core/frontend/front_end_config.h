/// @file front_end_config.h
/// @brief Every tunable of the image front end (seed Sec. II-A, II-C): detection, the
/// epipolar-guided stereo matching (eq. 5-6), bucketing, new-point checks and tracking, and
/// frontEndParameterTable(), the one list of its keys (name, type, range, meaning) that
/// validate(), the YAML loader (`front_end:`), the ROS loader (`~front_end/`) and
/// write_default_configs read.
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/parameter_section.h"

namespace osc {

/// The front end's configuration. Units: px, degrees where the name says `_deg`.
struct FrontEndConfig {
  // --- detection and description ---
  /// "ORB" (FAST + ORB pyramid), "FAST_ORB" (FAST on the full image, ORB descriptors on
  /// one level: fastest), "AKAZE" or "SIFT".
  std::string detector = "ORB";
  /// Most keypoints kept per image, [50, 50000].
  int max_features = 2000;
  /// FAST threshold (grey levels) of ORB / FAST_ORB, [1, 255].
  int fast_threshold = 12;
  /// Pyramid levels of ORB, [1, 16]; scale factor between them, (1, 2].
  int orb_levels = 1;
  double orb_scale_factor = 1.2;
  /// Keypoints are spread over a grid of this many cells per axis (the strongest per cell
  /// first), [1, 64]. 1 = no spreading.
  int detection_grid = 8;
  /// Keypoints closer than this to the image border are ignored (px), [0, 100].
  double border = 16.0;

  // --- epipolar-guided stereo matching (eq. 5-6) ---
  /// Half-width of the epipolar band in sigmas of the line distance (x_camr covariance
  /// propagated to each candidate plus pixel noise), (0, 10].
  double band_sigmas = 3.0;
  /// Least half-width of the band (px), [0.1, 50].
  double min_band = 1.5;
  /// Largest half-width of the band (px), [min_band, 500]; bounds the search when the
  /// calibration is very uncertain.
  double max_band = 60.0;
  /// Pixel noise (px) per image added to the band, [0, 10].
  double pixel_sigma = 0.5;
  /// Largest normalised descriptor distance of a match: Hamming / bits for binary
  /// descriptors, L2 / sqrt(|a|^2 + |b|^2) for float ones. (0, 1].
  double max_descriptor_distance = 0.2;
  /// Lowe's ratio: best distance < ratio * second best among the candidates, (0, 1].
  double ratio = 0.8;

  // --- sub-pixel refinement and verification of every stereo pair (matches and tracks) ---
  /// The left keypoint's patch is aligned into the right image (Lucas-Kanade, translation,
  /// bias-compensated) from the matched right keypoint; the right pixel becomes the aligned
  /// sub-pixel position. Half-size of the patch (px), [1, 15].
  int patch_half_size = 4;
  /// Largest move (px) of the alignment from the right keypoint, (0, 20].
  double max_refinement_shift = 2.0;
  /// Tracks: the point's patch in the previous left image is aligned into the current one
  /// from the keypoint found; largest move (px) from that keypoint, (0, 20].
  double max_temporal_shift = 3.0;
  /// Tracks: largest move (px) of the alignment of the point's first patch (resampled by its
  /// predicted growth) from the frame-to-frame position; fails = the track slid off (0 = off).
  double max_anchor_shift = 1.0;
  /// Least normalised cross-correlation of the aligned patches, [-1, 1]: below, the two
  /// views show different things there (an occluding edge, a wrong match).
  double min_patch_ncc = 0.9;
  /// Search tracks whose keypoint was not detected again by aligning their patch from the
  /// previous left image at the predicted pixel (more tracks survive, at some precision).
  bool search_lost_tracks = false;
  /// ... least NCC there, [-1, 1], and largest forward-backward error (px, aligned back
  /// into the previous image), (0, 10].
  double min_search_ncc = 0.95;
  double max_forward_backward = 0.3;
  /// Depth-discontinuity check of every refined pair: each half of the patch is matched at
  /// shifts of up to this many px along the epipolar line; a textured half that prefers a
  /// shift of >= 2 px means the pixel and its neighbours lie at different depths (an
  /// occluding contour) and the pair is rejected. [0, 20]; 0 = off.
  int discontinuity_search = 8;
  /// Least ratio of the smaller to the larger eigenvalue of the patch's structure tensor,
  /// [0, 1]: below, the patch is a straight edge (its position along the edge is unknown).
  double min_patch_eigen_ratio = 0.05;
  /// Pixel noise (px) per image of a refined (sub-pixel) pair: the refined right pixel must
  /// lie within band_sigmas of the epipolar line's distance sigma computed with it in place of
  /// pixel_sigma and without the min_band floor (0.3 px with a well-known x_camr), (0, 10].
  /// A pair aligned along an outline slides off the line by a few tenths of a pixel.
  double refined_pixel_sigma = 0.07;

  // --- spatial sampling ---
  /// Bucketing grid (cells per axis) for new points: the best match per cell, and none in a
  /// cell that already holds a tracked point. [1, 64].
  int bucket_cols = 12;
  int bucket_rows = 9;
  /// At most this many new points offered per frame, [0, 10000].
  int max_new_points_per_frame = 40;
  /// No new point within this distance (px, left image) of a tracked one, [0, 200].
  double min_distance_to_track = 10.0;
  /// Least angle between the two rays of a new point (deg), [0, 30].
  double min_parallax_deg = 0.05;
  /// A new point's left keypoint is moved to its sub-pixel corner (cv::cornerSubPix over a
  /// (2 corner_half_size + 1)^2 window: where the patch's gradients meet) and its right pixel
  /// aligned again from there. A detector's pixel beside a junction of two outlines would
  /// otherwise be carried along by them as they slide over each other. [0, 15]; 0 = off.
  int corner_half_size = 2;
  /// ... unless the corner lies farther (px) than this from the keypoint: the pair is then
  /// kept as matched. (0, 20].
  double max_corner_shift = 2.0;

  // --- tracking (Sec. II-C) ---
  /// Search window half-size in sigmas of the predicted pixel (from S), (0, 10].
  double track_window_sigmas = 3.0;
  /// Least and largest half-size of the search window (px).
  double min_track_window = 3.0;   ///< [0.5, 100]
  double max_track_window = 40.0;  ///< [min_track_window, 500]
  /// Largest normalised descriptor distance of a track to its stored descriptor, (0, 1].
  double max_track_descriptor_distance = 0.2;
  /// Ratio test of a track within its window: best distance < track_ratio * runner-up,
  /// (0, 1]; 1 = off.
  double track_ratio = 0.9;
  /// Gate on the squared Mahalanobis distance (2 dof, under the filter's S) of a track's
  /// keypoint from its predicted pixel in each image (13.8 = 99.9 %), (0, 1000].
  double track_gate_chi2_2dof = 13.8;
  /// When fewer than this fraction of (at least 10) tracks is found in their windows, the
  /// lost ones are searched over the whole image by descriptor: after a sudden change of the
  /// calibration (a knocked camera) the points are far from their predictions, and found
  /// there they reach the filter as outliers, from which it detects the change. [0, 1];
  /// 0 = off.
  double reacquire_below_fraction = 0.5;

  // --- input checks ---
  /// Least image size (px, each axis) accepted, [8, 10000].
  int min_image_size = 32;
  /// Least standard deviation of the grey levels (0-255): below it the image is rejected
  /// as all black, saturated or uniform. [0, 100].
  double min_contrast = 2.0;

  /// Every problem found, each naming the field, its value and the allowed range
  /// (checks every row of frontEndParameterTable()).
  std::vector<std::string> validate() const;
};

/// One row of the front end's parameter table: one FrontEndConfig field.
struct FrontEndParameterSpec {
  enum class Type { kString, kInteger, kReal, kBool };
  std::string name;  ///< field name = key under `front_end:` (YAML) / `~front_end/` (ROS)
  std::string doc;   ///< one line for humans
  Type type = Type::kReal;
  /// Numbers: allowed range [min_value, max_value]; (min_value, ...] if min_open.
  double min_value = 0.0;
  double max_value = 0.0;
  bool min_open = false;
  /// Numbers: if set, the lower bound is this field's value instead of min_value (e.g.
  /// max_band >= min_band).
  double FrontEndConfig::*min_from_field = nullptr;
  /// Strings: the allowed values (empty = any).
  std::vector<std::string> allowed_values;
  std::string FrontEndConfig::*string_field = nullptr;
  int FrontEndConfig::*integer_field = nullptr;
  double FrontEndConfig::*real_field = nullptr;
  bool FrontEndConfig::*bool_field = nullptr;
  /// The part of the front end that uses the key: one of frontEndParameterSections().
  std::string section;
  /// false: a key a user may need for a new camera or scene; true: an internal threshold
  /// tuned on measurements (the files list it after the user's keys).
  bool advanced = false;

  bool isNumber() const { return type == Type::kInteger || type == Type::kReal; }
  /// Integer and real fields: the value (bool: 0 / 1).
  double getNumber(const FrontEndConfig& config) const;
  /// Integer and real fields (integers rounded), bool (non-zero = true). No range check.
  void setNumber(FrontEndConfig* config, double value) const;
  /// String fields.
  const std::string& getString(const FrontEndConfig& config) const;
  void setString(FrontEndConfig* config, const std::string& value) const;
  /// Bool fields.
  bool getBool(const FrontEndConfig& config) const;
  void setBool(FrontEndConfig* config, bool value) const;
  /// The value as written in a YAML file: 12, 0.35, true, ORB.
  std::string format(const FrontEndConfig& config) const;
  /// The allowed range or values for the docs: "[1, 15]", "(0, 1]", "[min_band, 500]",
  /// "{ORB, FAST_ORB, AKAZE, SIFT}", "{true, false}".
  std::string allowedText() const;
  /// The problem with this field's value in @p config, "" if none; names the key:
  /// "ratio = 3 is outside (0, 1]".
  std::string check(const FrontEndConfig& config) const;
};

/// Every field of FrontEndConfig, in declaration order.
const std::vector<FrontEndParameterSpec>& frontEndParameterTable();

/// The sections of the front end's keys, in the order config/default.yaml lists them; every
/// FrontEndParameterSpec::section names one of them.
const std::vector<ParameterSection>& frontEndParameterSections();

}  // namespace osc
