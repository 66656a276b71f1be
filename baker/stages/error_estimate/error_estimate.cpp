// Standard errors from independent replicates, per texel and on bins.
#include "stages/error_estimate/error_estimate.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace irbake {
namespace {

void checkReplicates(const std::vector<std::vector<Lightmap>>& replicates) {
  if (replicates.size() < 2)
    throw Error(ErrorCode::Usage, "", "an error estimate needs at least two independent replicates");
  for (const auto& r : replicates) {
    if (r.size() != replicates[0].size())
      throw Error(ErrorCode::InvalidData, "", "error estimate: replicates with different page counts");
    for (size_t p = 0; p < r.size(); ++p)
      if (r[p].size() != replicates[0][p].size() || r[p].texels.size() != r[p].size())
        throw Error(ErrorCode::InvalidData, "", "error estimate: replicate pages of different sizes");
  }
}

bool validAt(const Lightmap& m, size_t t) { return m.valid.size() != m.size() || m.valid[t]; }

// Valid with its four in-page neighbours valid (compare.py's erode_cover: the page's edge does not erode).
bool interiorAt(const Lightmap& m, int x, int y) {
  const auto at = [&](int u, int v) { return validAt(m, static_cast<size_t>(v) * m.width + u); };
  return at(x, y) && (x == 0 || at(x - 1, y)) && (x + 1 == m.width || at(x + 1, y)) && (y == 0 || at(x, y - 1)) &&
         (y + 1 == m.height || at(x, y + 1));
}

// Per bin: the valid texels' mean of each replicate and of the value map, accumulated into sums of squares.
struct BinSums {
  double noise2 = 0.0, signal2 = 0.0;
  size_t bins = 0;
};

void scorePage(const std::vector<std::vector<Lightmap>>& replicates, size_t p, const Lightmap* value, int bin,
               double scale, BinTexels which, BinSums& sums) {
  const Lightmap& first = replicates[0][p];
  const size_t R = replicates.size();
  std::vector<glm::dvec3> means(R);
  for (int by = 0; by + bin <= first.height; by += bin)
    for (int bx = 0; bx + bin <= first.width; bx += bin) {
      std::fill(means.begin(), means.end(), glm::dvec3(0.0));
      glm::dvec3 v(0.0);
      int n = 0;
      for (int y = by; y < by + bin; ++y)
        for (int x = bx; x < bx + bin; ++x) {
          const size_t t = static_cast<size_t>(y) * first.width + x;
          if (which == BinTexels::Interior ? !interiorAt(first, x, y) : !validAt(first, t)) continue;
          ++n;
          for (size_t r = 0; r < R; ++r) means[r] += glm::dvec3(replicates[r][p].texels[t]);
          if (value) v += glm::dvec3(value->texels[t]);
        }
      if (2 * n < bin * bin) continue;  // compare.py keeps bins with at least half their texels
      glm::dvec3 mean(0.0);
      for (auto& m : means) mean += m /= double(n);
      mean /= double(R);
      glm::dvec3 s2(0.0);  // sample variance of the replicates' bin means
      for (const auto& m : means) s2 += (m - mean) * (m - mean);
      s2 /= double(R - 1);
      const glm::dvec3 v2 = value ? (v / double(n)) * (v / double(n)) : mean * mean;
      sums.noise2 += scale * scale * (s2.x + s2.y + s2.z) / double(R);
      sums.signal2 += v2.x + v2.y + v2.z;
      ++sums.bins;
    }
}

}  // namespace

nlohmann::json BinnedError::toJson() const {
  return {{"relative", relative}, {"noiseRms", noiseRms}, {"signalRms", signalRms}, {"bins", bins},
          {"replicates", replicates}};
}

BinnedError replicateError(const std::vector<std::vector<Lightmap>>& replicates, const std::vector<Lightmap>* value,
                           int bin, double scale, BinTexels texels) {
  checkReplicates(replicates);
  if (value && value->size() != replicates[0].size())
    throw Error(ErrorCode::InvalidData, "", "error estimate: the value map has a different page count");
  BinSums sums;
  for (size_t p = 0; p < replicates[0].size(); ++p) {
    const Lightmap* v = value ? &(*value)[p] : nullptr;
    if (v && v->texels.size() != replicates[0][p].size())
      throw Error(ErrorCode::InvalidData, "", "error estimate: the value page has a different size");
    scorePage(replicates, p, v, std::max(1, bin), scale, texels, sums);
  }
  BinnedError e;
  e.bins = sums.bins;
  e.replicates = static_cast<int>(replicates.size());
  if (sums.bins == 0) return e;
  const double channels = 3.0 * double(sums.bins);
  e.noiseRms = std::sqrt(sums.noise2 / channels);
  e.signalRms = std::sqrt(sums.signal2 / channels);
  e.relative = e.signalRms > 0.0 ? e.noiseRms / e.signalRms : 0.0;
  return e;
}

std::vector<Lightmap> replicateMean(const std::vector<std::vector<Lightmap>>& replicates) {
  checkReplicates(replicates);
  std::vector<Lightmap> mean = replicates[0];
  const float inv = 1.0f / static_cast<float>(replicates.size());
  for (size_t p = 0; p < mean.size(); ++p)
    for (size_t t = 0; t < mean[p].size(); ++t) {
      glm::vec3 s(0.0f);
      for (const auto& r : replicates) s += r[p].texels[t];
      mean[p].texels[t] = s * inv;
    }
  return mean;
}

std::vector<Lightmap> standardErrorPages(const std::vector<std::vector<Lightmap>>& replicates) {
  checkReplicates(replicates);
  std::vector<Lightmap> se = replicateMean(replicates);
  const double R = static_cast<double>(replicates.size());
  for (size_t p = 0; p < se.size(); ++p)
    for (size_t t = 0; t < se[p].size(); ++t) {
      if (!validAt(replicates[0][p], t)) {
        se[p].texels[t] = glm::vec3(0.0f);
        continue;
      }
      const glm::dvec3 mean(se[p].texels[t]);
      glm::dvec3 s2(0.0);
      for (const auto& r : replicates) {
        const glm::dvec3 d = glm::dvec3(r[p].texels[t]) - mean;
        s2 += d * d;
      }
      se[p].texels[t] = glm::vec3(glm::sqrt(s2 / ((R - 1.0) * R)));
    }
  return se;
}

}  // namespace irbake
