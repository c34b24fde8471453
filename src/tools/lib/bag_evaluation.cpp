/// @file bag_evaluation.cpp
/// @brief ROS-free pieces of the offline bag evaluation.
#include "online_stereo_calibration/tools/bag_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "online_stereo_calibration/tools/evaluation.h"

namespace osc {

std::vector<std::pair<std::size_t, std::size_t>> pairByExactStamp(
    const std::vector<std::int64_t>& left_stamps, const std::vector<std::int64_t>& right_stamps) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::size_t i = 0, j = 0;
  while (i < left_stamps.size() && j < right_stamps.size()) {
    if (left_stamps[i] < right_stamps[j]) {
      ++i;
    } else if (right_stamps[j] < left_stamps[i]) {
      ++j;
    } else {
      pairs.emplace_back(i, j);
      const std::int64_t stamp = left_stamps[i];
      while (i < left_stamps.size() && left_stamps[i] == stamp) ++i;
      while (j < right_stamps.size() && right_stamps[j] == stamp) ++j;
    }
  }
  return pairs;
}

int detectStepFrame(const std::vector<ReferenceRow>& reference, double translation_threshold,
                    double angle_threshold) {
  for (std::size_t k = 1; k < reference.size(); ++k) {
    for (int p = 0; p < 12; ++p) {
      const double difference =
          parameterError(reference[k].parameters, reference[k - 1].parameters, p);
      const double threshold = isAngleParameter(p) ? angle_threshold : translation_threshold;
      if (std::abs(difference) > threshold) {
        return reference[k].frame;
      }
    }
  }
  return -1;
}

Percentiles percentiles(std::vector<double> values) {
  Percentiles out;
  if (values.empty()) return out;
  std::sort(values.begin(), values.end());
  out.median = values[values.size() / 2];
  out.p95 = values[std::min(values.size() - 1, values.size() * 95 / 100)];
  return out;
}

std::string progressLine(int done, int total, double elapsed_seconds) {
  constexpr int kWidth = 30;
  const double fraction = total > 0 ? std::clamp(double(done) / total, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const double rate = done / std::max(elapsed_seconds, 1e-9);
  const double eta = rate > 0 ? (total - done) / rate : 0.0;
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "[%s%s] frame %5d/%d  %6.1f frames/s  ETA %5.0f s",
                std::string(filled, '#').c_str(), std::string(kWidth - filled, '.').c_str(), done,
                total, rate, eta);
  return buffer;
}

}  // namespace osc
