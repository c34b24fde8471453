#include "online_stereo_calibration/tools/perfect_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>

#include "online_stereo_calibration/tools/campaign_csv.h"
#include "online_stereo_calibration/tools/campaign_score.h"

namespace osc {
namespace {

constexpr int kParameters = 12;

/// One drawn run's score: the share of scored frames with all |z| <= 3, and the largest |z|.
struct RunScore {
  double share = 0.0;
  double max_z = 0.0;
};

/// A run of one model: tau <= 0 the running mean of a constant, else a first-order process
/// with correlation time tau frames, started in its stationary distribution.
RunScore drawRun(double tau, int frames, std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double a = tau > 0.0 ? std::exp(-1.0 / tau) : 0.0;
  const double innovation = std::sqrt(1.0 - a * a);
  std::array<double, kParameters> z{}, sum{};
  int within = 0, scored = 0;
  double max_z = 0.0;
  for (int t = 0; t < frames; ++t) {
    bool all_within = true;
    for (int p = 0; p < kParameters; ++p) {
      if (tau > 0.0) {
        z[p] = t == 0 ? normal(*rng) : a * z[p] + innovation * normal(*rng);
      } else {
        sum[p] += normal(*rng);
        z[p] = sum[p] / std::sqrt(static_cast<double>(t + 1));
      }
      if (t >= kCampaignFirstScoredFrame) {
        all_within &= std::abs(z[p]) <= 3.0;
        max_z = std::max(max_z, std::abs(z[p]));
      }
    }
    if (t >= kCampaignFirstScoredFrame) {
      ++scored;
      within += all_within;
    }
  }
  return {static_cast<double>(within) / scored, max_z};
}

}  // namespace

PerfectFilterScore perfectFilterScore(int frames, int runs_per_model, std::uint64_t seed) {
  if (frames <= kCampaignFirstScoredFrame || runs_per_model < 1) {
    throw std::invalid_argument("perfectFilterScore: frames must be above " +
                                std::to_string(kCampaignFirstScoredFrame) +
                                " and runs_per_model at least 1");
  }
  // The same arguments give the same figures: drawn once per process (the campaign's summary
  // and its last line both ask for them; ~0.8 s for 1000 runs of 600 frames).
  static std::mutex mutex;
  static std::map<std::tuple<int, int, std::uint64_t>, PerfectFilterScore> drawn;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(frames, runs_per_model, seed);
  const auto found = drawn.find(key);
  if (found != drawn.end()) return found->second;
  PerfectFilterScore score;
  score.frames = frames;
  score.runs_per_model = runs_per_model;
  score.honest_low = 1.0;
  std::mt19937_64 rng(seed);
  const std::array<double, 4> taus = {0.0, 30.0, 100.0, 300.0};  // 0: the constant's mean
  for (double tau : taus) {
    int honest = 0, beyond = 0;
    double shares = 0.0;
    for (int run = 0; run < runs_per_model; ++run) {
      const RunScore r = drawRun(tau, frames, &rng);
      honest += r.share >= kHonestShare && r.max_z <= 5.0;
      beyond += r.max_z > 5.0;
      shares += r.share;
    }
    const double honest_share = static_cast<double>(honest) / runs_per_model;
    score.honest_low = std::min(score.honest_low, honest_share);
    score.honest_high = std::max(score.honest_high, honest_share);
    score.beyond_5sigma =
        std::max(score.beyond_5sigma, static_cast<double>(beyond) / runs_per_model);
    score.mean_share += shares / runs_per_model / static_cast<double>(taus.size());
  }
  drawn[key] = score;
  return score;
}

}  // namespace osc
