/// @file perfect_filter.h
/// @brief What a perfectly consistent filter scores on the campaign's honesty criterion, so
/// that a campaign is judged against it and not against 100 % (docs/campaign.md).
///
/// A run is honest when from frame 30 on all 12 errors are within 3 sigma in >= 95 % of the
/// frames and none is beyond 5. A filter whose sigmas are exactly right misses that in some
/// runs: its 12 normalised errors z = error / sigma are N(0, 1) in every frame, all within 3 in
/// 96.8 % of the frames, and they change slowly, so a run spends long stretches on one side.
/// The runs are drawn from the models of scripts/honest_by_chance.py: the running mean of a
/// constant's measurements (z_t = sum of t N(0, 1) / sqrt(t)) and first-order processes with
/// correlation times of 30, 100 and 300 frames.
#pragma once

#include <cstdint>

namespace osc {

/// A perfect filter's campaign figures over its models (lowest and highest honest share).
struct PerfectFilterScore {
  int frames = 0;              ///< frames per run
  int runs_per_model = 0;      ///< runs drawn per model
  double honest_low = 0.0;     ///< share of honest runs, the lowest of the models
  double honest_high = 0.0;    ///< ... and the highest
  double beyond_5sigma = 0.0;  ///< share of runs with some |z| > 5, the highest of the models
  double mean_share = 0.0;     ///< mean share of frames with all 12 |z| <= 3, over the models
};

/// Draws @p runs_per_model runs of @p frames frames (> 30) of each model from @p seed (the
/// same figures on every machine); drawn once per process for the same arguments. About
/// 0.8 s for 1000 runs of 600 frames.
/// @throws std::invalid_argument if frames <= 30 or runs_per_model < 1.
PerfectFilterScore perfectFilterScore(int frames, int runs_per_model = 1000,
                                      std::uint64_t seed = 1);

}  // namespace osc
