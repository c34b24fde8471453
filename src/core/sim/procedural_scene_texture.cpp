/// @file procedural_scene_texture.cpp
/// @brief ProceduralScene's surface texture: the pattern atlas baked once per process and
/// texturePattern(), which samples it.
#include "procedural_scene_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>

namespace osc {
namespace procedural_scene_internal {
// ---------------------------------------------------------------------------------------------
// Texture: a periodic, mip-mapped pattern atlas baked once per process from procedural layers
// (spectral fractal noise, sharp-edged blobs, rectangular patches), sampled twice per surface
// point at different scales and rotations so the sum never repeats. Sampling a mip-mapped
// atlas is several times cheaper than evaluating the layers per pixel, and its mip levels
// band-limit the pattern to the pixel footprint (the texture's anti-aliasing).
// ---------------------------------------------------------------------------------------------

namespace {

/// Fast log2 of a positive float: exact at powers of two, linear in between (error < 0.09);
/// plenty to choose a mip level.
inline float approximateLog2(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const float exponent = static_cast<float>(static_cast<int>(bits >> 23) - 127);
  return exponent + static_cast<float>(bits & 0x7fffffU) * (1.0f / 8388608.0f);
}

/// Box-filtered checkerboard of unit squares, filter width `width`: in [-1, 1].
float filteredChecker(float x, float y, float width) {
  auto ramp = [width](float p) {
    auto tri = [](float q) { return std::abs(q - std::floor(q) - 0.5f); };
    return 2.0f * (tri((p - 0.5f * width) * 0.5f) - tri((p + 0.5f * width) * 0.5f)) / width;
  };
  return ramp(x) * ramp(y);
}

/// Coverage in [0, 1] of the interval |p - centre| <= half, box-filtered over `width`.
float filteredInterval(float p, float centre, float half, float width) {
  return std::min(1.0f, std::max(0.0f, (half - std::abs(p - centre)) / width + 0.5f));
}

/// Brightness offset of a layer of rectangular patches (a few holding a 3x3 checkerboard)
/// on cells of size `cell` (m), periodic over `period` cells: the corners detectors like.
float patchLayer(double u, double v, double cell, int period, double footprint,
                 std::uint32_t seed) {
  const double x = u / cell, y = v / cell;
  const int ix = static_cast<int>(std::floor(x)), iy = static_cast<int>(std::floor(y));
  const std::uint32_t h =
      hashCell(((ix % period) + period) % period, ((iy % period) + period) % period, seed);
  if ((h & 255U) >= 120U) return 0.0f;  // ~47 % of the cells hold a patch
  const std::uint32_t g = mix32(h);
  auto byte = [g](int i) { return static_cast<float>((g >> (8 * i)) & 255U) / 255.0f; };
  const float fx = static_cast<float>(x - ix), fy = static_cast<float>(y - iy);
  const float cx = 0.3f + 0.4f * byte(0), cy = 0.3f + 0.4f * byte(1);
  const float hx = 0.1f + 0.18f * byte(2), hy = 0.1f + 0.18f * byte(3);
  const float width = static_cast<float>(footprint / cell);
  float coverage = filteredInterval(fx, cx, hx, width) * filteredInterval(fy, cy, hy, width);
  if (((h >> 8) & 7U) == 0U) {
    const float squares = 1.5f / hx;
    coverage *=
        filteredChecker((fx - cx + hx) * squares, (fy - cy + hy) * squares, width * squares);
  }
  const float magnitude = 0.2f + 0.3f * static_cast<float>((h >> 11) & 255U) / 255.0f;
  return ((h >> 19) & 1U ? magnitude : -magnitude) * coverage;
}

/// A periodic Gaussian random field on an n x n grid with energy between the wavelengths
/// `shortest` and `longest` (texels), amplitude spectrum ~ 1/f^slope, unit variance: spectral
/// synthesis makes it isotropic and exactly periodic.
std::vector<float> spectralField(int n, double shortest, double longest, double slope,
                                 std::uint64_t seed) {
  cv::Mat spectrum(n, n, CV_64FC2);
  Rng rng(seed);
  // Smooth band edges (a raised cosine over an octave) keep ringing down.
  auto edge = [](double x) {
    return x <= 0.0 ? 0.0 : x >= 1.0 ? 1.0 : 0.5 - 0.5 * std::cos(kPi * x);
  };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double fx = i <= n / 2 ? i : i - n, fy = j <= n / 2 ? j : j - n;
      const double f = std::sqrt(fx * fx + fy * fy) / n;  // cycles per texel
      // Outside the band (an octave beyond each end) the coefficient is zero: skip the maths.
      if (!(f > 0.5 / longest && f < 2.0 / shortest)) {
        spectrum.at<cv::Vec2d>(j, i) = cv::Vec2d(0.0, 0.0);
        continue;
      }
      const double band = edge(std::log2(f * longest) + 1.0) * edge(1.0 - std::log2(f * shortest));
      const double amplitude = band * std::pow(f, -slope);
      // Box-Muller: a complex Gaussian coefficient.
      const double radius = std::sqrt(-2.0 * std::log(std::max(rng.uniform(), 1e-300)));
      const double angle = kTwoPi * rng.uniform();
      spectrum.at<cv::Vec2d>(j, i) =
          cv::Vec2d(amplitude * radius * std::cos(angle), amplitude * radius * std::sin(angle));
    }
  }
  cv::Mat field;
  cv::dft(spectrum, field,
          cv::DFT_INVERSE | cv::DFT_SCALE);  // complex; its real part is a real field
  std::vector<float> out(static_cast<size_t>(n) * n);
  double sum2 = 0.0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double value = field.at<cv::Vec2d>(j, i)[0];
      out[static_cast<size_t>(i + n * j)] = static_cast<float>(value);
      sum2 += value * value;
    }
  }
  const float scale = static_cast<float>(1.0 / std::sqrt(sum2 / static_cast<double>(out.size())));
  for (float& value : out) value *= scale;
  return out;
}

/// Coverage of {field > threshold}, the edge a ramp one texel wide (from the local gradient).
std::vector<float> thresholdCoverage(int n, const std::vector<float>& field, float threshold) {
  std::vector<float> out(field.size());
  auto at = [&](int i, int j) {
    return field[static_cast<size_t>(((i + n) % n) + n * ((j + n) % n))];
  };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const float gx = 0.5f * (at(i + 1, j) - at(i - 1, j)),
                  gy = 0.5f * (at(i, j + 1) - at(i, j - 1));
      const float gradient = std::max(1e-6f, std::sqrt(gx * gx + gy * gy));
      out[static_cast<size_t>(i + n * j)] =
          std::min(1.0f, std::max(0.0f, 0.5f + (at(i, j) - threshold) / gradient));
    }
  }
  return out;
}

/// The baked pattern (about 0 on average), the same for every scene and built once per
/// process: fractal noise from 1.6 m to 5 cm, blobs at 0.8 m and 0.2 m, patches on cells of
/// 1.6, 0.4 and 0.1 m. One period is 6.4 m; texels are 12.5 mm.
class PatternAtlas {
 public:
  static constexpr int kLog2Size = 9;
  static constexpr int kSize = 1 << kLog2Size;
  static constexpr double kTexel = 0.0125;

  static const PatternAtlas& instance() {
    static const PatternAtlas atlas;  // thread-safe initialisation
    return atlas;
  }

  /// Value at texel coordinates (x, y), trilinear over the mip levels for a footprint of
  /// `footprint` texels, from level `min_level` up. The level is biased half a level sharper
  /// than the footprint: the usual choice (one texel per footprint) with bilinear filtering
  /// blurs over ~2 pixels.
  float sample(double x, double y, float footprint, float min_level = 0.0f) const {
    const float level = std::min(static_cast<float>(kLog2Size),
                                 std::max(min_level, approximateLog2(footprint) - 0.5f));
    const int l0 = static_cast<int>(level);
    const float t = level - static_cast<float>(l0);
    const float v0 = bilinear(l0, x, y);
    if (t <= 0.0f || l0 >= kLog2Size) return v0;
    return v0 + t * (bilinear(l0 + 1, x, y) - v0);
  }

 private:
  PatternAtlas();
  float bilinear(int level, double x, double y) const;

  /// Texels are stored in 8x8 blocks, each with a one-texel apron (the next block's first
  /// column and row: 9x9 values), so the 2x2 texels of any bilinear fetch lie in one block
  /// at offsets 0, 1, 9 and 10 from one index. Blocks keep the fetches local whatever the
  /// direction the image walks the texture in.
  static constexpr int kLog2Block = 3, kBlock = 1 << kLog2Block, kStride = kBlock + 1;
  static constexpr int kBlockValues = kStride * kStride;

  struct Level {
    const float* texels;  // blocked, with aprons
    double scale;         // 2^-level: level-0 texels -> this level's texels
    std::uint64_t mask;   // size - 1
    int log2_blocks_per_row;
  };
  std::vector<std::vector<float>> storage_;
  std::array<Level, kLog2Size + 1> levels_;
};

PatternAtlas::PatternAtlas() {
  const int n = kSize;
  const double per_metre = 1.0 / kTexel;
  const std::vector<float> fractal = spectralField(n, 0.05 * per_metre, 1.6 * per_metre, 1.0, 11);
  const std::vector<float> large =
      thresholdCoverage(n, spectralField(n, 0.5 * per_metre, 1.2 * per_metre, 0.0, 23), 0.55f);
  const std::vector<float> small =
      thresholdCoverage(n, spectralField(n, 0.12 * per_metre, 0.3 * per_metre, 0.0, 37), 0.55f);
  std::vector<std::vector<float>> rows(
      1, std::vector<float>(static_cast<size_t>(n) * n));  // row-major levels
  const double period = n * kTexel;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // The patch edges are box-filtered over the texel: its mean coverage, exactly.
      const double u = (i + 0.5) * kTexel, v = (j + 0.5) * kTexel;
      float patches = 0.0f;
      for (const auto& [cell, seed] : {std::pair<double, std::uint32_t>{1.6, 0x85ebca6bU},
                                       {0.4, 0xc2b2ae35U},
                                       {0.1, 0x27d4eb2fU}}) {
        patches +=
            patchLayer(u, v, cell, static_cast<int>(std::lround(period / cell)), kTexel, seed);
      }
      const size_t index = static_cast<size_t>(i + n * j);
      rows[0][index] =
          0.15f * fractal[index] - 0.3f * large[index] + 0.25f * small[index] + 1.2f * patches;
    }
  }
  // Mip levels: 2x2 box filter, down to one texel.
  for (int size = n / 2; size >= 1; size /= 2) {
    const std::vector<float>& fine = rows.back();
    std::vector<float> coarse(static_cast<size_t>(size) * size);
    for (int j = 0; j < size; ++j) {
      for (int i = 0; i < size; ++i) {
        auto f = [&](int a, int b) {
          return fine[static_cast<size_t>(2 * i + a + 2 * size * (2 * j + b))];
        };
        coarse[static_cast<size_t>(i + size * j)] = 0.25f * (f(0, 0) + f(1, 0) + f(0, 1) + f(1, 1));
      }
    }
    rows.push_back(std::move(coarse));
  }
  for (size_t level = 0; level < rows.size(); ++level) {
    const int log2_size = kLog2Size - static_cast<int>(level), size = 1 << log2_size;
    const int log2_blocks = std::max(0, log2_size - kLog2Block), blocks = 1 << log2_blocks;
    std::vector<float> blocked(static_cast<size_t>(blocks) * blocks * kBlockValues);
    const int span = std::min(size, kBlock);  // texels per block side (small levels: the level)
    for (int bj = 0; bj < blocks; ++bj) {
      for (int bi = 0; bi < blocks; ++bi) {
        for (int b = 0; b <= span; ++b) {
          for (int a = 0; a <= span; ++a) {  // the apron wraps around the period
            const int i = (bi * kBlock + a) % size, j = (bj * kBlock + b) % size;
            blocked[static_cast<size_t>((bi + bj * blocks) * kBlockValues + b * kStride + a)] =
                rows[level][static_cast<size_t>(i + size * j)];
          }
        }
      }
    }
    storage_.push_back(std::move(blocked));
    levels_[level] = Level{storage_.back().data(), 1.0 / static_cast<double>(1 << level),
                           static_cast<std::uint64_t>(size - 1), log2_blocks};
  }
}

float PatternAtlas::bilinear(int level, double x, double y) const {
  const Level& l = levels_[static_cast<size_t>(level)];
  const double xs = x * l.scale - 0.5, ys = y * l.scale - 0.5;  // texel centres at +0.5
  const std::int64_t i = floorToInt(xs), j = floorToInt(ys);
  const float s = static_cast<float>(xs - static_cast<double>(i)),
              r = static_cast<float>(ys - static_cast<double>(j));
  const std::uint64_t ui = static_cast<std::uint64_t>(i) & l.mask,
                      uj = static_cast<std::uint64_t>(j) & l.mask;
  const std::uint64_t block = ((uj >> kLog2Block) << l.log2_blocks_per_row) + (ui >> kLog2Block);
  const float* p =
      l.texels + block * kBlockValues + (uj & (kBlock - 1)) * kStride + (ui & (kBlock - 1));
  const float a = p[0] + s * (p[1] - p[0]), b = p[kStride] + s * (p[kStride + 1] - p[kStride]);
  return a + r * (b - a);
}

}  // namespace

float texturePattern(double u, double v, double footprint, std::uint32_t seed) {
  // Rotations with rational sines and cosines, picked by the seed (no trigonometry per sample).
  static const double kCos[8] = {0.8, 0.6, -0.6, -0.8, 0.28, -0.28, 0.96, -0.96};
  static const double kSin[8] = {0.6, 0.8, 0.8, 0.6, 0.96, 0.96, 0.28, 0.28};
  constexpr double kPerMetre = 1.0 / PatternAtlas::kTexel, kShrink = 1.0 / 1.618;
  const PatternAtlas& atlas = PatternAtlas::instance();
  const double x = u * kPerMetre, y = v * kPerMetre;
  const float footprint_texels = static_cast<float>(footprint * kPerMetre);
  const double c = kCos[seed & 7U], s = kSin[seed & 7U];
  const double ox = static_cast<double>((seed >> 3) & 1023U),
               oy = static_cast<double>((seed >> 13) & 1023U);
  const float first = atlas.sample(x + ox, y + oy, footprint_texels);
  // The second sample only needs its coarse content (level 3 and up) to break the period;
  // those levels are small and stay in cache.
  const float second = atlas.sample((c * x - s * y) * kShrink + oy, (s * x + c * y) * kShrink + ox,
                                    footprint_texels * static_cast<float>(kShrink), 3.0f);
  return std::max(0.04f, 1.0f + first + 0.5f * second);
}

}  // namespace procedural_scene_internal
}  // namespace osc
