// The bake's own error from independent replicates of its VPL sum (docs/units.md, "Estimated error"): the
// standard error of the mean of R independent estimates, per texel and on 4×4-texel bins, in the measure
// bench/cycles/compare.py scores against a reference (rel_rmse_4).
#pragma once
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "lightmap/lightmap.h"

namespace irbake {

struct ErrorEstimateOptions {
  bool enabled = false;       // the walk as independent replicates (two per round), their spread the estimate
  double targetError = 0.0;   // > 0: rounds (paths or stage rays) until the whole estimate (relative, 4×4 bins) ≤ this
  double maxSeconds = 0.0;    // with a target: no round started that would end past this bake time (0: no cap)
  int maxRounds = 16;         // with a target: at most this many rounds (each the plan's paths or more stage rays)
  int bin = 4;                // bin side in texels (compare.py's rel_rmse_4)
  bool errorMap = false;      // also each texel's standard error, as pages (BakeResult::standardError)
};

// Relative error on bins: sqrt(mean over bins and RGB channels of the bin mean's squared standard error)
// over sqrt(mean over the same bins and channels of the bin value squared), bins of bin×bin texels with at
// least half of them valid (the bin mean over its valid texels), pooled over every page.
struct BinnedError {
  double relative = 0.0;   // noiseRms / signalRms (0 where there is no signal)
  double noiseRms = 0.0;   // RMS of the bins' standard errors (map units)
  double signalRms = 0.0;  // RMS of the bins' values (map units)
  size_t bins = 0;         // bins scored
  int replicates = 0;      // R
  nlohmann::json toJson() const;
};

// Which texels a bin averages: every valid texel, or only the interior ones (valid, and so are the four
// neighbours inside the page): the texels bench/cycles/compare.py scores, its chart-border ring left out.
enum class BinTexels { Valid, Interior };

// Error of the mean of R ≥ 2 independent, identically distributed replicates (replicates[r][page]), scaled
// by `scale` (an extra factor on every replicate's deviation: 1 for the plain mean), normalised by `value`'s
// bins (the map the bake writes, or the replicates' mean when null). Unbiased for the mean's squared error on
// each bin: s²/R with s² the replicates' sample variance of the bin mean. Pages must match in size.
BinnedError replicateError(const std::vector<std::vector<Lightmap>>& replicates, const std::vector<Lightmap>* value,
                           int bin = 4, double scale = 1.0, BinTexels texels = BinTexels::Valid);

// Per texel: the standard error of the replicates' mean, sqrt(s²/R) per channel (0 on invalid texels).
std::vector<Lightmap> standardErrorPages(const std::vector<std::vector<Lightmap>>& replicates);

// The mean of the replicates, texel by texel (valid where the first replicate is).
std::vector<Lightmap> replicateMean(const std::vector<std::vector<Lightmap>>& replicates);

}  // namespace irbake
