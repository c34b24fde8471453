#include "online_stereo_calibration/core/sim/procedural_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace osc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
const Eigen::Vector3f kHorizon(0.8f, 0.83f, 0.87f);  // sky colour at the horizon

// ---------------------------------------------------------------------------------------------
// Hashing, random numbers and value noise
// ---------------------------------------------------------------------------------------------

/// Integer finaliser (lowbias32): every output bit depends on every input bit.
inline std::uint32_t mix32(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

inline std::uint32_t hashCell(std::int32_t x, std::int32_t y, std::uint32_t seed) {
  return mix32((static_cast<std::uint32_t>(x) * 0x8da6b343U) ^
               (static_cast<std::uint32_t>(y) * 0xd8163841U) ^ seed);
}

/// A cheaper hash for noise lattices (one multiplication): good enough for value noise,
/// and the noise is the renderer's hot path.
inline std::uint32_t latticeHash(std::uint32_t x_term, std::uint32_t y_term, std::uint32_t seed) {
  std::uint32_t h = x_term ^ y_term ^ seed;
  h ^= h >> 15;
  h *= 0x2c1b3c6dU;
  h ^= h >> 12;
  return h;
}

/// Hash -> [0, 1).
inline float unitFloat(std::uint32_t h) {
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

/// floor() for |x| < 2^31 without a libm call (GCC calls libm for std::floor on plain x86-64).
inline std::int32_t fastFloor(double x) {
  const auto i = static_cast<std::int32_t>(x);
  return i - static_cast<std::int32_t>(x < i);
}

/// floor() to a 64-bit integer without a libm call.
inline std::int64_t floorToInt(double x) {
  const auto i = static_cast<std::int64_t>(x);
  return i - static_cast<std::int64_t>(x < static_cast<double>(i));
}

inline float smoothUnit(float t) { return t * t * (3.0f - 2.0f * t); }

/// 2D value noise in [-1, 1] with a unit lattice.
inline float valueNoise(double x, double y, std::uint32_t seed) {
  const std::int32_t ix = fastFloor(x), iy = fastFloor(y);
  const float sx = smoothUnit(static_cast<float>(x - ix));
  const float sy = smoothUnit(static_cast<float>(y - iy));
  const std::uint32_t x0 = static_cast<std::uint32_t>(ix) * 0x8da6b343U, x1 = x0 + 0x8da6b343U;
  const std::uint32_t y0 = static_cast<std::uint32_t>(iy) * 0xd8163841U, y1 = y0 + 0xd8163841U;
  const float v00 = unitFloat(latticeHash(x0, y0, seed)),
              v10 = unitFloat(latticeHash(x1, y0, seed));
  const float v01 = unitFloat(latticeHash(x0, y1, seed)),
              v11 = unitFloat(latticeHash(x1, y1, seed));
  const float a = v00 + (v10 - v00) * sx, b = v01 + (v11 - v01) * sx;
  return 2.0f * (a + (b - a) * sy) - 1.0f;
}

/// SplitMix64: small, fast and identical on every platform (std distributions are not).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Knuth's method: fine for the small means used here.
  int poisson(double mean) {
    const double limit = std::exp(-mean);
    int count = 0;
    for (double p = uniform(); p > limit && count < 1000; p *= uniform()) ++count;
    return count;
  }

 private:
  std::uint64_t state_;
};

// ---------------------------------------------------------------------------------------------
// Texture: a periodic, mip-mapped pattern atlas baked once per process from procedural layers
// (spectral fractal noise, sharp-edged blobs, rectangular patches), sampled twice per surface
// point at different scales and rotations so the sum never repeats. Sampling a mip-mapped
// atlas is several times cheaper than evaluating the layers per pixel, and its mip levels
// band-limit the pattern to the pixel footprint (the texture's anti-aliasing).
// ---------------------------------------------------------------------------------------------

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

/// The texture (about 1 on average) at surface coordinates (u, v) in metres for a sample
/// footprint (m): the atlas at an offset chosen by the seed, plus half the atlas rotated and
/// enlarged 1.618 times, so the sum of the two periodic patterns never repeats.
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

// ---------------------------------------------------------------------------------------------
// Grid traversal (Amanatides & Woo) shared by the ground and the structure grid
// ---------------------------------------------------------------------------------------------

/// Visits, in ray order, the square cells of size `cell` (indices counted from x0, y0) that
/// the ray's x-y projection crosses for t in [t_begin, t_end]. `visit(ix, iy, t_in, t_out)`
/// returns true to stop.
template <class Visit>
void traverseCells(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double x0, double y0,
                   double cell, double inverse_cell, double t_begin, double t_end, Visit&& visit) {
  const double px = o.x() + t_begin * d.x(), py = o.y() + t_begin * d.y();
  std::int64_t ix = floorToInt((px - x0) * inverse_cell), iy = floorToInt((py - y0) * inverse_cell);
  const int step_x = d.x() > 0.0 ? 1 : -1, step_y = d.y() > 0.0 ? 1 : -1;
  double next_x = kInf, next_y = kInf, delta_x = kInf, delta_y = kInf;
  if (d.x() != 0.0) {
    const double inverse = 1.0 / d.x();
    next_x = (x0 + static_cast<double>(ix + (d.x() > 0.0 ? 1 : 0)) * cell - o.x()) * inverse;
    delta_x = cell * std::abs(inverse);
  }
  if (d.y() != 0.0) {
    const double inverse = 1.0 / d.y();
    next_y = (y0 + static_cast<double>(iy + (d.y() > 0.0 ? 1 : 0)) * cell - o.y()) * inverse;
    delta_y = cell * std::abs(inverse);
  }
  double t = t_begin;
  for (int guard = 0; guard < 1000000; ++guard) {
    const double t_out = std::min(std::min(next_x, next_y), t_end);
    if (visit(ix, iy, t, t_out) || t_out >= t_end) return;
    if (next_x < next_y) {
      ix += step_x;
      t = next_x;
      next_x += delta_x;
    } else {
      iy += step_y;
      t = next_y;
      next_y += delta_y;
    }
  }
}

/// Smallest root in [0, length] of a*s^2 + b*s + c, given c >= 0 ("above" at s = 0).
double firstRoot(double a, double b, double c, double length) {
  if (c <= 0.0) return 0.0;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return kInf;
  // With c > 0 the first positive root is c / q when b < 0 (also when a is ~0: the linear
  // root), and q / a when b >= 0 and a < 0; otherwise both roots are negative.
  double root;
  if (b < 0.0) {
    root = c / (0.5 * (std::sqrt(disc) - b));
  } else {
    if (!(a < 0.0)) return kInf;
    root = -0.5 * (b + std::sqrt(disc)) / a;
  }
  return root <= length ? root : kInf;
}

// ---------------------------------------------------------------------------------------------
// Ground: a periodic table of heights on a square lattice, bilinear between vertices (so a
// ray meets it in closed form), smooth shading normals from the analytic gradient.
// ---------------------------------------------------------------------------------------------

class Ground {
 public:
  static constexpr int kSize = 128;  // vertices per period along x and y (a power of two)

  void build(double amplitude, double wavelength, std::uint32_t seed);

  double height(double x, double y) const;
  Eigen::Vector3d normal(double x, double y) const;
  double minHeight() const { return min_; }
  double maxHeight() const { return max_; }
  /// Distance to the first ground point along the ray in (0, t_max], else +infinity; the
  /// shading normal there goes to *normal.
  double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                   Eigen::Vector3d* normal) const;

 private:
  /// One lattice vertex; interleaved so a cell's data shares cache lines.
  struct Vertex {
    float height, grad_x, grad_y;
    float cell_max;  // highest vertex of the cell whose lower-left corner this is
  };
  const Vertex& at(std::int64_t i, std::int64_t j) const {
    return vertices_[static_cast<size_t>((i & (kSize - 1)) + kSize * (j & (kSize - 1)))];
  }
  double cellRoot(const Eigen::Vector3d& o, const Eigen::Vector3d& d, std::int64_t i,
                  std::int64_t j, double t_in, double t_out, Eigen::Vector3d* normal) const;
  /// Shading normal at (s, r) in [0, 1]^2 of cell (i, j): interpolated vertex gradients.
  Eigen::Vector3d cellNormal(std::int64_t i, std::int64_t j, float s, float r) const;

  bool flat_ = true;
  double spacing_ = 1.0, inverse_spacing_ = 1.0, min_ = 0.0, max_ = 0.0;
  std::vector<Vertex> vertices_;
};

void Ground::build(double amplitude, double wavelength, std::uint32_t seed) {
  flat_ = !(amplitude > 0.0);
  if (flat_) return;
  spacing_ = wavelength / 8.0;  // period = 16 wavelengths
  inverse_spacing_ = 1.0 / spacing_;
  // A sum of plane waves with whole numbers of cycles per period: smooth, isotropic-looking
  // and exactly periodic, so the table tiles the whole plane without seams.
  struct Wave {
    double kx, ky, amplitude, phase;
  };
  Rng rng(0x6a09e667f3bcc909ULL ^ seed);
  std::vector<Wave> waves;
  const double cycles = kSize * spacing_ / wavelength;
  while (waves.size() < 24) {
    const double angle = rng.uniform(0.0, kPi), magnitude = cycles * rng.uniform(0.5, 1.8);
    const double m = std::round(magnitude * std::cos(angle)),
                 n = std::round(magnitude * std::sin(angle));
    if (m == 0.0 && n == 0.0) continue;
    const double k = kTwoPi / (kSize * spacing_);
    waves.push_back({k * m, k * n, 1.0 / std::hypot(m, n), rng.uniform(0.0, kTwoPi)});
  }
  vertices_.resize(static_cast<size_t>(kSize) * kSize);
  double peak = 0.0;
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      double value = 0.0, dx = 0.0, dy = 0.0;
      for (const Wave& w : waves) {
        const double arg = w.kx * i * spacing_ + w.ky * j * spacing_ + w.phase;
        const double sine = std::sin(arg);
        value += w.amplitude * std::cos(arg);
        dx -= w.amplitude * w.kx * sine;
        dy -= w.amplitude * w.ky * sine;
      }
      vertices_[static_cast<size_t>(i + kSize * j)] = {
          static_cast<float>(value), static_cast<float>(dx), static_cast<float>(dy), 0.0f};
      peak = std::max(peak, std::abs(value));
    }
  }
  const float scale = static_cast<float>(amplitude / peak);
  min_ = kInf;
  max_ = -kInf;
  for (Vertex& v : vertices_) {
    v.height *= scale;
    v.grad_x *= scale;
    v.grad_y *= scale;
    min_ = std::min(min_, static_cast<double>(v.height));
    max_ = std::max(max_, static_cast<double>(v.height));
  }
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      vertices_[static_cast<size_t>(i + kSize * j)].cell_max =
          std::max(std::max(at(i, j).height, at(i + 1, j).height),
                   std::max(at(i, j + 1).height, at(i + 1, j + 1).height));
    }
  }
}

double Ground::height(double x, double y) const {
  if (flat_) return 0.0;
  const double gx = x * inverse_spacing_, gy = y * inverse_spacing_;
  const std::int64_t i = floorToInt(gx), j = floorToInt(gy);
  const double s = gx - static_cast<double>(i), r = gy - static_cast<double>(j);
  const double h00 = at(i, j).height, h10 = at(i + 1, j).height;
  const double h01 = at(i, j + 1).height, h11 = at(i + 1, j + 1).height;
  return h00 + (h10 - h00) * s + (h01 - h00) * r + (h00 - h10 - h01 + h11) * s * r;
}

Eigen::Vector3d Ground::normal(double x, double y) const {
  if (flat_) return Eigen::Vector3d::UnitZ();
  const double gx = x * inverse_spacing_, gy = y * inverse_spacing_;
  const std::int64_t i = floorToInt(gx), j = floorToInt(gy);
  return cellNormal(i, j, static_cast<float>(gx - static_cast<double>(i)),
                    static_cast<float>(gy - static_cast<double>(j)));
}

Eigen::Vector3d Ground::cellNormal(std::int64_t i, std::int64_t j, float s, float r) const {
  const Vertex &v00 = at(i, j), &v10 = at(i + 1, j), &v01 = at(i, j + 1), &v11 = at(i + 1, j + 1);
  const float w00 = (1.0f - s) * (1.0f - r), w10 = s * (1.0f - r), w01 = (1.0f - s) * r,
              w11 = s * r;
  const float nx = -(w00 * v00.grad_x + w10 * v10.grad_x + w01 * v01.grad_x + w11 * v11.grad_x);
  const float ny = -(w00 * v00.grad_y + w10 * v10.grad_y + w01 * v01.grad_y + w11 * v11.grad_y);
  const float inverse_norm = 1.0f / std::sqrt(nx * nx + ny * ny + 1.0f);
  return Eigen::Vector3d(nx * inverse_norm, ny * inverse_norm, inverse_norm);
}

double Ground::cellRoot(const Eigen::Vector3d& o, const Eigen::Vector3d& d, std::int64_t i,
                        std::int64_t j, double t_in, double t_out, Eigen::Vector3d* normal) const {
  // Height along the ray inside the cell is quadratic in s = t - t_in (bilinear patch).
  const double h00 = at(i, j).height, h10 = at(i + 1, j).height;
  const double h01 = at(i, j + 1).height, h11 = at(i + 1, j + 1).height;
  const double e1 = h10 - h00, e2 = h01 - h00, e3 = h00 - h10 - h01 + h11;
  const double sa = (o.x() + t_in * d.x()) * inverse_spacing_ - static_cast<double>(i);
  const double ra = (o.y() + t_in * d.y()) * inverse_spacing_ - static_cast<double>(j);
  const double sd = d.x() * inverse_spacing_, rd = d.y() * inverse_spacing_;
  const double za = o.z() + t_in * d.z();
  const double c = za - (h00 + e1 * sa + e2 * ra + e3 * sa * ra);
  const double b = d.z() - (e1 * sd + e2 * rd + e3 * (sa * rd + ra * sd));
  const double a = -e3 * sd * rd;
  const double s = firstRoot(a, b, c, t_out - t_in);
  if (!(s < kInf)) return kInf;
  const auto clamp01 = [](double x) { return static_cast<float>(std::min(1.0, std::max(0.0, x))); };
  *normal = cellNormal(i, j, clamp01(sa + sd * s), clamp01(ra + rd * s));
  return t_in + s;
}

double Ground::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                         Eigen::Vector3d* normal) const {
  if (flat_) {
    if (!(d.z() < 0.0) || !(o.z() > 0.0)) return kInf;
    const double t = -o.z() / d.z();
    *normal = Eigen::Vector3d::UnitZ();
    return t <= t_max ? t : kInf;
  }
  // Only the part of the ray inside the slab of possible heights can meet the ground.
  double t0 = 0.0, t1 = t_max;
  if (d.z() < 0.0) {
    const double inverse = 1.0 / d.z();
    t0 = std::max(t0, (max_ - o.z()) * inverse);
    t1 = std::min(t1, (min_ - o.z()) * inverse);
  } else if (d.z() > 0.0) {
    t1 = std::min(t1, (max_ - o.z()) / d.z());
  } else if (o.z() > max_ || o.z() < min_) {
    return kInf;
  }
  if (!(t0 <= t1) || !std::isfinite(t1)) return kInf;
  double hit = kInf;
  traverseCells(o, d, 0.0, 0.0, spacing_, inverse_spacing_, t0, t1,
                [&](std::int64_t i, std::int64_t j, double t_in, double t_out) {
                  // The ray's lowest point in the cell is above its highest vertex: no hit.
                  if (o.z() + (d.z() < 0.0 ? t_out : t_in) * d.z() > at(i, j).cell_max)
                    return false;
                  hit = cellRoot(o, d, i, j, t_in, t_out, normal);
                  return hit < kInf;
                });
  return hit;
}

// ---------------------------------------------------------------------------------------------
// Path: decimated polyline with a grid of its segments for distance queries
// ---------------------------------------------------------------------------------------------

class PathIndex {
 public:
  void build(const std::vector<Eigen::Vector2d>& path, double reach);
  double distance(const Eigen::Vector2d& p) const;
  const std::vector<Eigen::Vector2d>& points() const { return points_; }

 private:
  static constexpr double kCell = 16.0;
  std::vector<Eigen::Vector2d> points_;
  double reach_ = 0.0, x0_ = 0.0, y0_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_begin_, cell_items_;
};

void PathIndex::build(const std::vector<Eigen::Vector2d>& path, double reach) {
  reach_ = reach;
  points_.clear();
  if (path.empty()) points_.push_back(Eigen::Vector2d::Zero());
  for (const Eigen::Vector2d& p : path) {
    if (points_.empty() || (p - points_.back()).norm() >= 1.0) points_.push_back(p);
  }
  if (!path.empty() && (path.back() - points_.back()).norm() > 0.0) points_.push_back(path.back());
  Eigen::Vector2d lo = points_[0], hi = points_[0];
  for (const Eigen::Vector2d& p : points_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  x0_ = lo.x() - reach - kCell;
  y0_ = lo.y() - reach - kCell;
  nx_ = static_cast<int>(std::ceil((hi.x() - x0_ + reach + kCell) / kCell));
  ny_ = static_cast<int>(std::ceil((hi.y() - y0_ + reach + kCell) / kCell));
  // Counting sort of the segments into the cells their bounding boxes overlap.
  const size_t segments = std::max<size_t>(1, points_.size() - 1);
  std::vector<std::vector<int>> cells(static_cast<size_t>(nx_) * ny_);
  for (size_t k = 0; k < segments; ++k) {
    const Eigen::Vector2d a = points_[k], b = points_[std::min(k + 1, points_.size() - 1)];
    const int i0 = static_cast<int>((std::min(a.x(), b.x()) - x0_) / kCell);
    const int i1 = static_cast<int>((std::max(a.x(), b.x()) - x0_) / kCell);
    const int j0 = static_cast<int>((std::min(a.y(), b.y()) - y0_) / kCell);
    const int j1 = static_cast<int>((std::max(a.y(), b.y()) - y0_) / kCell);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i)
        cells[static_cast<size_t>(i + nx_ * j)].push_back(static_cast<int>(k));
    }
  }
  cell_begin_.assign(cells.size() + 1, 0);
  cell_items_.clear();
  for (size_t c = 0; c < cells.size(); ++c) {
    cell_items_.insert(cell_items_.end(), cells[c].begin(), cells[c].end());
    cell_begin_[c + 1] = static_cast<int>(cell_items_.size());
  }
}

double PathIndex::distance(const Eigen::Vector2d& p) const {
  const int i0 = std::max(0, static_cast<int>(std::floor((p.x() - reach_ - x0_) / kCell)));
  const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor((p.x() + reach_ - x0_) / kCell)));
  const int j0 = std::max(0, static_cast<int>(std::floor((p.y() - reach_ - y0_) / kCell)));
  const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor((p.y() + reach_ - y0_) / kCell)));
  double best = kInf;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const size_t c = static_cast<size_t>(i + nx_ * j);
      for (int k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
        const auto segment = static_cast<size_t>(cell_items_[static_cast<size_t>(k)]);
        const Eigen::Vector2d a = points_[segment];
        const Eigen::Vector2d b = points_[std::min(segment + 1, points_.size() - 1)];
        const Eigen::Vector2d ab = b - a;
        const double len2 = ab.squaredNorm();
        const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, (a + s * ab - p).norm());
      }
    }
  }
  return best <= reach_ ? best : kInf;
}

// ---------------------------------------------------------------------------------------------
// Solids: precomputed forms of the primitives and their ray intersections
// ---------------------------------------------------------------------------------------------

struct Solid {
  ScenePrimitive::Shape shape = ScenePrimitive::Shape::kBox;
  double cx = 0.0, cy = 0.0;  // axis (x, y)
  double z0 = 0.0, z1 = 0.0;  // bottom and top
  double hx = 0.0, hy = 0.0;  // box half extents; radius of the round shapes in hx
  double cos_yaw = 1.0, sin_yaw = 0.0;
  double sz = 0.0;     // sphere centre height
  double bound = 0.0;  // radius of the x-y bounding circle
};

Solid makeSolid(const ScenePrimitive& p) {
  Solid s;
  s.shape = p.shape;
  s.cx = p.position.x();
  s.cy = p.position.y();
  switch (p.shape) {
    case ScenePrimitive::Shape::kBox:
      s.hx = 0.5 * p.size.x();
      s.hy = 0.5 * p.size.y();
      s.z0 = p.position.z();
      s.z1 = p.position.z() + p.size.z();
      s.cos_yaw = std::cos(p.yaw);
      s.sin_yaw = std::sin(p.yaw);
      s.bound = std::hypot(s.hx, s.hy);
      break;
    case ScenePrimitive::Shape::kCylinder:
    case ScenePrimitive::Shape::kCone:
      s.hx = p.size.x();
      s.z0 = p.position.z();
      s.z1 = p.position.z() + p.size.z();
      s.bound = s.hx;
      break;
    case ScenePrimitive::Shape::kSphere:
      s.hx = p.size.x();
      s.sz = p.position.z();
      s.z0 = s.sz - s.hx;
      s.z1 = s.sz + s.hx;
      s.bound = s.hx;
      break;
  }
  return s;
}

constexpr double kMinHitDistance = 1e-9;

/// Entry distance into the slab lo <= p + t*d <= hi; updates [t_near, t_far] and the axis.
inline bool clipSlab(double p, double d, double lo, double hi, int axis, double* t_near,
                     double* t_far, int* near_face) {
  if (d == 0.0) return p >= lo && p <= hi;
  double ta = (lo - p) / d, tb = (hi - p) / d;
  int face = 2 * axis + 1;  // entering through the low side: the "-axis" face
  if (ta > tb) {
    std::swap(ta, tb);
    face = 2 * axis;
  }
  if (ta > *t_near) {
    *t_near = ta;
    *near_face = face;
  }
  *t_far = std::min(*t_far, tb);
  return *t_near <= *t_far;
}

double intersectBox(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d, int* face) {
  const double px = o.x() - s.cx, py = o.y() - s.cy;
  const double lx = s.cos_yaw * px + s.sin_yaw * py, ly = -s.sin_yaw * px + s.cos_yaw * py;
  const double dx = s.cos_yaw * d.x() + s.sin_yaw * d.y(),
               dy = -s.sin_yaw * d.x() + s.cos_yaw * d.y();
  double t_near = -kInf, t_far = kInf;
  int near_face = -1;
  if (!clipSlab(lx, dx, -s.hx, s.hx, 0, &t_near, &t_far, &near_face) ||
      !clipSlab(ly, dy, -s.hy, s.hy, 1, &t_near, &t_far, &near_face) ||
      !clipSlab(o.z(), d.z(), s.z0, s.z1, 2, &t_near, &t_far, &near_face) ||
      t_near < kMinHitDistance) {
    return kInf;
  }
  *face = std::min(near_face, 4);  // the bottom (5) is buried: report it as the top
  return t_near;
}

/// Smaller root of a t^2 + 2 h t + c = 0 (entry of a convex quadric), or +infinity.
inline bool quadraticRoots(double a, double h, double c, double* t_lo, double* t_hi) {
  if (a <= 0.0) return false;
  const double disc = h * h - a * c;
  if (disc < 0.0) return false;
  const double root = std::sqrt(disc);
  const double q = -(h + std::copysign(root, h));
  if (q == 0.0) {
    *t_lo = *t_hi = 0.0;
    return true;
  }
  *t_lo = q / a;
  *t_hi = c / q;
  if (*t_lo > *t_hi) std::swap(*t_lo, *t_hi);
  return true;
}

double intersectCylinder(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                         int* face) {
  const double px = o.x() - s.cx, py = o.y() - s.cy, r2 = s.hx * s.hx;
  double best = kInf;
  double t_lo, t_hi;
  if (quadraticRoots(d.x() * d.x() + d.y() * d.y(), px * d.x() + py * d.y(), px * px + py * py - r2,
                     &t_lo, &t_hi) &&
      t_lo >= kMinHitDistance) {
    const double z = o.z() + t_lo * d.z();
    if (z >= s.z0 && z <= s.z1) {
      best = t_lo;
      *face = 0;
    }
  }
  if (d.z() < 0.0 && o.z() > s.z1) {  // the top cap
    const double t = (s.z1 - o.z()) / d.z();
    const double x = px + t * d.x(), y = py + t * d.y();
    if (t < best && x * x + y * y <= r2) {
      best = t;
      *face = 1;
    }
  }
  return best;
}

double intersectSphere(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d p(o.x() - s.cx, o.y() - s.cy, o.z() - s.sz);
  double t_lo, t_hi;
  if (!quadraticRoots(1.0, p.dot(d), p.squaredNorm() - s.hx * s.hx, &t_lo, &t_hi)) return kInf;
  return t_lo >= kMinHitDistance ? t_lo : kInf;
}

double intersectCone(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                     int* face) {
  // x^2 + y^2 = k^2 w^2 with w = apex height - z in [0, height].
  const double height = s.z1 - s.z0, k = s.hx / height;
  const double px = o.x() - s.cx, py = o.y() - s.cy, w0 = s.z1 - o.z();
  const double k2 = k * k;
  const double a = d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z();
  const double h = px * d.x() + py * d.y() + k2 * w0 * d.z();
  const double c = px * px + py * py - k2 * w0 * w0;
  double best = kInf;
  auto consider = [&](double t) {
    const double w = w0 - t * d.z();
    if (t >= kMinHitDistance && t < best && w >= 0.0 && w <= height) {
      best = t;
      *face = 0;
    }
  };
  if (std::abs(a) > 1e-15) {
    const double disc = h * h - a * c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      consider((-h - root) / a);
      consider((-h + root) / a);
    }
  } else if (h != 0.0) {
    consider(-c / (2.0 * h));
  }
  if (d.z() > 0.0 && o.z() < s.z0) {  // the base disc, seen from below
    const double t = (s.z0 - o.z()) / d.z();
    const double x = px + t * d.x(), y = py + t * d.y();
    if (t < best && x * x + y * y <= s.hx * s.hx) {
      best = t;
      *face = 1;
    }
  }
  return best;
}

double intersectSolid(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                      int* face) {
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox:
      return intersectBox(s, o, d, face);
    case ScenePrimitive::Shape::kCylinder:
      return intersectCylinder(s, o, d, face);
    case ScenePrimitive::Shape::kSphere:
      *face = 0;
      return intersectSphere(s, o, d);
    case ScenePrimitive::Shape::kCone:
      return intersectCone(s, o, d, face);
  }
  return kInf;
}

Eigen::Vector3d solidNormal(const Solid& s, const Eigen::Vector3d& p, int face) {
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox: {
      if (face == 4) return Eigen::Vector3d::UnitZ();
      const double sign = (face % 2 == 0) ? 1.0 : -1.0;
      if (face < 2) return Eigen::Vector3d(sign * s.cos_yaw, sign * s.sin_yaw, 0.0);
      return Eigen::Vector3d(-sign * s.sin_yaw, sign * s.cos_yaw, 0.0);
    }
    case ScenePrimitive::Shape::kCylinder:
      if (face == 1) return Eigen::Vector3d::UnitZ();
      return Eigen::Vector3d(p.x() - s.cx, p.y() - s.cy, 0.0).normalized();
    case ScenePrimitive::Shape::kSphere:
      return Eigen::Vector3d(p.x() - s.cx, p.y() - s.cy, p.z() - s.sz).normalized();
    case ScenePrimitive::Shape::kCone: {
      if (face == 1) return -Eigen::Vector3d::UnitZ();
      const Eigen::Vector2d radial = Eigen::Vector2d(p.x() - s.cx, p.y() - s.cy).normalized();
      return Eigen::Vector3d(radial.x(), radial.y(), s.hx / (s.z1 - s.z0)).normalized();
    }
  }
  return Eigen::Vector3d::UnitZ();
}

// ---------------------------------------------------------------------------------------------
// Uniform x-y grid over the solids
// ---------------------------------------------------------------------------------------------

class SolidGrid {
 public:
  void build(const std::vector<Solid>& solids);
  /// Nearest solid hit with distance < *best; updates *best, *index and *face.
  void intersect(const std::vector<Solid>& solids, const Eigen::Vector3d& o,
                 const Eigen::Vector3d& d, double* best, int* index, int* face) const;

 private:
  double cell_ = 12.0, x0_ = 0.0, y0_ = 0.0, z_lo_ = 0.0, z_hi_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_begin_, cell_items_;
  std::vector<float> cell_top_;
};

void SolidGrid::build(const std::vector<Solid>& solids) {
  nx_ = ny_ = 0;
  if (solids.empty()) return;
  double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf;
  z_lo_ = kInf;
  z_hi_ = -kInf;
  for (const Solid& s : solids) {
    x_lo = std::min(x_lo, s.cx - s.bound);
    x_hi = std::max(x_hi, s.cx + s.bound);
    y_lo = std::min(y_lo, s.cy - s.bound);
    y_hi = std::max(y_hi, s.cy + s.bound);
    z_lo_ = std::min(z_lo_, s.z0);
    z_hi_ = std::max(z_hi_, s.z1);
  }
  // Keep the cell count bounded for very large scenes.
  cell_ = std::max(12.0, std::sqrt((x_hi - x_lo) * (y_hi - y_lo) / 4e6));
  x0_ = x_lo - 1.0;
  y0_ = y_lo - 1.0;
  nx_ = static_cast<int>(std::ceil((x_hi + 1.0 - x0_) / cell_));
  ny_ = static_cast<int>(std::ceil((y_hi + 1.0 - y0_) / cell_));
  std::vector<std::vector<int>> cells(static_cast<size_t>(nx_) * ny_);
  cell_top_.assign(cells.size(), -std::numeric_limits<float>::infinity());
  for (size_t k = 0; k < solids.size(); ++k) {
    const Solid& s = solids[k];
    const int i0 = static_cast<int>((s.cx - s.bound - x0_) / cell_);
    const int i1 = static_cast<int>((s.cx + s.bound - x0_) / cell_);
    const int j0 = static_cast<int>((s.cy - s.bound - y0_) / cell_);
    const int j1 = static_cast<int>((s.cy + s.bound - y0_) / cell_);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const size_t c = static_cast<size_t>(i + nx_ * j);
        cells[c].push_back(static_cast<int>(k));
        cell_top_[c] = std::max(cell_top_[c], static_cast<float>(s.z1));
      }
    }
  }
  cell_begin_.assign(cells.size() + 1, 0);
  cell_items_.clear();
  for (size_t c = 0; c < cells.size(); ++c) {
    cell_items_.insert(cell_items_.end(), cells[c].begin(), cells[c].end());
    cell_begin_[c + 1] = static_cast<int>(cell_items_.size());
  }
}

void SolidGrid::intersect(const std::vector<Solid>& solids, const Eigen::Vector3d& o,
                          const Eigen::Vector3d& d, double* best, int* index, int* face) const {
  if (nx_ == 0) return;
  // Clip the ray to the grid's box (x, y) and to the solids' height range (z).
  double t0 = 0.0, t1 = *best;
  int unused = 0;
  if (!clipSlab(o.x(), d.x(), x0_, x0_ + nx_ * cell_, 0, &t0, &t1, &unused) ||
      !clipSlab(o.y(), d.y(), y0_, y0_ + ny_ * cell_, 1, &t0, &t1, &unused) ||
      !clipSlab(o.z(), d.z(), z_lo_, z_hi_, 2, &t0, &t1, &unused)) {
    return;
  }
  t0 = std::max(t0, 0.0);
  if (!(t0 <= t1)) return;
  traverseCells(o, d, x0_, y0_, cell_, 1.0 / cell_, t0, t1,
                [&](std::int64_t i, std::int64_t j, double t_in, double t_out) {
                  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return true;
                  const size_t c = static_cast<size_t>(i + nx_ * j);
                  // Lowest point of the ray inside the cell: skip cells it passes above.
                  const double z_min = o.z() + (d.z() > 0.0 ? t_in : t_out) * d.z();
                  if (z_min <= cell_top_[c]) {
                    for (int k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
                      const int id = cell_items_[static_cast<size_t>(k)];
                      int f = 0;
                      const double t = intersectSolid(solids[static_cast<size_t>(id)], o, d, &f);
                      if (t < *best) {
                        *best = t;
                        *index = id;
                        *face = f;
                      }
                    }
                  }
                  return *best <= t_out;
                });
}

// ---------------------------------------------------------------------------------------------
// Backdrop: a vertical cylinder around the whole path with a jagged skyline
// ---------------------------------------------------------------------------------------------

class Backdrop {
 public:
  void build(const std::vector<Eigen::Vector2d>& path_points, double distance, double ground_low,
             std::uint32_t seed);
  /// Distance to the cylinder wall from inside (any height), +infinity if none.
  double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const;
  /// Height of the skyline at azimuth `angle` about the centre.
  double skyline(double angle) const;
  /// True if the point on the cylinder wall is below the skyline.
  bool belowSkyline(const Eigen::Vector3d& p) const {
    if (p.z() <= low_) return true;
    if (p.z() > high_) return false;
    return p.z() <= skyline(angle(p));
  }
  double angle(const Eigen::Vector3d& p) const {
    return std::atan2(p.y() - centre_.y(), p.x() - centre_.x());
  }
  const Eigen::Vector2d& centre() const { return centre_; }
  double radius() const { return radius_; }
  /// Lower bound on the distance from p to the wall along any ray.
  double minimumDistance(const Eigen::Vector3d& p) const {
    const double dx = p.x() - centre_.x(), dy = p.y() - centre_.y();
    return radius_ - std::sqrt(dx * dx + dy * dy);
  }

 private:
  double periodicNoise(double angle, int lattice, bool smooth, std::uint32_t seed) const;

  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double radius_ = 1.0, low_ = 0.0, high_ = 1.0;
  int coarse_ = 12, fine_ = 100;
  std::uint32_t seed_ = 0;
};

void Backdrop::build(const std::vector<Eigen::Vector2d>& path_points, double distance,
                     double ground_low, std::uint32_t seed) {
  Eigen::Vector2d lo = path_points[0], hi = path_points[0];
  for (const Eigen::Vector2d& p : path_points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  centre_ = 0.5 * (lo + hi);
  double reach = 0.0;
  for (const Eigen::Vector2d& p : path_points) reach = std::max(reach, (p - centre_).norm());
  radius_ = reach + distance;
  low_ = ground_low + 0.06 * distance;
  high_ = ground_low + 0.22 * distance;
  coarse_ = std::max(12, static_cast<int>(std::round(kTwoPi * radius_ / 120.0)));
  fine_ = std::max(60, static_cast<int>(std::round(kTwoPi * radius_ / 8.0)));
  seed_ = seed;
}

double Backdrop::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  const double px = o.x() - centre_.x(), py = o.y() - centre_.y();
  double t_lo, t_hi;
  if (!quadraticRoots(d.x() * d.x() + d.y() * d.y(), px * d.x() + py * d.y(),
                      px * px + py * py - radius_ * radius_, &t_lo, &t_hi)) {
    return kInf;
  }
  return t_hi > 0.0 ? t_hi : kInf;
}

double Backdrop::periodicNoise(double angle, int lattice, bool smooth, std::uint32_t seed) const {
  const double x = (angle + kPi) / kTwoPi * lattice;  // in [0, lattice]
  std::int32_t i = std::min(fastFloor(x), lattice - 1);
  float f = static_cast<float>(x - i);
  if (smooth) f = smoothUnit(f);
  const std::int32_t next = i + 1 == lattice ? 0 : i + 1;
  const float a = unitFloat(hashCell(i, 0, seed)), b = unitFloat(hashCell(next, 0, seed));
  return a + (b - a) * f;
}

double Backdrop::skyline(double angle) const {
  const double coarse = periodicNoise(angle, coarse_, true, seed_);
  const double fine = periodicNoise(angle, fine_, false, seed_ ^ 0x3c6ef372U);
  return low_ + (high_ - low_) * (0.78 * coarse + 0.22 * fine);
}

// ---------------------------------------------------------------------------------------------
// Structure generation
// ---------------------------------------------------------------------------------------------

constexpr double kTile = 32.0;  // generation cell: its structures depend on seed + index only

Eigen::Vector3f jitterTint(Rng* rng, const Eigen::Vector3f& base, float amount) {
  const float brightness = static_cast<float>(rng->uniform(1.0 - amount, 1.0 + amount));
  Eigen::Vector3f tint = base * brightness;
  for (int c = 0; c < 3; ++c) tint[c] *= static_cast<float>(rng->uniform(0.92, 1.08));
  return tint.cwiseMin(1.0f);
}

/// One random structure (1-2 primitives) at (x, y) and the radius it occupies.
double makeStructure(Rng* rng, double x, double y, const Ground& ground,
                     std::vector<ScenePrimitive>* out) {
  const double bottom = ground.minHeight() - 0.3;  // buried: no gap on undulating ground
  const double base = ground.height(x, y);
  const double kind = rng->uniform();
  auto seed = [rng]() { return static_cast<std::uint32_t>(rng->next()); };
  if (kind < 0.3) {  // building, container
    static const Eigen::Vector3f palette[] = {
        {0.62f, 0.62f, 0.6f}, {0.62f, 0.4f, 0.32f}, {0.72f, 0.64f, 0.5f}, {0.46f, 0.52f, 0.62f}};
    ScenePrimitive box;
    box.shape = ScenePrimitive::Shape::kBox;
    box.size = Eigen::Vector3d(rng->uniform(2.0, 9.0), rng->uniform(2.0, 9.0), 0.0);
    box.size.z() = base - bottom + rng->uniform(1.5, 8.0);
    box.position = Eigen::Vector3d(x, y, bottom);
    box.yaw = rng->uniform(0.0, kPi);
    box.tint = jitterTint(rng, palette[rng->next() % 4], 0.15f);
    box.texture_seed = seed();
    out->push_back(box);
    return 0.5 * std::hypot(box.size.x(), box.size.y());
  }
  if (kind < 0.55) {  // wall
    ScenePrimitive wall;
    wall.shape = ScenePrimitive::Shape::kBox;
    wall.size = Eigen::Vector3d(rng->uniform(4.0, 15.0), rng->uniform(0.2, 0.45), 0.0);
    wall.size.z() = base - bottom + rng->uniform(1.5, 4.0);
    wall.position = Eigen::Vector3d(x, y, bottom);
    wall.yaw = rng->uniform(0.0, kPi);
    wall.tint = jitterTint(rng, Eigen::Vector3f(0.66f, 0.63f, 0.58f), 0.2f);
    wall.texture_seed = seed();
    out->push_back(wall);
    return 0.5 * std::hypot(wall.size.x(), wall.size.y());
  }
  // Tree: a trunk with a round or a conical crown.
  ScenePrimitive trunk;
  trunk.shape = ScenePrimitive::Shape::kCylinder;
  const double trunk_height = rng->uniform(1.8, 3.5);
  trunk.size = Eigen::Vector3d(rng->uniform(0.12, 0.35), 0.0, base - bottom + trunk_height + 0.5);
  trunk.position = Eigen::Vector3d(x, y, bottom);
  trunk.tint = jitterTint(rng, Eigen::Vector3f(0.45f, 0.34f, 0.25f), 0.15f);
  trunk.texture_seed = seed();
  out->push_back(trunk);
  ScenePrimitive crown;
  crown.tint = jitterTint(rng, Eigen::Vector3f(0.34f, 0.5f, 0.26f), 0.2f);
  crown.texture_seed = seed();
  double radius = 0.0;
  if (rng->uniform() < 0.5) {
    crown.shape = ScenePrimitive::Shape::kSphere;
    radius = rng->uniform(1.0, 3.0);
    crown.size = Eigen::Vector3d(radius, 0.0, 0.0);
    crown.position = Eigen::Vector3d(x, y, base + trunk_height + 0.8 * radius);
  } else {
    crown.shape = ScenePrimitive::Shape::kCone;
    radius = rng->uniform(1.0, 2.5);
    crown.size = Eigen::Vector3d(radius, 0.0, rng->uniform(3.0, 8.0));
    crown.position = Eigen::Vector3d(x, y, base + 0.6 * trunk_height);
  }
  out->push_back(crown);
  return radius;
}

void appendError(std::vector<std::string>* errors, bool ok, const std::string& message) {
  if (!ok) errors->push_back(message);
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// SceneConfig
// ---------------------------------------------------------------------------------------------

std::vector<std::string> SceneConfig::validate() const {
  std::vector<std::string> e;
  appendError(&e, finite(ground_undulation) && ground_undulation >= 0.0 && ground_undulation <= 5.0,
              "ground_undulation must be in [0, 5] m");
  appendError(&e,
              finite(ground_wavelength) && ground_wavelength >= 10.0 * ground_undulation &&
                  ground_wavelength >= 4.0 && ground_wavelength <= 1000.0,
              "ground_wavelength must be in [4, 1000] m and at least 10 x ground_undulation");
  appendError(&e,
              finite(structure_density) && structure_density >= 0.0 && structure_density <= 500.0,
              "structure_density must be in [0, 500] per hectare");
  appendError(&e, finite(min_structure_distance) && min_structure_distance >= 0.0,
              "min_structure_distance must be >= 0 m");
  appendError(&e,
              finite(max_structure_distance) && max_structure_distance > min_structure_distance &&
                  max_structure_distance <= 1000.0,
              "max_structure_distance must be in (min_structure_distance, 1000] m");
  appendError(&e,
              finite(backdrop_distance) && backdrop_distance > max_structure_distance &&
                  backdrop_distance <= 5000.0,
              "backdrop_distance must be in (max_structure_distance, 5000] m");
  bool path_finite = true;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < path.size(); ++k) {
    path_finite = path_finite && path[k].allFinite();
    lo = k == 0 ? path[k] : lo.cwiseMin(path[k]);
    hi = k == 0 ? path[k] : hi.cwiseMax(path[k]);
  }
  appendError(&e, path_finite, "path must hold finite points");
  appendError(&e,
              !path_finite || ((hi - lo).maxCoeff() <= 20000.0 && lo.cwiseAbs().maxCoeff() <= 1e5 &&
                               hi.cwiseAbs().maxCoeff() <= 1e5),
              "path must span at most 20 km and stay within 100 km of the origin");
  for (size_t k = 0; k < extra_primitives.size(); ++k) {
    const ScenePrimitive& p = extra_primitives[k];
    const bool round = p.shape != ScenePrimitive::Shape::kBox;
    const bool sphere = p.shape == ScenePrimitive::Shape::kSphere;
    const bool ok = p.position.allFinite() && finite(p.yaw) && p.size.allFinite() &&
                    p.size.x() > 0.0 && (round || p.size.y() > 0.0) &&
                    (sphere || p.size.z() > 0.0) && p.tint.allFinite() && p.tint.minCoeff() >= 0.0f;
    appendError(&e, ok,
                "extra_primitives[" + std::to_string(k) +
                    "] needs finite values, positive sizes and a non-negative tint");
  }
  appendError(&e, finite(sun_elevation) && sun_elevation > 0.0 && sun_elevation <= kPi / 2.0,
              "sun_elevation must be in (0, pi/2] rad");
  appendError(&e, finite(sun_azimuth), "sun_azimuth must be finite");
  appendError(&e, finite(ambient) && ambient >= 0.0 && ambient <= 1.0, "ambient must be in [0, 1]");
  return e;
}

// ---------------------------------------------------------------------------------------------
// ProceduralScene
// ---------------------------------------------------------------------------------------------

struct ProceduralScene::Impl {
  SceneConfig config;
  Ground ground;
  PathIndex path;
  Backdrop backdrop;
  std::vector<ScenePrimitive> primitives;
  std::vector<Solid> solids;
  SolidGrid grid;
  Eigen::Vector3d sun = Eigen::Vector3d::UnitZ();
  std::uint32_t ground_seed = 0, backdrop_seed = 0;

  void generateStructures();
  bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 double max_distance, const PrimitiveCandidates* candidates, SceneHit* hit) const;
  /// Texture coordinates (u, v) in metres, pattern seed and tint of a hit.
  void surfaceFrame(const SceneHit& hit, double* u, double* v, std::uint32_t* seed,
                    Eigen::Vector3f* tint, double* scale) const;
};

void ProceduralScene::Impl::generateStructures() {
  const double reach = config.max_structure_distance + 15.0 + kTile;
  const std::vector<Eigen::Vector2d>& points = path.points();
  Eigen::Vector2d lo = points[0], hi = points[0];
  for (const Eigen::Vector2d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int tx0 = static_cast<int>(std::floor((lo.x() - reach) / kTile));
  const int ty0 = static_cast<int>(std::floor((lo.y() - reach) / kTile));
  const int nx = static_cast<int>(std::floor((hi.x() + reach) / kTile)) - tx0 + 1;
  const int ny = static_cast<int>(std::floor((hi.y() + reach) / kTile)) - ty0 + 1;
  // Mark the tiles near the path, then fill each from its own seed.
  std::vector<char> near(static_cast<size_t>(nx) * ny, 0);
  const int r = static_cast<int>(std::ceil(reach / kTile));
  for (const Eigen::Vector2d& p : points) {
    const int ci = static_cast<int>(std::floor(p.x() / kTile)) - tx0;
    const int cj = static_cast<int>(std::floor(p.y() / kTile)) - ty0;
    for (int j = std::max(0, cj - r); j <= std::min(ny - 1, cj + r); ++j) {
      for (int i = std::max(0, ci - r); i <= std::min(nx - 1, ci + r); ++i)
        near[static_cast<size_t>(i + nx * j)] = 1;
    }
  }
  const double mean_count = config.structure_density * kTile * kTile / 1e4;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (!near[static_cast<size_t>(i + nx * j)]) continue;
      const std::uint32_t tile_seed = hashCell(tx0 + i, ty0 + j, mix32(config.seed) ^ 0xa54ff53aU);
      Rng rng((static_cast<std::uint64_t>(tile_seed) << 32) | mix32(tile_seed + 1U));
      const int count = rng.poisson(mean_count);
      for (int n = 0; n < count; ++n) {
        const double x = (tx0 + i + rng.uniform()) * kTile, y = (ty0 + j + rng.uniform()) * kTile;
        std::vector<ScenePrimitive> parts;
        const double radius = makeStructure(&rng, x, y, ground, &parts);
        const double distance = path.distance(Eigen::Vector2d(x, y));
        if (distance <= config.max_structure_distance &&
            distance - radius >= config.min_structure_distance) {
          primitives.insert(primitives.end(), parts.begin(), parts.end());
        }
      }
    }
  }
}

void ProceduralScene::Impl::surfaceFrame(const SceneHit& hit, double* u, double* v,
                                         std::uint32_t* seed, Eigen::Vector3f* tint,
                                         double* scale) const {
  const Eigen::Vector3d& p = hit.point;
  *scale = 1.0;
  if (hit.surface == SceneHit::Surface::kGround) {
    *u = p.x();
    *v = p.y();
    *seed = ground_seed;
    *tint = Eigen::Vector3f(0.55f, 0.5f, 0.4f);
    return;
  }
  if (hit.surface == SceneHit::Surface::kBackdrop) {
    *u = backdrop.radius() * backdrop.angle(p);
    *v = p.z();
    *seed = backdrop_seed;
    *tint = Eigen::Vector3f(0.4f, 0.47f, 0.42f);
    *scale = 8.0;
    return;
  }
  const ScenePrimitive& prim = primitives[static_cast<size_t>(hit.primitive)];
  const Solid& s = solids[static_cast<size_t>(hit.primitive)];
  *seed = mix32(prim.texture_seed + 0x9e3779b9U * static_cast<std::uint32_t>(hit.face));
  *tint = prim.tint;
  const double px = p.x() - s.cx, py = p.y() - s.cy;
  switch (s.shape) {
    case ScenePrimitive::Shape::kBox: {
      const double lx = s.cos_yaw * px + s.sin_yaw * py, ly = -s.sin_yaw * px + s.cos_yaw * py;
      *u = hit.face < 2 ? ly : lx;
      *v = hit.face == 4 ? ly : p.z();
      return;
    }
    case ScenePrimitive::Shape::kCylinder:
      *u = hit.face == 1 ? px : s.hx * std::atan2(py, px);
      *v = hit.face == 1 ? py : p.z();
      return;
    case ScenePrimitive::Shape::kSphere: {
      const double polar = std::acos(std::clamp((p.z() - s.sz) / s.hx, -1.0, 1.0));
      *u = s.hx * std::sin(polar) * std::atan2(py, px);
      *v = s.hx * polar;
      return;
    }
    case ScenePrimitive::Shape::kCone: {
      if (hit.face == 1) {
        *u = px;
        *v = py;
        return;
      }
      const double k = s.hx / (s.z1 - s.z0), w = s.z1 - p.z();
      *u = k * w * std::atan2(py, px);
      *v = w * std::sqrt(1.0 + k * k);
      return;
    }
  }
}

ProceduralScene::ProceduralScene(const SceneConfig& config) {
  const std::vector<std::string> errors = config.validate();
  if (!errors.empty()) {
    std::string message = "invalid SceneConfig:";
    for (const std::string& e : errors) message += " " + e + ";";
    throw std::invalid_argument(message);
  }
  auto impl = std::make_shared<Impl>();
  impl->config = config;
  impl->ground.build(config.ground_undulation, config.ground_wavelength,
                     mix32(config.seed ^ 0x510e527fU));
  impl->path.build(config.path, config.max_structure_distance + 100.0);
  impl->backdrop.build(impl->path.points(), config.backdrop_distance, impl->ground.minHeight(),
                       mix32(config.seed ^ 0x9b05688cU));
  impl->ground_seed = mix32(config.seed ^ 0x1f83d9abU);
  impl->backdrop_seed = mix32(config.seed ^ 0x5be0cd19U);
  if (config.generate_structures && config.structure_density > 0.0) impl->generateStructures();
  impl->primitives.insert(impl->primitives.end(), config.extra_primitives.begin(),
                          config.extra_primitives.end());
  impl->solids.reserve(impl->primitives.size());
  for (const ScenePrimitive& p : impl->primitives) impl->solids.push_back(makeSolid(p));
  impl->grid.build(impl->solids);
  impl->sun = Eigen::Vector3d(std::cos(config.sun_elevation) * std::cos(config.sun_azimuth),
                              std::cos(config.sun_elevation) * std::sin(config.sun_azimuth),
                              std::sin(config.sun_elevation));
  impl_ = std::move(impl);
}

const SceneConfig& ProceduralScene::config() const { return impl_->config; }

const std::vector<ScenePrimitive>& ProceduralScene::primitives() const { return impl_->primitives; }

double ProceduralScene::groundHeight(double x, double y) const {
  return impl_->ground.height(x, y);
}

Eigen::Vector3d ProceduralScene::groundNormal(double x, double y) const {
  return impl_->ground.normal(x, y);
}

double ProceduralScene::distanceToPath(const Eigen::Vector2d& xy) const {
  return impl_->path.distance(xy);
}

Eigen::Vector3d ProceduralScene::backdropCircle() const {
  return Eigen::Vector3d(impl_->backdrop.centre().x(), impl_->backdrop.centre().y(),
                         impl_->backdrop.radius());
}

bool ProceduralScene::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_distance, SceneHit* hit) const {
  return impl_->intersect(origin, direction, max_distance, nullptr, hit);
}

bool ProceduralScene::intersectCandidates(const Eigen::Vector3d& origin,
                                          const Eigen::Vector3d& direction, double max_distance,
                                          const PrimitiveCandidates& candidates,
                                          SceneHit* hit) const {
  return impl_->intersect(origin, direction, max_distance, &candidates, hit);
}

std::array<Eigen::Vector3d, 8> ProceduralScene::boundingCorners(int index) const {
  const Solid& s = impl_->solids.at(static_cast<size_t>(index));
  std::array<Eigen::Vector3d, 8> corners;
  for (int k = 0; k < 8; ++k) {
    const double a = (k & 1) ? 1.0 : -1.0, b = (k & 2) ? 1.0 : -1.0;
    const double z = (k & 4) ? s.z1 : s.z0;
    if (s.shape == ScenePrimitive::Shape::kBox) {
      corners[static_cast<size_t>(k)] =
          Eigen::Vector3d(s.cx + a * s.hx * s.cos_yaw - b * s.hy * s.sin_yaw,
                          s.cy + a * s.hx * s.sin_yaw + b * s.hy * s.cos_yaw, z);
    } else {
      corners[static_cast<size_t>(k)] = Eigen::Vector3d(s.cx + a * s.hx, s.cy + b * s.hx, z);
    }
  }
  return corners;
}

bool ProceduralScene::Impl::intersect(const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& direction, double max_distance,
                                      const PrimitiveCandidates* candidates, SceneHit* hit) const {
  // A descending ray's search for the ground is bounded by the slab of ground heights; a
  // ground hit nearer than the backdrop wall can be needs no wall test (most ground rays).
  const bool descending = direction.z() < 0.0;
  double t_backdrop = descending ? kInf : backdrop.intersect(origin, direction);
  Eigen::Vector3d ground_normal;
  const double t_ground =
      ground.intersect(origin, direction, std::min(max_distance, t_backdrop), &ground_normal);
  if (descending && !(t_ground < backdrop.minimumDistance(origin)))
    t_backdrop = backdrop.intersect(origin, direction);
  double best = std::min(max_distance, t_backdrop);
  SceneHit::Surface surface = SceneHit::Surface::kBackdrop;
  if (t_ground <= best) {
    best = t_ground;
    surface = SceneHit::Surface::kGround;
  }
  int index = -1, face = 0;
  if (candidates == nullptr) {
    grid.intersect(solids, origin, direction, &best, &index, &face);
  } else {
    for (size_t k = 0; k < candidates->count && candidates->min_distance[k] < best; ++k) {
      int f = 0;
      const int id = candidates->index[k];
      const double t = intersectSolid(solids[static_cast<size_t>(id)], origin, direction, &f);
      if (t < best) {
        best = t;
        index = id;
        face = f;
      }
    }
  }
  if (index >= 0) surface = SceneHit::Surface::kStructure;
  if (surface == SceneHit::Surface::kBackdrop) {
    // Nothing nearer: the backdrop wall below the skyline, else the sky.
    if (!(t_backdrop <= max_distance)) return false;
    if (!backdrop.belowSkyline(origin + t_backdrop * direction)) return false;
  }
  hit->surface = surface;
  hit->distance = best;
  hit->point = origin + best * direction;
  hit->primitive = index;
  hit->face = face;
  switch (surface) {
    case SceneHit::Surface::kGround:
      hit->normal = ground_normal;
      break;
    case SceneHit::Surface::kStructure:
      hit->normal = solidNormal(solids[static_cast<size_t>(index)], hit->point, face);
      break;
    case SceneHit::Surface::kBackdrop: {
      const Eigen::Vector2d inward = backdrop.centre() - hit->point.head<2>();
      hit->normal = Eigen::Vector3d(inward.x(), inward.y(), 0.0).normalized();
      break;
    }
  }
  return true;
}

Eigen::Vector3f ProceduralScene::shade(const SceneHit& hit, double footprint) const {
  const Impl& s = *impl_;
  double u = 0.0, v = 0.0, scale = 1.0;
  std::uint32_t seed = 0;
  Eigen::Vector3f tint;
  s.surfaceFrame(hit, &u, &v, &seed, &tint, &scale);
  const double inverse_scale = 1.0 / scale;
  const float pattern =
      texturePattern(u * inverse_scale, v * inverse_scale, footprint * inverse_scale, seed);
  const double lambert =
      s.config.ambient + (1.0 - s.config.ambient) * std::max(0.0, hit.normal.dot(s.sun));
  const Eigen::Vector3f colour = tint * (pattern * static_cast<float>(lambert));
  // Aerial perspective: far surfaces fade a little towards the horizon's colour.
  const float haze = static_cast<float>(hit.distance / (hit.distance + 2500.0));
  return colour + haze * (kHorizon - colour);
}

Eigen::Vector3f ProceduralScene::skyColor(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3f zenith(0.42f, 0.56f, 0.84f);
  const float up = static_cast<float>(std::max(0.0, direction.z()));
  Eigen::Vector3f colour = kHorizon + std::sqrt(up) * (zenith - kHorizon);
  if (direction.z() > 0.02) {
    // Soft clouds, a function of the direction only (the sky is at infinity).
    const double scale = 1.5 / (direction.z() + 0.15);
    const float n =
        valueNoise(scale * direction.x(), scale * direction.y(), impl_->backdrop_seed ^ 0x1234567U);
    const float cover =
        0.35f * smoothUnit(std::min(1.0f, std::max(0.0f, 1.25f * n))) * std::min(1.0f, 10.0f * up);
    colour += cover * (Eigen::Vector3f(0.93f, 0.93f, 0.94f) - colour);
  }
  return colour;
}

}  // namespace osc
