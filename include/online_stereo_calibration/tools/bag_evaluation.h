/// @file bag_evaluation.h
/// @brief ROS-free pieces of the offline bag evaluation (`evaluate`): pairing left and right
/// images by exact stamp, finding a calibration step in a reference, timing statistics.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "online_stereo_calibration/tools/estimates_csv.h"

namespace osc {

/// Index pairs (left, right) of images with exactly equal stamps (ns), in stamp order. Both
/// lists must be sorted ascending; an image without a partner, or a repeated stamp beyond the
/// first, is left out.
std::vector<std::pair<std::size_t, std::size_t>> pairByExactStamp(
    const std::vector<std::int64_t>& left_stamps, const std::vector<std::int64_t>& right_stamps);

/// The first frame whose reference differs from the previous row's by more than
/// @p translation_threshold (m) or @p angle_threshold (rad) in any parameter (a sudden
/// calibration change), or -1.
int detectStepFrame(const std::vector<ReferenceRow>& reference, double translation_threshold = 0.01,
                    double angle_threshold = 0.01);

/// Median and 95th percentile of a list of values (0, 0 when empty).
struct Percentiles {
  double median = 0.0;
  double p95 = 0.0;
};
Percentiles percentiles(std::vector<double> values);

/// A one-line progress bar: `[#####.....]  frame 120/1500  35.2 frames/s  ETA 39 s`.
std::string progressLine(int done, int total, double elapsed_seconds);

}  // namespace osc
