#include "online_stereo_calibration/tools/evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

bool isAngleParameter(int index) { return index % 6 >= 3; }

double parameterError(const Vector12d& estimate, const Vector12d& truth, int index) {
  const double error = estimate(index) - truth(index);
  return isAngleParameter(index) ? wrapAngle(error) : error;
}

Vector12d parameterErrors(const Vector12d& estimate, const Vector12d& truth) {
  Vector12d error;
  for (int k = 0; k < 12; ++k) error(k) = parameterError(estimate, truth, k);
  return error;
}

namespace {

std::map<int, const ReferenceRow*> referenceByFrame(const std::vector<ReferenceRow>& reference) {
  std::map<int, const ReferenceRow*> by_frame;
  for (const ReferenceRow& row : reference) {
    if (!by_frame.emplace(row.frame, &row).second) {
      throw std::invalid_argument("reference: frame " + std::to_string(row.frame) + " repeats");
    }
  }
  return by_frame;
}

/// (frame, error) of every estimate with a reference, sorted by frame.
std::vector<std::pair<int, const EstimateRow*>> matchedEstimates(
    const std::vector<EstimateRow>& estimates) {
  std::vector<std::pair<int, const EstimateRow*>> sorted;
  sorted.reserve(estimates.size());
  for (const EstimateRow& row : estimates) sorted.emplace_back(row.frame, &row);
  std::sort(sorted.begin(), sorted.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (sorted[i].first == sorted[i - 1].first) {
      throw std::invalid_argument("estimates: frame " + std::to_string(sorted[i].first) +
                                  " repeats");
    }
  }
  return sorted;
}

constexpr double kDeg = M_PI / 180.0;

const char* const kStateNames[12] = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                                     "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%9.5f", value);
  return buffer;
}

std::string cell(int k, const EvaluationReport& report) {
  const ParameterStatistics& s = report.parameters[k];
  const double scale = isAngleParameter(k) ? 1.0 / kDeg : 1.0;
  const bool below = s.rmse < paperTableRmse()[k];  // false for NaN
  char name[24];
  std::snprintf(name, sizeof(name), "%-7s %-3s", kStateNames[k], isAngleParameter(k) ? "deg" : "m");
  char percent[16];
  std::snprintf(percent, sizeof(percent), "%7.1f%%", 100.0 * s.within_2sigma);
  return std::string(name) + number(s.rmse * scale) + number(paperTableRmse()[k] * scale) +
         (below ? "    yes" : "     no") + number(s.sigma_at_last * scale) +
         number(paperTableSigma()[k] * scale) + percent;
}

}  // namespace

EvaluationReport evaluateWindow(const std::vector<EstimateRow>& estimates,
                                const std::vector<ReferenceRow>& reference, int first_frame,
                                int last_frame) {
  if (first_frame > last_frame) {
    throw std::invalid_argument("evaluateWindow: first frame " + std::to_string(first_frame) +
                                " > last frame " + std::to_string(last_frame));
  }
  const auto truth = referenceByFrame(reference);
  EvaluationReport report;
  report.first_frame = first_frame;
  report.last_frame = last_frame;

  Vector12d sum_squared = Vector12d::Zero();
  Vector12d within = Vector12d::Zero();
  double nees_sum = 0.0;
  for (const auto& [frame, row] : matchedEstimates(estimates)) {
    if (frame < first_frame || frame > last_frame) continue;
    const auto it = truth.find(frame);
    if (it == truth.end()) continue;
    const Vector12d error = parameterErrors(row->parameters, it->second->parameters);
    ++report.frames_used;
    sum_squared += error.cwiseAbs2();
    nees_sum += error.cwiseQuotient(row->sigmas).squaredNorm() / 12.0;
    for (int k = 0; k < 12; ++k) {
      ParameterStatistics& s = report.parameters[k];
      if (std::abs(error(k)) <= 2.0 * row->sigmas(k)) within(k) += 1.0;
      // std::max would drop a NaN; a NaN error must show.
      if (!(std::abs(error(k)) <= s.max_abs_error)) s.max_abs_error = std::abs(error(k));
      s.sigma_at_last = row->sigmas(k);  // rows are sorted by frame
    }
  }
  if (report.frames_used == 0) {
    throw std::invalid_argument("evaluateWindow: no frame in [" + std::to_string(first_frame) +
                                ", " + std::to_string(last_frame) +
                                "] has both an estimate and a reference");
  }
  const double n = report.frames_used;
  for (int k = 0; k < 12; ++k) {
    report.parameters[k].rmse = std::sqrt(sum_squared(k) / n);
    report.parameters[k].within_2sigma = within(k) / n;
  }
  report.mean_nees = nees_sum / n;
  return report;
}

int framesToConverge(const std::vector<EstimateRow>& estimates,
                     const std::vector<ReferenceRow>& reference, int parameter_index,
                     double tolerance, int from_frame) {
  if (parameter_index < 0 || parameter_index >= 12) {
    throw std::invalid_argument("framesToConverge: parameter index " +
                                std::to_string(parameter_index) + " outside 0..11");
  }
  const auto truth = referenceByFrame(reference);
  int converged_since = -1;
  for (const auto& [frame, row] : matchedEstimates(estimates)) {
    if (frame < from_frame) continue;
    const auto it = truth.find(frame);
    if (it == truth.end()) continue;
    const double error = parameterError(row->parameters, it->second->parameters, parameter_index);
    if (std::abs(error) <= tolerance) {
      if (converged_since < 0) converged_since = frame;
    } else {
      converged_since = -1;  // also for NaN
    }
  }
  return converged_since;
}

const std::array<double, 12>& paperTableRmse() {
  static const std::array<double, 12> rmse = {
      0.0608, 0.0382, 0.0132, 0.2995 * kDeg, 0.7061 * kDeg, 0.2844 * kDeg,
      0.0044, 0.0048, 0.0037, 0.0236 * kDeg, 0.0174 * kDeg, 0.0193 * kDeg};
  return rmse;
}

const std::array<double, 12>& paperTableSigma() {
  static const std::array<double, 12> sigma = {
      0.0185, 0.0206, 0.0223, 0.0025 * kDeg, 0.0011 * kDeg, 0.0011 * kDeg,
      0.0020, 0.0013, 0.0011, 0.0100 * kDeg, 0.0067 * kDeg, 0.0076 * kDeg};
  return sigma;
}

std::string formatTableI(const EvaluationReport& report) {
  char title[160];
  std::snprintf(title, sizeof(title),
                "Table I: frames %d..%d (%d used); m and deg; paper = Mueller & Wuensche 2016, "
                "Table I\n",
                report.first_frame, report.last_frame, report.frames_used);
  const std::string head = "state          RMSE    paper  below   1sigma   paper1s  in 2sig";
  std::string text = std::string(title) + head + " | " + head + "\n";
  for (int k = 0; k < 6; ++k) text += cell(k, report) + " | " + cell(k + 6, report) + "\n";
  char nees[32];
  std::snprintf(nees, sizeof(nees), "%.3f", report.mean_nees);
  return text +
         "RMSE over the window; 1sigma at the last frame; in 2sig: frames with |error| <= 2 sigma "
         "(95.4% if consistent).\nMean normalised error squared per parameter: " +
         nees + " (1 if consistent)\n";
}

}  // namespace osc
