#include "online_stereo_calibration/core/frontend/front_end_config.h"

#include <cmath>
#include <sstream>

namespace osc {
namespace {

void checkRange(std::vector<std::string>* problems, const char* name, double value, double low,
                double high, bool low_open = false) {
  const bool ok = std::isfinite(value) && (low_open ? value > low : value >= low) && value <= high;
  if (!ok) {
    std::ostringstream s;
    s << name << " = " << value << " is outside " << (low_open ? "(" : "[") << low << ", " << high
      << "]";
    problems->push_back(s.str());
  }
}

}  // namespace

std::vector<std::string> FrontEndConfig::validate() const {
  std::vector<std::string> p;
  if (detector != "ORB" && detector != "FAST_ORB" && detector != "AKAZE" && detector != "SIFT") {
    p.push_back("detector = '" + detector + "' is not one of ORB, FAST_ORB, AKAZE, SIFT");
  }
  checkRange(&p, "max_features", max_features, 50, 50000);
  checkRange(&p, "fast_threshold", fast_threshold, 1, 255);
  checkRange(&p, "orb_levels", orb_levels, 1, 16);
  checkRange(&p, "orb_scale_factor", orb_scale_factor, 1.0, 2.0, true);
  checkRange(&p, "detection_grid", detection_grid, 1, 64);
  checkRange(&p, "border", border, 0.0, 100.0);
  checkRange(&p, "band_sigmas", band_sigmas, 0.0, 10.0, true);
  checkRange(&p, "min_band", min_band, 0.1, 50.0);
  checkRange(&p, "max_band", max_band, min_band, 500.0);
  checkRange(&p, "pixel_sigma", pixel_sigma, 0.0, 10.0);
  checkRange(&p, "max_descriptor_distance", max_descriptor_distance, 0.0, 1.0, true);
  checkRange(&p, "ratio", ratio, 0.0, 1.0, true);
  checkRange(&p, "patch_half_size", patch_half_size, 1, 15);
  checkRange(&p, "max_refinement_shift", max_refinement_shift, 0.0, 20.0, true);
  checkRange(&p, "max_temporal_shift", max_temporal_shift, 0.0, 20.0, true);
  checkRange(&p, "min_search_ncc", min_search_ncc, -1.0, 1.0);
  checkRange(&p, "max_forward_backward", max_forward_backward, 0.0, 10.0, true);
  checkRange(&p, "discontinuity_search", discontinuity_search, 0, 20);
  checkRange(&p, "min_patch_ncc", min_patch_ncc, -1.0, 1.0);
  checkRange(&p, "min_patch_eigen_ratio", min_patch_eigen_ratio, 0.0, 1.0);
  checkRange(&p, "refined_pixel_sigma", refined_pixel_sigma, 0.0, 10.0, true);
  checkRange(&p, "bucket_cols", bucket_cols, 1, 64);
  checkRange(&p, "bucket_rows", bucket_rows, 1, 64);
  checkRange(&p, "max_new_points_per_frame", max_new_points_per_frame, 0, 10000);
  checkRange(&p, "min_distance_to_track", min_distance_to_track, 0.0, 200.0);
  checkRange(&p, "min_parallax_deg", min_parallax_deg, 0.0, 30.0);
  checkRange(&p, "track_window_sigmas", track_window_sigmas, 0.0, 10.0, true);
  checkRange(&p, "min_track_window", min_track_window, 0.5, 100.0);
  checkRange(&p, "max_track_window", max_track_window, min_track_window, 500.0);
  checkRange(&p, "max_track_descriptor_distance", max_track_descriptor_distance, 0.0, 1.0, true);
  checkRange(&p, "track_ratio", track_ratio, 0.0, 1.0, true);
  checkRange(&p, "reacquire_below_fraction", reacquire_below_fraction, 0.0, 1.0, false);
  checkRange(&p, "track_gate_chi2_2dof", track_gate_chi2_2dof, 0.0, 1000.0, true);
  checkRange(&p, "min_image_size", min_image_size, 8, 10000);
  checkRange(&p, "min_contrast", min_contrast, 0.0, 100.0);
  return p;
}

}  // namespace osc
