#include "online_stereo_calibration/core/frontend/epipolar_trend.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace osc {
namespace {

/// Median of the absolute values (a copy is partially sorted).
double medianAbsolute(std::vector<double> values) {
  for (double& v : values) v = std::abs(v);
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

EpipolarTrend EpipolarTrend::fit(const std::vector<EpipolarResidual>& residuals,
                                 double center_column, double focal) {
  EpipolarTrend trend;
  trend.center_column_ = center_column;
  trend.focal_ = focal > 0.0 ? focal : 1.0;
  if (static_cast<int>(residuals.size()) < kMinResiduals) return trend;
  // Iteratively reweighted least squares with Huber weights (k = 1.345 robust sigmas): the
  // pairs that slid along an outline are the outliers here.
  constexpr int kIterations = 5;
  constexpr double kHuber = 1.345;
  constexpr double kMinScale = 0.01;  // px: a perfect fit must not make every weight tiny
  std::vector<double> errors(residuals.size());
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int iteration = 0; iteration < kIterations; ++iteration) {
    for (size_t i = 0; i < residuals.size(); ++i) {
      errors[i] = residuals[i].distance - c.dot(trend.regressors(residuals[i].right_pixel));
    }
    const double scale = std::max(kMinScale, 1.4826 * medianAbsolute(errors));
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for (size_t i = 0; i < residuals.size(); ++i) {
      const Eigen::Vector2d x = trend.regressors(residuals[i].right_pixel);
      const double a = std::abs(errors[i]) / scale;
      const double weight = a <= kHuber ? 1.0 : kHuber / a;
      normal.noalias() += weight * x * x.transpose();
      rhs.noalias() += weight * residuals[i].distance * x;
    }
    // A small ridge keeps the fit defined when all pairs lie in one column.
    normal.diagonal().array() += 1e-6 * static_cast<double>(residuals.size());
    const Eigen::Vector2d next = normal.ldlt().solve(rhs);
    if (!next.allFinite()) return trend;
    c = next;
  }
  double squared = 0.0;
  for (const EpipolarResidual& r : residuals)
    squared += std::pow(c.dot(trend.regressors(r.right_pixel)), 2);
  const double rms = std::sqrt(squared / static_cast<double>(residuals.size()));
  if (rms < kMinDistance) return trend;
  trend.coefficients_ = c;
  trend.rms_ = rms;
  return trend;
}

double EpipolarTrend::at(const Eigen::Vector2d& right_pixel) const {
  return coefficients_.dot(regressors(right_pixel));
}

Eigen::Vector2d EpipolarTrend::regressors(const Eigen::Vector2d& right_pixel) const {
  return Eigen::Vector2d(1.0, (right_pixel.x() - center_column_) / focal_);
}

}  // namespace osc
