// Systematic resampling of a walk's VPLs per bounce (docs/units.md, "Walking more paths than are evaluated").
#include "vpl/resample.h"

#include <algorithm>
#include <numeric>

#include "sampling/sampling.h"

namespace irbake {

namespace {

// 10 bits of x spread to every third bit.
uint32_t spreadBits(uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

// Morton codes of VPLs [first, last) over their own bounding box: neighbours on the curve are neighbours in
// space, so an evenly spaced pick along it is spread over the bounce's surfaces.
std::vector<uint32_t> mortonCodes(const std::vector<Vpl>& vpls, size_t first, size_t last) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (size_t v = first; v < last; ++v) lo = glm::min(lo, vpls[v].position), hi = glm::max(hi, vpls[v].position);
  const glm::vec3 scale = 1023.0f / glm::max(hi - lo, glm::vec3(1e-30f));
  std::vector<uint32_t> codes(last - first);
  for (size_t v = first; v < last; ++v) {
    const glm::uvec3 q(glm::clamp((vpls[v].position - lo) * scale, glm::vec3(0.0f), glm::vec3(1023.0f)));
    codes[v - first] = spreadBits(q.x) << 2 | spreadBits(q.y) << 1 | spreadBits(q.z);
  }
  return codes;
}

double weightOf(const Vpl& v) {
  return std::max(0.0, double(v.power.x)) + std::max(0.0, double(v.power.y)) + std::max(0.0, double(v.power.z));
}

// How many times each VPL of [first, last) is picked when `keep` picks fall at (k + u) W / keep along the
// Morton order (k = 0…keep−1); total = W, the VPLs' Σ weightOf.
std::vector<uint32_t> systematicPicks(const std::vector<Vpl>& vpls, size_t first, size_t last, size_t keep, double u,
                                      double total) {
  const std::vector<uint32_t> codes = mortonCodes(vpls, first, last);
  std::vector<size_t> order(last - first);
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return codes[a] < codes[b]; });
  std::vector<uint32_t> picks(last - first, 0);
  if (!(total > 0.0)) return picks;
  const double step = total / static_cast<double>(keep);
  double next = u * step, cumulative = 0.0;
  size_t taken = 0;
  for (size_t o = 0; o < order.size() && taken < keep; ++o) {
    cumulative += weightOf(vpls[first + order[o]]);
    while (taken < keep && next < cumulative) {
      ++picks[order[o]];
      ++taken;
      next = (static_cast<double>(taken) + u) * step;
    }
  }
  // Rounding at the curve's end: the last picks go to its last VPL of positive weight.
  for (size_t o = order.size(); taken < keep && o-- > 0;)
    if (weightOf(vpls[first + order[o]]) > 0.0) picks[order[o]] += static_cast<uint32_t>(keep - taken), taken = keep;
  return picks;
}

}  // namespace

void resampleVpls(VplSet& set, const std::vector<size_t>& keep, uint64_t seed) {
  set.walked = set.vpls.size();
  if (keep.empty()) return;
  std::vector<Vpl> kept;
  size_t first = 0;
  for (size_t j = 0; j < set.countPerBounce.size(); ++j) {
    const size_t last = first + set.countPerBounce[j], count = last - first;
    const size_t k = std::max<size_t>(1, keep[std::min(j, keep.size() - 1)]);
    if (count <= k) {
      kept.insert(kept.end(), set.vpls.begin() + first, set.vpls.begin() + last);
    } else {
      double total = 0.0;
      for (size_t v = first; v < last; ++v) total += weightOf(set.vpls[v]);
      Rng rng(hashSeed(seed, 0x726573616d706c65ull, j));  // "resample"
      const std::vector<uint32_t> picks = systematicPicks(set.vpls, first, last, k, rng.uniform(), total);
      for (size_t v = first; v < last; ++v) {
        if (picks[v - first] == 0) continue;
        Vpl vpl = set.vpls[v];
        const double scale = picks[v - first] * total / (static_cast<double>(k) * weightOf(vpl));
        vpl.power = glm::vec3(glm::dvec3(vpl.power) * scale);
        kept.push_back(vpl);
      }
    }
    first = last;
  }
  set.vpls = std::move(kept);
  std::fill(set.countPerBounce.begin(), set.countPerBounce.end(), size_t(0));
  std::fill(set.powerPerBounce.begin(), set.powerPerBounce.end(), glm::dvec3(0.0));
  for (const Vpl& v : set.vpls) {
    ++set.countPerBounce[v.bounce];
    set.powerPerBounce[v.bounce] += glm::dvec3(v.power);
  }
}

}  // namespace irbake
