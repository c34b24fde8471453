#include "online_stereo_calibration/core/estimator/consistency_monitor.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "online_stereo_calibration/core/filter/state_layout.h"

namespace osc {

Eigen::Matrix<double, 6, 1> partialShiftEstimate(const Eigen::Matrix<double, 12, 1>& g,
                                                 const Eigen::Matrix<double, 12, 12>& F,
                                                 ConsistencyBlock block) {
  const int b = block == ConsistencyBlock::kVehicleToLeft ? layout::kCaml : layout::kCamr;
  const int o = block == ConsistencyBlock::kVehicleToLeft ? layout::kCamr : layout::kCaml;
  const Eigen::MatrixXd F_bo = F.block<6, 6>(b, o);
  const Eigen::MatrixXd regression = F_bo * scaledPseudoInverse(F.block<6, 6>(o, o));
  const Eigen::MatrixXd F_partial = F.block<6, 6>(b, b) - regression * F_bo.transpose();
  const Eigen::VectorXd g_partial = g.segment<6>(b) - regression * g.segment<6>(o);
  return scaledPseudoInverse(0.5 * (F_partial + F_partial.transpose())) * g_partial;
}

const char* consistencyBlockName(ConsistencyBlock block) {
  switch (block) {
    case ConsistencyBlock::kVehicleToLeft:
      return "x_caml";
    case ConsistencyBlock::kLeftToRight:
      return "x_camr";
    case ConsistencyBlock::kPoints:
      return "points";
  }
  return "?";
}

std::string ConsistencyStatus::message() const {
  const bool left = acting(ConsistencyBlock::kVehicleToLeft);
  const bool right = acting(ConsistencyBlock::kLeftToRight);
  if (left || right) {
    return std::string("measurements disagree with the model: process noise raised on ") +
           (left && right ? "x_caml and x_camr"
            : left        ? "x_caml"
                          : "x_camr");
  }
  if (exceeded[static_cast<int>(ConsistencyBlock::kPoints)]) {
    return "measurements disagree with the model: not explained by the calibration (points, "
           "motion or pixel noise)";
  }
  return "";
}

void calibrationStatistics(const Eigen::Matrix<double, 12, 1>& g,
                           const Eigen::Matrix<double, 12, 12>& F, std::array<double, 2>* statistic,
                           std::array<int, 2>* dof) {
  const Eigen::VectorXd gd = g;
  const Eigen::MatrixXd Fd = F;
  int rank_caml = 0, rank_camr = 0, rank_both = 0;
  const double t_caml =
      scoreStatistic(Fd, gd, indexRange(layout::kCaml, layout::kPoseDim), &rank_caml);
  const double t_camr =
      scoreStatistic(Fd, gd, indexRange(layout::kCamr, layout::kPoseDim), &rank_camr);
  const double t_both = scoreStatistic(Fd, gd, indexRange(0, layout::kCalibrationDim), &rank_both);
  // Partial scores: each block with the other one free, T_{b|o} = T_{b+o} - T_o.
  (*statistic)[0] = std::max(t_both - t_camr, 0.0);
  (*dof)[0] = std::max(rank_both - rank_camr, 0);
  (*statistic)[1] = std::max(t_both - t_caml, 0.0);
  (*dof)[1] = std::max(rank_both - rank_caml, 0);
}

ConsistencyMonitor::ConsistencyMonitor(const FilterConfig& config)
    : enabled_(config.consistency_window > 0.0),
      window_(config.consistency_window),
      false_alarm_(config.consistency_false_alarm),
      max_log_inflation_(std::log(std::max(config.max_drift_inflation, 1.0))),
      log_rate_(config.drift_inflation_decade > 0.0 ? std::log(10.0) / config.drift_inflation_decade
                                                    : 0.0),
      relax_time_(config.drift_inflation_relax) {
  reset();
}

void ConsistencyMonitor::reset() {
  time_ = 0.0;
  window_entries_.clear();
  log_inflation_ = {0.0, 0.0};
  status_ = ConsistencyStatus();
  status_.enabled = enabled_;
}

void ConsistencyMonitor::forgetEvidence() {
  window_entries_.clear();
  evaluate();
}

void ConsistencyMonitor::addUpdate(double dt, const UpdateScores* scores) {
  if (!enabled_) return;
  time_ += dt;
  if (scores) window_entries_.push_back({time_, *scores});
  while (!window_entries_.empty() && window_entries_.front().time <= time_ - window_) {
    window_entries_.pop_front();
  }
  evaluate();
  // The factor of a block whose disagreement is significant grows, else relaxes.
  for (int k = 0; k < 2; ++k) {
    if (status_.acting(static_cast<ConsistencyBlock>(k))) {
      log_inflation_[k] = std::min(log_inflation_[k] + log_rate_ * dt, max_log_inflation_);
    } else {
      log_inflation_[k] *= relax_time_ > 0.0 ? std::exp(-dt / relax_time_) : 0.0;
    }
  }
  status_.inflation.caml = std::exp(log_inflation_[0]);
  status_.inflation.camr = std::exp(log_inflation_[1]);
}

void ConsistencyMonitor::evaluate() {
  Eigen::Matrix<double, 12, 1> score = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::Matrix<double, 12, 12> information = Eigen::Matrix<double, 12, 12>::Zero();
  double rest = 0.0, rest_dof = 0.0;
  for (const Entry& entry : window_entries_) {
    score += entry.scores.score;
    information += entry.scores.information;
    rest += entry.scores.rest;
    rest_dof += entry.scores.rest_dof;
  }
  status_.window_updates = static_cast<int>(window_entries_.size());
  std::array<double, 2> statistic = {0.0, 0.0};
  std::array<int, 2> dof = {0, 0};
  if (!window_entries_.empty()) calibrationStatistics(score, information, &statistic, &dof);
  const int points = static_cast<int>(ConsistencyBlock::kPoints);
  const std::array<double, kConsistencyBlocks> sums = {statistic[0], statistic[1], rest};
  const std::array<double, kConsistencyBlocks> dofs = {double(dof[0]), double(dof[1]), rest_dof};
  for (int k = 0; k < kConsistencyBlocks; ++k) {
    status_.statistic[k] = dofs[k] > 0.0 ? sums[k] / dofs[k] : 0.0;
    status_.bound[k] =
        dofs[k] > 0.0 ? chiSquareUpperQuantile(dofs[k], false_alarm_) / dofs[k] : 0.0;
  }
  // A common excess (the noise of every measurement under-estimated) is not the calibration's.
  const double common = std::max(status_.statistic[points], 1.0);
  for (int k = 0; k < 2; ++k) status_.statistic[k] /= common;
  for (int k = 0; k < kConsistencyBlocks; ++k) {
    status_.exceeded[k] = dofs[k] > 0.0 && status_.statistic[k] > status_.bound[k];
  }
}

}  // namespace osc
