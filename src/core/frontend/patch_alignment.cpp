#include "online_stereo_calibration/core/frontend/patch_alignment.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/LU>

namespace osc {
namespace {

/// Bilinear sample of a mono8 image; false if (x, y) is outside [0, cols-1] x [0, rows-1].
inline bool sample(const cv::Mat& image, double x, double y, float* value) {
  if (!(x >= 0.0 && y >= 0.0 && x <= image.cols - 1.0 && y <= image.rows - 1.0)) return false;
  int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  x0 = std::min(x0, image.cols - 2);
  y0 = std::min(y0, image.rows - 2);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const unsigned char* r0 = image.ptr<unsigned char>(y0) + x0;
  const unsigned char* r1 = image.ptr<unsigned char>(y0 + 1) + x0;
  const float top = r0[0] + ax * (r0[1] - r0[0]);
  const float bottom = r1[0] + ax * (r1[1] - r1[0]);
  *value = top + ay * (bottom - top);
  return true;
}

/// Samples the (2h+1)^2 patch (plus a one-pixel rim when `rim`) centred at p.
bool samplePatch(const cv::Mat& image, const Eigen::Vector2d& p, int h, std::vector<float>* out) {
  const int n = 2 * h + 1;
  out->resize(static_cast<size_t>(n * n));
  size_t k = 0;
  for (int dy = -h; dy <= h; ++dy) {
    for (int dx = -h; dx <= h; ++dx) {
      if (!sample(image, p.x() + dx, p.y() + dy, &(*out)[k++])) return false;
    }
  }
  return true;
}

}  // namespace

PatchAlignment alignPatch(const cv::Mat& source, const Eigen::Vector2d& source_point,
                          const cv::Mat& target, const Eigen::Vector2d& guess,
                          const PatchAlignmentConfig& config) {
  PatchAlignment result;
  result.position = guess;
  const int h = config.half_size;
  const int n = 2 * h + 1;
  // Template with a one-pixel rim for its central-difference gradients.
  std::vector<float> big;
  if (!samplePatch(source, source_point, h + 1, &big)) return result;
  const int nb = n + 2;
  std::vector<float> tmpl(static_cast<size_t>(n * n)), gx(tmpl.size()), gy(tmpl.size());
  double mean_t = 0.0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const size_t k = static_cast<size_t>(y * n + x);
      const size_t b = static_cast<size_t>((y + 1) * nb + (x + 1));
      tmpl[k] = big[b];
      gx[k] = 0.5f * (big[b + 1] - big[b - 1]);
      gy[k] = 0.5f * (big[b + nb] - big[b - nb]);
      mean_t += tmpl[k];
    }
  }
  mean_t /= static_cast<double>(tmpl.size());
  // Bias-compensated: the mean difference is removed, so the template gradient is used
  // minus its mean (the bias parameter is eliminated).
  double mgx = 0.0, mgy = 0.0;
  for (size_t k = 0; k < tmpl.size(); ++k) {
    mgx += gx[k];
    mgy += gy[k];
  }
  mgx /= static_cast<double>(tmpl.size());
  mgy /= static_cast<double>(tmpl.size());
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (size_t k = 0; k < tmpl.size(); ++k) {
    const double ux = gx[k] - mgx, uy = gy[k] - mgy;
    H(0, 0) += ux * ux;
    H(0, 1) += ux * uy;
    H(1, 1) += uy * uy;
  }
  H(1, 0) = H(0, 1);
  const double tr = H.trace(), det = H.determinant();
  const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  const double lmax = 0.5 * tr + disc, lmin = 0.5 * tr - disc;
  result.eigen_ratio = lmax > 0.0 ? lmin / lmax : 0.0;
  if (!(lmax > 0.0) || result.eigen_ratio < config.min_eigenvalue) return result;
  const Eigen::Matrix2d H_inv = H.inverse();

  // Inverse compositional: warp W(x; p) = x + p; the template's warp is inverted each step.
  Eigen::Vector2d p = guess;
  std::vector<float> warped;
  bool converged = false;
  for (int it = 0; it < config.max_iterations; ++it) {
    if (!samplePatch(target, p, h, &warped)) return result;
    double mean_w = 0.0;
    for (float v : warped) mean_w += v;
    mean_w /= static_cast<double>(warped.size());
    Eigen::Vector2d b = Eigen::Vector2d::Zero();
    for (size_t k = 0; k < tmpl.size(); ++k) {
      const double e = (warped[k] - mean_w) - (tmpl[k] - mean_t);
      b.x() += (gx[k] - mgx) * e;
      b.y() += (gy[k] - mgy) * e;
    }
    const Eigen::Vector2d step = H_inv * b;
    p -= step;
    if ((p - guess).norm() > config.max_shift) return result;
    if (step.squaredNorm() < 1e-4) {
      converged = true;
      break;
    }
  }
  if (!converged) return result;
  if (!samplePatch(target, p, h, &warped)) return result;
  // Normalised cross-correlation of the aligned patches.
  double mean_w = 0.0;
  for (float v : warped) mean_w += v;
  mean_w /= static_cast<double>(warped.size());
  double stt = 0.0, sww = 0.0, stw = 0.0;
  for (size_t k = 0; k < tmpl.size(); ++k) {
    const double a = tmpl[k] - mean_t, c = warped[k] - mean_w;
    stt += a * a;
    sww += c * c;
    stw += a * c;
  }
  result.ncc = (stt > 0.0 && sww > 0.0) ? stw / std::sqrt(stt * sww) : 0.0;
  result.position = p;
  result.ok = result.ncc >= config.min_ncc;
  return result;
}

}  // namespace osc
