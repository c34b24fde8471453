#include "online_stereo_calibration/core/frontend/patch_alignment.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/LU>
#include <opencv2/core/hal/intrin.hpp>

namespace osc {
namespace {

/// Samples the (2h+1)^2 patch centred at p (bilinear; the offset is the same for every
/// pixel, so the weights are computed once). False if any sample falls outside the image.
bool samplePatch(const cv::Mat& image, const Eigen::Vector2d& p, int h, std::vector<float>* out) {
  const int n = 2 * h + 1;
  out->resize(static_cast<size_t>(n * n));
  if (!(p.x() - h >= 0.0 && p.y() - h >= 0.0 && p.x() + h <= image.cols - 1.0 &&
        p.y() + h <= image.rows - 1.0)) {
    return false;
  }
  const double fx = std::floor(p.x()), fy = std::floor(p.y());
  int x0 = static_cast<int>(fx) - h, y0 = static_cast<int>(fy) - h;
  float ax = static_cast<float>(p.x() - fx), ay = static_cast<float>(p.y() - fy);
  // At the last column / row the right / lower neighbour is not needed (weight 0).
  if (x0 + n >= image.cols) {
    --x0;
    ax += 1.0f;
  }
  if (y0 + n >= image.rows) {
    --y0;
    ay += 1.0f;
  }
  const float w00 = (1.0f - ax) * (1.0f - ay), w01 = ax * (1.0f - ay);
  const float w10 = (1.0f - ax) * ay, w11 = ax * ay;
  float* o = out->data();
  for (int y = 0; y < n; ++y) {
    const unsigned char* r0 = image.ptr<unsigned char>(y0 + y) + x0;
    const unsigned char* r1 = r0 + image.step[0];
    int x = 0;
#if CV_SIMD128
    // Four samples at a time, with the same operations in the same order as below.
    const auto load = [](const unsigned char* p) {
      return cv::v_cvt_f32(cv::v_reinterpret_as_s32(cv::v_load_expand_q(p)));
    };
    const cv::v_float32x4 v00 = cv::v_setall_f32(w00), v01 = cv::v_setall_f32(w01);
    const cv::v_float32x4 v10 = cv::v_setall_f32(w10), v11 = cv::v_setall_f32(w11);
    for (; x + 4 <= n; x += 4, o += 4) {
      cv::v_store(o, v00 * load(r0 + x) + v01 * load(r0 + x + 1) + v10 * load(r1 + x) +
                         v11 * load(r1 + x + 1));
    }
#endif
    for (; x < n; ++x) {
      *o++ = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
    }
  }
  return true;
}

/// Samples the (2h+1)^2 patch centred at p whose sample (x, y) lies at p + M (x, y)
/// (bilinear, weights per sample). False if any sample falls outside the image.
bool sampleWarpedPatch(const cv::Mat& image, const Eigen::Vector2d& p, int h,
                       const Eigen::Matrix2d& M, std::vector<float>* out) {
  const int n = 2 * h + 1;
  out->resize(static_cast<size_t>(n * n));
  const double reach_x = h * (std::abs(M(0, 0)) + std::abs(M(0, 1)));
  const double reach_y = h * (std::abs(M(1, 0)) + std::abs(M(1, 1)));
  if (!(p.x() - reach_x >= 0.0 && p.y() - reach_y >= 0.0 && p.x() + reach_x <= image.cols - 1.0 &&
        p.y() + reach_y <= image.rows - 1.0)) {
    return false;
  }
  float* o = out->data();
  for (int y = -h; y <= h; ++y) {
    for (int x = -h; x <= h; ++x) {
      const double sx = p.x() + (x * M(0, 0) + y * M(0, 1));
      const double sy = p.y() + (y * M(1, 1) + x * M(1, 0));
      const int x0 = std::min(static_cast<int>(sx), image.cols - 2);
      const int y0 = std::min(static_cast<int>(sy), image.rows - 2);
      const float ax = static_cast<float>(sx - x0), ay = static_cast<float>(sy - y0);
      const unsigned char* r0 = image.ptr<unsigned char>(y0);
      const unsigned char* r1 = r0 + image.step[0];
      *o++ = (1.0f - ay) * ((1.0f - ax) * r0[x0] + ax * r0[x0 + 1]) +
             ay * ((1.0f - ax) * r1[x0] + ax * r1[x0 + 1]);
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
  // Scratch buffers reused across calls (one set per thread).
  thread_local std::vector<float> big, tmpl, gx, gy, warped;
  const bool sampled =
      config.template_sampling == Eigen::Matrix2d::Identity()
          ? samplePatch(source, source_point, h + 1, &big)
          : sampleWarpedPatch(source, source_point, h + 1, config.template_sampling, &big);
  if (!sampled) return result;
  const int nb = n + 2;
  tmpl.resize(static_cast<size_t>(n * n));
  gx.resize(tmpl.size());
  gy.resize(tmpl.size());
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

bool straddlesDepthDiscontinuity(const cv::Mat& source, const Eigen::Vector2d& source_point,
                                 const cv::Mat& target, const Eigen::Vector2d& target_point,
                                 const Eigen::Vector2d& direction, int half_size, int max_shift) {
  const int h = half_size, n = 2 * h + 1;
  thread_local std::vector<float> tmpl, shifted;
  thread_local std::vector<double> ssd;  // [half][shift]
  if (!samplePatch(source, source_point, h, &tmpl)) return false;
  const int shifts = 2 * max_shift + 1;
  ssd.assign(static_cast<size_t>(4 * shifts), 0.0);
  // Halves: 0 left columns, 1 right columns, 2 upper rows, 3 lower rows (centre included).
  auto inHalf = [h](int q, int x, int y) {
    switch (q) {
      case 0:
        return x <= h;
      case 1:
        return x >= h;
      case 2:
        return y <= h;
      default:
        return y >= h;
    }
  };
  const int count = (h + 1) * n;
  double texture[4] = {0.0, 0.0, 0.0, 0.0};
  for (int q = 0; q < 4; ++q) {
    // Texture along the direction: variance of the directional derivative in the half.
    double sum = 0.0, sum2 = 0.0;
    for (int y = 0; y < n; ++y) {
      for (int x = 1; x + 1 < n; ++x) {
        if (!inHalf(q, x, y)) continue;
        const size_t k = static_cast<size_t>(y * n + x);
        const double gx = 0.5 * (tmpl[k + 1] - tmpl[k - 1]);
        const double gy = (y > 0 && y + 1 < n) ? 0.5 * (tmpl[k + n] - tmpl[k - n]) : 0.0;
        const double g = direction.x() * gx + direction.y() * gy;
        sum += g;
        sum2 += g * g;
      }
    }
    texture[q] = sum2 - sum * sum / count;
  }
  for (int s = 0; s < shifts; ++s) {
    const Eigen::Vector2d p = target_point + (s - max_shift) * direction;
    if (!samplePatch(target, p, h, &shifted)) return false;
    // Bias-compensated SSD per half: sum(e^2) - sum(e)^2 / count, one pass.
    double se[4] = {0.0, 0.0, 0.0, 0.0}, se2[4] = {0.0, 0.0, 0.0, 0.0};
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const size_t k = static_cast<size_t>(y * n + x);
        const double e = shifted[k] - tmpl[k];
        const double e2 = e * e;
        if (x <= h) {
          se[0] += e;
          se2[0] += e2;
        }
        if (x >= h) {
          se[1] += e;
          se2[1] += e2;
        }
        if (y <= h) {
          se[2] += e;
          se2[2] += e2;
        }
        if (y >= h) {
          se[3] += e;
          se2[3] += e2;
        }
      }
    }
    for (int q = 0; q < 4; ++q) {
      ssd[static_cast<size_t>(q * shifts + s)] = se2[q] - se[q] * se[q] / count;
    }
  }
  // A half needs enough texture along the direction to tell its own shift: at least a
  // quarter of the best-textured half's.
  const double most = std::max(std::max(texture[0], texture[1]), std::max(texture[2], texture[3]));
  for (int q = 0; q < 4; ++q) {
    if (!(texture[q] > 0.25 * most) || !(most > 0.0)) continue;
    const double* row = &ssd[static_cast<size_t>(q * shifts)];
    int best = max_shift;
    for (int s = 0; s < shifts; ++s) {
      if (row[s] < row[best]) best = s;
    }
    if (std::abs(best - max_shift) >= 2 && row[best] < 0.5 * row[max_shift]) return true;
  }
  return false;
}

}  // namespace osc
