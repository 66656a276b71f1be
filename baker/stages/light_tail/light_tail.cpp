#include "stages/light_tail/light_tail.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "common/progress.h"
#include "lights/light_reach.h"
#include "lights/light_tree.h"
#include "sampling/sampling.h"
#include "texels/surface_filter_cache.h"
#include "transport/geometry_term.h"

namespace irbake {

namespace {

// The cut lights as they would be without the cut, by scene index (empty where not cut or skipped).
struct CutLights {
  std::vector<Light> whole;
  std::vector<uint8_t> cut;
  LightTree tree;
};

CutLights cutLights(const Scene& scene, const VplEvalOptions& eval, const std::vector<uint8_t>& skip) {
  CutLights c;
  c.whole = scene.lights;
  c.cut.assign(scene.lights.size(), 0);
  std::vector<LightTreeEntry> entries;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (!(l.cutoff > 0.0f) || !eval.directIncludes(i) || (i < skip.size() && skip[i])) continue;
    c.whole[i].cutoff = 0.0f;
    c.cut[i] = 1;
    // Light::cutoffWindow is 1 up to three quarters of the cutoff (nothing is left out nearer) and falls to 0 at the
    // cutoff by a smoothstep: what it leaves out rises by that smoothstep.
    entries.push_back({static_cast<uint32_t>(i), l.position,
                       static_cast<float>(channelMean(l.color)) * peakIntensity(l), 0.75f * l.cutoff, l.cutoff});
  }
  c.tree = LightTree(std::move(entries));
  return c;
}

// What the cut took from light i at (x, n), before its shadow: its light whole less its light faded.
struct LeftOut {
  glm::vec3 value{0.0f};
  PunctualContribution whole;
};
LeftOut leftOutLight(const Scene& scene, const CutLights& c, uint32_t i, const glm::vec3& x, const glm::vec3& n) {
  LeftOut out;
  out.whole = punctualDirect(c.whole[i], x, n);
  if (out.whole.mapValue == glm::vec3(0.0f)) return out;
  out.value = out.whole.mapValue * (1.0f - scene.lights[i].cutoffWindow(out.whole.distance));
  return out;
}

}  // namespace

nlohmann::json LightTailStats::toJson() const {
  return {{"lights", lights}, {"texels", texels}, {"rays", rays}, {"addedMean", texels ? added / double(texels) : 0.0},
          {"noiseRms", texels ? std::sqrt(variance / double(texels)) : 0.0}};
}

namespace {

// The left-out light that reaches x along lo's direction: lo's value times the transmittance of one shadow ray,
// nothing where the ray is blocked.
glm::vec3 shadowed(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, const LeftOut& lo, size_t& traced) {
  const float eps = in.rayTracer.epsilon();
  const glm::vec3 origin = x + n * eps;
  const float tmax = std::isinf(lo.whole.distance) ? 1e30f : lo.whole.distance - eps;
  ++traced;
  if (!(tmax > 0.0f)) return lo.value;
  if (in.rayTracer.occluded(origin, lo.whole.toLight, 0.0f, tmax)) return glm::vec3(0.0f);
  return lo.value * in.rayTracer.transmittance(origin, lo.whole.toLight, 0.0f, tmax);
}

// A thread's room for one position's candidates.
struct Candidates {
  std::vector<LeftOut> lo;
  std::vector<double> weight, upTo;  // 1 / its unshadowed value; running sum of unshadowed value / pmf
};

// The left-out light at (x, n), `rays` shadow rays. Without candidates each ray goes to its own light drawn from the
// tree (stratified over its unit interval, its order spatial) and weighs value / pmf. With m candidates (m ≥ rays):
// m lights drawn alike, each weighed by its unshadowed left-out light over its pmf (exact, no ray); the rays go to
// lights resampled among them in proportion to those weights (systematic: a light picked twice is traced once), each
// weighing its shadowed light over its unshadowed light times the weights' mean. Resampled importance sampling
// (Talbot et al. 2005): unbiased, the unshadowed light is estimated from m draws for the price of tree walks and
// the rays spend themselves on the visibility only.
glm::dvec3 drawAt(const BakeInputs& in, const CutLights& c, const glm::vec3& x, const glm::vec3& n, int rays,
                  int candidates, Rng& rng, Candidates& room, size_t& traced) {
  auto exact = [&](uint32_t i) { return double(channelMean(leftOutLight(in.scene, c, i, x, n).value)); };
  glm::dvec3 sum(0.0);
  if (candidates <= 0) {
    const double shift = rng.uniform();
    for (int k = 0; k < rays; ++k) {
      const LightTree::Choice choice = c.tree.sample(x, n, (k + shift) / rays, exact);
      if (choice.light == UINT32_MAX || !(choice.pmf > 0.0)) continue;
      const LeftOut lo = leftOutLight(in.scene, c, choice.light, x, n);
      if (lo.value != glm::vec3(0.0f)) sum += glm::dvec3(shadowed(in, x, n, lo, traced)) / choice.pmf;
    }
    return sum / double(rays);
  }
  const int m = std::max(candidates, rays);
  room.lo.resize(size_t(m)), room.weight.resize(size_t(m)), room.upTo.resize(size_t(m));
  // The walk weighs a leaf by its exact light just before it hands that leaf over: the last two lights weighed are
  // kept, so a candidate's light is not evaluated twice.
  uint32_t seen[2] = {UINT32_MAX, UINT32_MAX};
  LeftOut seenLo[2];
  int next = 0;
  auto weigh = [&](uint32_t i) {
    seen[next] = i, seenLo[next] = leftOutLight(in.scene, c, i, x, n);
    const double v = channelMean(seenLo[next].value);
    next ^= 1;
    return v;
  };
  std::fill(room.weight.begin(), room.weight.end(), 0.0);
  c.tree.sampleStratified(x, n, rng.uniform(), m, weigh, [&](int j, const LightTree::Choice& choice) {
    LeftOut& lo = room.lo[size_t(j)];
    lo = seen[0] == choice.light ? seenLo[0] : seen[1] == choice.light ? seenLo[1]
                                                                        : leftOutLight(in.scene, c, choice.light, x, n);
    const double value = channelMean(lo.value);
    if (value > 0.0 && choice.pmf > 0.0) room.weight[size_t(j)] = 1.0 / value, room.upTo[size_t(j)] = value / choice.pmf;
  });
  double total = 0.0;
  for (int j = 0; j < m; ++j) total += room.weight[size_t(j)] > 0.0 ? room.upTo[size_t(j)] : 0.0, room.upTo[size_t(j)] = total;
  if (!(total > 0.0)) return sum;
  const double pick = rng.uniform();
  int j = 0, last = -1;
  glm::dvec3 v(0.0);
  for (int k = 0; k < rays; ++k) {
    const double at = (k + pick) / rays * total;
    while (j + 1 < m && !(at < room.upTo[size_t(j)])) ++j;
    if (j != last) v = glm::dvec3(shadowed(in, x, n, room.lo[size_t(j)], traced)) * room.weight[size_t(j)], last = j;
    sum += v;
  }
  return sum * (total / double(m)) / double(rays);
}

// One texel's draws: `count` rays of the texel's samples from slot `first` on, one slot after another; a slot's
// rays share its candidates (`candidates` per `count` rays, in proportion). The weighted mean over the slots.
struct TexelDraws {
  glm::dvec3 mean{0.0};
  bool any = false;
};
TexelDraws drawTexel(const BakeInputs& in, const CutLights& c, const TexelSamples& ts, size_t t, int first, int count,
                     int candidates, Rng& rng, Candidates& room, size_t& traced) {
  const size_t layer = ts.layerSize();
  const int layers = ts.supersample * ts.supersample;
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int k = 0; k < std::min(count, layers); ++k) {
    const size_t s = static_cast<size_t>((first + k) % layers) * layer + t;
    const int rays = count / layers + (k < count % layers ? 1 : 0);
    const float w = ts.positionWeight[s].w * float(rays);
    if (!(w > 0.0f)) continue;
    glm::vec3 x(ts.positionWeight[s]);
    if (s < ts.primitive.size() && ts.primitive[s] < in.scene.primitives.size() &&
        ts.triangle[s] < in.scene.primitives[ts.primitive[s]].triangleCount())
      x = in.rayTracer.insetPoint(ts.primitive[s], ts.triangle[s], x);
    const int m = candidates > 0 ? (candidates * rays + count - 1) / count : 0;
    sum += double(w) * drawAt(in, c, x, glm::vec3(ts.normal[s]), rays, m, rng, room, traced);
    weight += double(w);
  }
  TexelDraws d;
  if (weight > 0.0) d.mean = sum / weight, d.any = true;
  return d;
}

}  // namespace

LightTailStats addLightTail(const BakeInputs& in, std::vector<Lightmap>& maps, const LightTailOptions& options,
                            const std::vector<uint8_t>& skip) {
  LightTailStats stats;
  Stopwatch watch;
  const CutLights c = cutLights(in.scene, in.eval, skip);
  stats.lights = c.tree.size();
  if (c.tree.empty() || options.samples <= 0) return stats;
  // Two independent halves of the draws, each stratified with its own shift: their difference tells the noise of
  // their mean, filtered or not. One draw cannot be split: it is its own half and reports no noise.
  const int halfA = std::max(1, options.samples / 2), halfB = options.samples - halfA;
  // Each half its own candidates, in proportion to its rays.
  const int candidates = options.candidates > 0 ? std::max(options.candidates, options.samples) : 0;
  const int candidatesA = candidates > 0 ? std::max(halfA, candidates * halfA / options.samples) : 0;
  const int candidatesB = candidates > 0 ? std::max(halfB, candidates - candidatesA) : 0;
  std::atomic<size_t> rays{0};
  for (size_t p = 0; p < maps.size() && p < in.texels.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    Lightmap& map = maps[p];
    const size_t layer = ts.layerSize();
    std::vector<glm::vec3> a(layer, glm::vec3(0.0f)), b(layer, glm::vec3(0.0f));
    std::vector<uint8_t> valid(layer, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, layer, 256), [&](const tbb::blocked_range<size_t>& range) {
      size_t traced = 0;
      Candidates room;
      for (size_t t = range.begin(); t < range.end(); ++t) {
        if (t >= ts.valid.size() || !ts.valid[t]) continue;
        valid[t] = 1;  // the page's own validity, so the bake's filter plan serves it
        Rng rng(hashSeed(options.seed, p, t));
        const TexelDraws da = drawTexel(in, c, ts, t, 0, halfA, candidatesA, rng, room, traced);
        const TexelDraws db = halfB > 0 ? drawTexel(in, c, ts, t, halfA, halfB, candidatesB, rng, room, traced) : da;
        if (da.any && db.any) a[t] = glm::vec3(da.mean), b[t] = glm::vec3(db.mean);
      }
      rays += traced;
    });
    if (options.filterRadius > 0) {
      TexelFilterOptions fo;
      fo.radius = options.filterRadius;
      auto filtered = filterOnSurface(in.surfaceFilters, ts, std::vector<const std::vector<glm::vec3>*>{&a, &b}, valid, fo);
      a = std::move(filtered[0]), b = std::move(filtered[1]);
    }
    for (size_t t = 0; t < layer; ++t) {
      if (!valid[t] || t >= map.valid.size() || !map.valid[t]) continue;
      const glm::vec3 mean = 0.5f * (a[t] + b[t]);
      const double half = halfB > 0 ? 0.5 * channelMean(a[t] - b[t]) : 0.0;
      map.texels[t] += mean;
      ++stats.texels, stats.variance += half * half, stats.added += channelMean(mean);
    }
  }
  stats.rays = rays.load();
  stats.seconds = watch.seconds();
  return stats;
}

}  // namespace irbake
