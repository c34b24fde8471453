#include "online_stereo_calibration/core/frontend/orb_description.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace osc {

OrbDescription::OrbDescription(int patch_size, int edge_threshold, int fast_threshold)
    : patch_size_(patch_size), edge_threshold_(edge_threshold), fast_threshold_(fast_threshold) {
  if (patch_size < 2 || patch_size == 31) {
    throw std::invalid_argument("OrbDescription: patch size " + std::to_string(patch_size) +
                                " (>= 2, not ORB's learned 31)");
  }
  // Half-width of each row of the circular patch of the orientation, made symmetric in the
  // two axes as cv::ORB makes it: rows up to 45 degrees from the circle, the rest mirrored.
  const int r = patch_size / 2;
  half_width_.assign(static_cast<size_t>(r + 2), 0);
  const int v_max = cvFloor(r * std::sqrt(2.f) / 2 + 1);
  const int v_min = cvCeil(r * std::sqrt(2.f) / 2);
  for (int v = 0; v <= v_max; ++v) {
    half_width_[static_cast<size_t>(v)] = cvRound(std::sqrt(static_cast<double>(r) * r - v * v));
  }
  for (int v = r, v0 = 0; v >= v_min; --v) {
    while (half_width_[static_cast<size_t>(v0)] == half_width_[static_cast<size_t>(v0 + 1)]) ++v0;
    half_width_[static_cast<size_t>(v)] = v0;
    ++v0;
  }
  // ORB's random pattern for patch sizes other than 31: a fixed seed, x then y of each point
  // uniform in [-patch/2, patch/2].
  cv::RNG rng(0x34985739);
  pattern_x_.resize(kPoints);
  pattern_y_.resize(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    pattern_x_[static_cast<size_t>(i)] =
        static_cast<float>(rng.uniform(-patch_size / 2, patch_size / 2 + 1));
    pattern_y_[static_cast<size_t>(i)] =
        static_cast<float>(rng.uniform(-patch_size / 2, patch_size / 2 + 1));
  }
  // The farthest a rotated pattern point can land (rounded).
  border_ = static_cast<int>(std::ceil((patch_size / 2) * std::sqrt(2.0))) + 1;
}

void OrbDescription::detect(const cv::Mat& mono, int max_keypoints,
                            std::vector<cv::KeyPoint>* keypoints) const {
  // cv::ORB on one level: FAST with non-maximum suppression, nothing within edgeThreshold of
  // the border, the best nfeatures by FAST score.
  cv::FAST(mono, *keypoints, fast_threshold_, true);
  cv::KeyPointsFilter::runByImageBorder(*keypoints, mono.size(), edge_threshold_);
  cv::KeyPointsFilter::retainBest(*keypoints, max_keypoints);
  for (cv::KeyPoint& k : *keypoints) {
    k.octave = 0;
    k.size = static_cast<float>(patch_size_);
  }
}

namespace {

/// First moments (m_10, m_01) of the intensity over a circular patch of rows -r..r with
/// half-widths half_width[|v|], centred at `center` (integers: exact in any order).
void moments(const unsigned char* center, int step, int r, const std::vector<int>& half_width,
             int* m_10, int* m_01) {
  int m10 = 0, m01 = 0;
  for (int u = -r; u <= r; ++u) m10 += u * center[u];
  for (int v = 1; v <= r; ++v) {
    const int d = half_width[static_cast<size_t>(v)];
    const unsigned char* below = center + v * step;
    const unsigned char* above = center - v * step;
    int difference = 0;
    for (int u = -d; u <= d; ++u) {
      difference += below[u] - above[u];
      m10 += u * (below[u] + above[u]);
    }
    m01 += v * difference;
  }
  *m_10 = m10;
  *m_01 = m01;
}

}  // namespace

void OrbDescription::orient(const cv::Mat& mono, std::vector<cv::KeyPoint>* keypoints) const {
  CV_Assert(mono.type() == CV_8UC1);
  const int r = patch_size_ / 2;
  const int step = static_cast<int>(mono.step[0]);
#if CV_SIMD128
  // Each row of the patch as chunks of eight pixels from -r on, with per-lane weights u (for
  // m_10) and v (for m_01) that are zero outside the row's half-width: sixteen-bit products
  // summed in pairs into 32 bits (exact; |u| (below + above) <= 9 * 510 for patch 19).
  const int chunks = (2 * r + 1 + 7) / 8;
  const bool simd = r <= 15;  // the products stay within 16 bits
  std::vector<short> u_weight(static_cast<size_t>((r + 1) * chunks * 8), 0);
  std::vector<short> v_weight(u_weight.size(), 0);
  for (int v = 0; v <= r; ++v) {
    const int d = v == 0 ? r : half_width_[static_cast<size_t>(v)];
    for (int lane = 0; lane < chunks * 8; ++lane) {
      const int u = lane - r;
      if (u < -d || u > d) continue;
      u_weight[static_cast<size_t>(v * chunks * 8 + lane)] = static_cast<short>(u);
      v_weight[static_cast<size_t>(v * chunks * 8 + lane)] = static_cast<short>(v);
    }
  }
  const auto pixels = [](const unsigned char* p) {
    return cv::v_reinterpret_as_s16(cv::v_load_expand(p));
  };
#endif
  for (cv::KeyPoint& k : *keypoints) {
    const int cx = cvRound(k.pt.x), cy = cvRound(k.pt.y);
    CV_Assert(cx >= r && cy >= r && cx < mono.cols - r && cy < mono.rows - r);
    const unsigned char* center = mono.ptr<unsigned char>(cy) + cx;
    int m_10 = 0, m_01 = 0;
#if CV_SIMD128
    if (simd && cx - r + chunks * 8 <= mono.cols) {  // the last chunk stays in the row
      cv::v_int32x4 sum_10 = cv::v_setzero_s32(), sum_01 = cv::v_setzero_s32();
      for (int c = 0; c < chunks; ++c) {
        const cv::v_int16x8 u = cv::v_load(&u_weight[static_cast<size_t>(c * 8)]);
        sum_10 += cv::v_dotprod(pixels(center - r + 8 * c), u);
      }
      for (int v = 1; v <= r; ++v) {
        const unsigned char* below = center + v * step - r;
        const unsigned char* above = center - v * step - r;
        for (int c = 0; c < chunks; ++c) {
          const size_t w = static_cast<size_t>((v * chunks + c) * 8);
          const cv::v_int16x8 b = pixels(below + 8 * c), a = pixels(above + 8 * c);
          sum_10 += cv::v_dotprod(b + a, cv::v_load(&u_weight[w]));
          sum_01 += cv::v_dotprod(b - a, cv::v_load(&v_weight[w]));
        }
      }
      m_10 = cv::v_reduce_sum(sum_10);
      m_01 = cv::v_reduce_sum(sum_01);
    } else {
      moments(center, step, r, half_width_, &m_10, &m_01);
    }
#else
    moments(center, step, r, half_width_, &m_10, &m_01);
#endif
    k.angle = cv::fastAtan2(static_cast<float>(m_01), static_cast<float>(m_10));
  }
}

bool OrbDescription::compute(const cv::Mat& mono, const std::vector<cv::KeyPoint>& keypoints,
                             cv::Mat* descriptors) const {
  CV_Assert(mono.type() == CV_8UC1);
  for (const cv::KeyPoint& k : keypoints) {
    const int x = cvRound(k.pt.x), y = cvRound(k.pt.y);
    if (k.octave != 0 || x < border_ || y < border_ || x >= mono.cols - border_ ||
        y >= mono.rows - border_) {
      return false;
    }
  }
  // ORB's smoothing before the tests, done as cv::ORB does it: in place, inside a copy of
  // the image with a mirrored border (filtering the bare image gives values that differ by
  // one grey level at some pixels, and so different bits).
  constexpr int kOrbBorder = 20;  // cv::ORB's for edgeThreshold 19
  cv::Mat extended;
  cv::copyMakeBorder(mono, extended, kOrbBorder, kOrbBorder, kOrbBorder, kOrbBorder,
                     cv::BORDER_REFLECT_101);
  cv::Mat blurred = extended(cv::Rect(kOrbBorder, kOrbBorder, mono.cols, mono.rows));
  cv::GaussianBlur(blurred, blurred, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
  const int step = static_cast<int>(blurred.step[0]);
  descriptors->create(static_cast<int>(keypoints.size()), kPoints / 16, CV_8U);
  alignas(16) int offset[kPoints];
  for (size_t j = 0; j < keypoints.size(); ++j) {
    const cv::KeyPoint& k = keypoints[j];
    // The same float arithmetic as cv::ORB (angle in float, cos/sin rounded to float,
    // coordinates rounded to nearest even), so every test reads the same pixels.
    const float angle = k.angle * static_cast<float>(CV_PI / 180.f);
    const float a = static_cast<float>(std::cos(static_cast<double>(angle)));
    const float b = static_cast<float>(std::sin(static_cast<double>(angle)));
    int i = 0;
#if CV_SIMD128
    const cv::v_float32x4 va = cv::v_setall_f32(a), vb = cv::v_setall_f32(b);
    // The offset row * step + column in float: exact (integers far below 2^24), and cheaper
    // than a 32-bit integer product, which SSE2 lacks.
    const cv::v_float32x4 vstep = cv::v_setall_f32(static_cast<float>(step));
    for (; i < kPoints; i += 4) {
      const cv::v_float32x4 px = cv::v_load(&pattern_x_[static_cast<size_t>(i)]);
      const cv::v_float32x4 py = cv::v_load(&pattern_y_[static_cast<size_t>(i)]);
      const cv::v_float32x4 ix = cv::v_cvt_f32(cv::v_round(px * va - py * vb));
      const cv::v_float32x4 iy = cv::v_cvt_f32(cv::v_round(px * vb + py * va));
      cv::v_store_aligned(offset + i, cv::v_round(iy * vstep + ix));
    }
#endif
    for (; i < kPoints; ++i) {
      const float px = pattern_x_[static_cast<size_t>(i)], py = pattern_y_[static_cast<size_t>(i)];
      offset[i] = cvRound(px * b + py * a) * step + cvRound(px * a - py * b);
    }
    const unsigned char* center = blurred.ptr<unsigned char>(cvRound(k.pt.y)) + cvRound(k.pt.x);
    unsigned char* out = descriptors->ptr<unsigned char>(static_cast<int>(j));
    // Eight tests per byte, written out (a loop with a variable shift is twice as slow).
    const auto test = [center](const int* o, int bit) {
      return static_cast<int>(center[o[2 * bit]] < center[o[2 * bit + 1]]) << bit;
    };
    for (int byte = 0; byte < kPoints / 16; ++byte) {
      const int* o = offset + 16 * byte;
      out[byte] = static_cast<unsigned char>(test(o, 0) | test(o, 1) | test(o, 2) | test(o, 3) |
                                             test(o, 4) | test(o, 5) | test(o, 6) | test(o, 7));
    }
  }
  return true;
}

}  // namespace osc
