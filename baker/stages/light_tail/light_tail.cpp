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
  // Within three quarters of its cut the cut leaves nothing out.
  const Light& l = scene.lights[i];
  const glm::vec3 d = l.position - x;
  if (glm::dot(d, d) <= 0.5625f * l.cutoff * l.cutoff) return out;
  out.whole = punctualDirect(c.whole[i], x, n);
  if (out.whole.mapValue == glm::vec3(0.0f)) return out;
  out.value = out.whole.mapValue * (1.0f - l.cutoffWindow(out.whole.distance));
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
  const float tmax = shadowRayLength(lo.whole, eps);
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

// The walk's exact weights at (x, n): the walk weighs a light by its exact light before it hands that light over,
// mostly within its last kChoices weighings, so the recent ones are kept and a candidate's light is seldom
// evaluated twice.
struct WalkWeights {
  WalkWeights(const Scene& scene, const CutLights& c, const glm::vec3& x, const glm::vec3& n) : scene(scene), c(c), x(x), n(n) {
    std::fill(seen, seen + kKept, UINT32_MAX);
  }
  const Scene& scene;
  const CutLights& c;
  glm::vec3 x, n;
  static constexpr int kKept = 2 * LightTree::kChoices;
  uint32_t seen[kKept];
  LeftOut seenLo[kKept];
  int next = 0;
  double operator()(uint32_t i) {
    seen[next] = i, seenLo[next] = leftOutLight(scene, c, i, x, n);
    const double v = channelMean(seenLo[next].value);
    next = (next + 1) % kKept;
    return v;
  }
  LeftOut of(uint32_t i) const {  // the most recent first
    for (int k = 1; k <= kKept; ++k)
      if (const int at = (next - k + kKept) % kKept; seen[at] == i) return seenLo[at];
    return leftOutLight(scene, c, i, x, n);
  }
};

void resizeCandidates(Candidates& room, int m) {
  room.lo.resize(size_t(m)), room.weight.resize(size_t(m)), room.upTo.resize(size_t(m));
  std::fill(room.weight.begin(), room.weight.end(), 0.0);
}
void takeCandidate(Candidates& room, int j, const LeftOut& lo, const LightTree::Choice& choice) {
  room.lo[size_t(j)] = lo;
  const double value = channelMean(lo.value);
  if (value > 0.0 && choice.pmf > 0.0) room.weight[size_t(j)] = 1.0 / value, room.upTo[size_t(j)] = value / choice.pmf;
}
// Turns room.upTo into the running sum of the weights; returns their sum.
double sumCandidates(Candidates& room, int m) {
  double total = 0.0;
  for (int j = 0; j < m; ++j) total += room.weight[size_t(j)] > 0.0 ? room.upTo[size_t(j)] : 0.0, room.upTo[size_t(j)] = total;
  return total;
}

// m candidate lights at (x, n) drawn from the tree (stratified over the unit interval from `shift`), each weighed by
// its exact unshadowed left-out light over its pmf, no ray. room.upTo holds the running sum of those weights;
// returns their sum, m times the unbiased estimate of the unshadowed left-out light.
double drawCandidates(const BakeInputs& in, const CutLights& c, const glm::vec3& x, const glm::vec3& n, int m, double shift,
                      Candidates& room) {
  resizeCandidates(room, m);
  WalkWeights weigh{in.scene, c, x, n};
  c.tree.sampleStratified(x, n, shift, m, weigh,
                          [&](int j, const LightTree::Choice& choice) { takeCandidate(room, j, weigh.of(choice.light), choice); });
  return sumCandidates(room, m);
}

// drawCandidates for two independent sets of draws at the same (x, n), in one walk of the tree.
void drawCandidatePair(const BakeInputs& in, const CutLights& c, const glm::vec3& x, const glm::vec3& n, const int m[2],
                       const double shift[2], Candidates room[2], double total[2]) {
  resizeCandidates(room[0], m[0]), resizeCandidates(room[1], m[1]);
  WalkWeights weigh{in.scene, c, x, n};
  c.tree.sampleStratifiedPair(x, n, shift, m, weigh, [&](int s, int j, const LightTree::Choice& choice) {
    takeCandidate(room[s], j, weigh.of(choice.light), choice);
  });
  total[0] = sumCandidates(room[0], m[0]), total[1] = sumCandidates(room[1], m[1]);
}

// How a position's rays are drawn.
struct DrawShifts {
  double walk = 0.0;   // the tree walk's stratified shift
  double pick = 0.0;   // the resampling's systematic shift
  double round = 0.0;  // the ray count's random rounding
};

// drawAt's rays (below), once its m candidates are drawn into `room` (their weights summing to `total`).
glm::dvec3 traceCandidates(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, int rays, int m, double total,
                           double raysPerUnit, const DrawShifts& shifts, const Candidates& room, size_t& traced,
                           double& unshadowed) {
  glm::dvec3 sum(0.0);
  unshadowed = 0.0;
  if (!(total > 0.0)) return sum;
  unshadowed = total / double(m);
  double scale = 1.0;  // the ray count's share of the estimate: 1 unless Russian roulette kept one ray
  if (raysPerUnit > 0.0) {
    const double want = std::min(double(rays) * total / double(m) * raysPerUnit, 8.0 * rays);
    if (want < 1.0) {
      if (!(shifts.round < want)) return sum;
      rays = 1, scale = 1.0 / want;
    } else {
      rays = int(std::floor(want + shifts.round));
    }
  }
  int j = 0, last = -1;
  glm::dvec3 v(0.0);
  for (int k = 0; k < rays; ++k) {
    const double at = (k + shifts.pick) / rays * total;
    while (j + 1 < m && !(at < room.upTo[size_t(j)])) ++j;
    if (j != last) v = glm::dvec3(shadowed(in, x, n, room.lo[size_t(j)], traced)) * room.weight[size_t(j)], last = j;
    sum += v;
  }
  return sum * (scale * total / double(m)) / double(rays);
}

// The left-out light at (x, n), and in `unshadowed` the candidates' estimate of it before its shadows (0 without
// candidates). Without candidates: `rays` shadow rays, each to its own light drawn from the tree
// (stratified over its unit interval, its order spatial), weighing value / pmf. With m candidates (drawCandidates):
// the rays go to lights resampled among them in proportion to their weights (systematic: a light picked twice is
// traced once), each weighing its shadowed light over its unshadowed light times the weights' mean. Resampled
// importance sampling (Talbot et al. 2005): unbiased, the unshadowed light is estimated from m draws for the price
// of tree walks and the rays spend themselves on the visibility only. With raysPerUnit > 0 the ray count follows
// that unshadowed estimate (rays × estimate × raysPerUnit, at most 8 × rays, randomly rounded; below one ray, one
// ray by Russian roulette): the visibility's noise in absolute terms grows with the light it gates, so the rays go
// where the tail is (Neyman's allocation). The estimate stays unbiased whatever the count, which depends on the
// candidates only.
glm::dvec3 drawAt(const BakeInputs& in, const CutLights& c, const glm::vec3& x, const glm::vec3& n, int rays,
                  int candidates, double raysPerUnit, const DrawShifts& shifts, Candidates& room, size_t& traced,
                  double& unshadowed) {
  glm::dvec3 sum(0.0);
  unshadowed = 0.0;
  if (candidates <= 0) {
    auto exact = [&](uint32_t i) { return double(channelMean(leftOutLight(in.scene, c, i, x, n).value)); };
    for (int k = 0; k < rays; ++k) {
      const LightTree::Choice choice = c.tree.sample(x, n, (k + shifts.walk) / rays, exact);
      if (choice.light == UINT32_MAX || !(choice.pmf > 0.0)) continue;
      const LeftOut lo = leftOutLight(in.scene, c, choice.light, x, n);
      if (lo.value != glm::vec3(0.0f)) sum += glm::dvec3(shadowed(in, x, n, lo, traced)) / choice.pmf;
    }
    return sum / double(rays);
  }
  const int m = std::max(candidates, rays);
  return traceCandidates(in, x, n, rays, m, drawCandidates(in, c, x, n, m, shifts.walk, room), raysPerUnit, shifts, room,
                         traced, unshadowed);
}

// A texel sample's position on its surface (inset into its triangle), or false where it has none.
bool texelPosition(const BakeInputs& in, const TexelSamples& ts, size_t s, glm::vec3& x) {
  if (!(ts.positionWeight[s].w > 0.0f)) return false;
  x = glm::vec3(ts.positionWeight[s]);
  if (s < ts.primitive.size() && ts.primitive[s] < in.scene.primitives.size() &&
      ts.triangle[s] < in.scene.primitives[ts.primitive[s]].triangleCount())
    x = in.rayTracer.insetPoint(ts.primitive[s], ts.triangle[s], x);
  return true;
}

// One texel's draws: `count` rays of the texel's samples from slot `first` on, one slot after another; a slot's
// rays share its candidates (`candidates` per `count` rays, in proportion). The weighted mean over the slots.
struct TexelDraws {
  glm::dvec3 mean{0.0};
  double unshadowed = 0.0;
  bool any = false;
};
TexelDraws drawTexel(const BakeInputs& in, const CutLights& c, const TexelSamples& ts, size_t t, int first, int count,
                     int candidates, double raysPerUnit, Rng& rng, Candidates& room, size_t& traced) {
  const size_t layer = ts.layerSize();
  const int layers = ts.supersample * ts.supersample;
  glm::dvec3 sum(0.0);
  double weight = 0.0, unshadowed = 0.0;
  for (int k = 0; k < std::min(count, layers); ++k) {
    const size_t s = static_cast<size_t>((first + k) % layers) * layer + t;
    const int rays = count / layers + (k < count % layers ? 1 : 0);
    const float w = ts.positionWeight[s].w * float(rays);
    glm::vec3 x;
    if (!texelPosition(in, ts, s, x)) continue;
    const int m = candidates > 0 ? (candidates * rays + count - 1) / count : 0;
    const DrawShifts shifts{rng.uniform(), rng.uniform(), rng.uniform()};
    double u = 0.0;
    sum += double(w) * drawAt(in, c, x, glm::vec3(ts.normal[s]), rays, m, raysPerUnit, shifts, room, traced, u);
    unshadowed += double(w) * u;
    weight += double(w);
  }
  TexelDraws d;
  if (weight > 0.0) d.mean = sum / weight, d.unshadowed = unshadowed / weight, d.any = true;
  return d;
}

// drawTexel for both halves of a texel of one sample slot (no supersampling), each half `count[h]` rays and
// `candidates[h]` candidates: the halves draw at the same point, so their candidates come from one walk of the
// tree (drawCandidatePair); each half gets what drawTexel gives it.
void drawTexelPair(const BakeInputs& in, const CutLights& c, const TexelSamples& ts, size_t t, const int count[2],
                   const int candidates[2], double raysPerUnit, Rng& rng, Candidates room[2], size_t& traced,
                   TexelDraws out[2]) {
  glm::vec3 x;
  if (!texelPosition(in, ts, t, x)) return;
  const glm::vec3 n(ts.normal[t]);
  DrawShifts shifts[2];
  for (DrawShifts& sh : shifts) sh = {rng.uniform(), rng.uniform(), rng.uniform()};
  const int m[2] = {std::max(candidates[0], count[0]), std::max(candidates[1], count[1])};
  const double walk[2] = {shifts[0].walk, shifts[1].walk};
  double total[2];
  drawCandidatePair(in, c, x, n, m, walk, room, total);
  for (int h = 0; h < 2; ++h) {
    const double w = double(ts.positionWeight[t].w * float(count[h]));
    double u = 0.0;
    const glm::dvec3 sum = w * traceCandidates(in, x, n, count[h], m[h], total[h], raysPerUnit, shifts[h], room[h], traced, u);
    if (w > 0.0) out[h].mean = sum / w, out[h].unshadowed = w * u / w, out[h].any = true;
  }
}

// A texel's candidates: `candidates` times its expected share of the page's mean tail, at least one per ray and
// at most eight times the mean.
int candidatesFor(int candidates, double share, int samples) {
  const double want = double(candidates) * share;
  return int(std::clamp(std::floor(want + 0.5), double(samples), 8.0 * candidates));
}

// 1 / the page's mean unshadowed left-out light, from m candidates at up to about `pilots` valid texels spread
// over the page (tree walks, no ray): the unit drawAt's ray allocation scales by. 0 where the tail is nothing.
double pageRaysPerUnit(const BakeInputs& in, const CutLights& c, const TexelSamples& ts, int m, size_t pilots, uint64_t seed) {
  const size_t texels = std::min(ts.valid.size(), ts.layerSize());
  const size_t valid = size_t(std::count_if(ts.valid.begin(), ts.valid.begin() + std::ptrdiff_t(texels), [](uint8_t v) { return v != 0; }));
  if (valid == 0 || m <= 0) return 0.0;
  const size_t step = std::max<size_t>(1, valid / pilots);
  double sum = 0.0;
  size_t count = 0, seen = 0;
  Candidates room;
  Rng rng(hashSeed(seed, 0x9170));
  for (size_t t = 0; t < texels; ++t) {
    if (!ts.valid[t] || seen++ % step != 0) continue;
    glm::vec3 x;
    ++count;
    if (texelPosition(in, ts, t, x)) sum += drawCandidates(in, c, x, glm::vec3(ts.normal[t]), m, rng.uniform(), room) / m;
  }
  return sum > 0.0 ? double(count) / sum : 0.0;
}

}  // namespace

LightTailPages traceLightTail(const BakeInputs& in, const std::vector<Lightmap>& maps, const LightTailOptions& options,
                              const std::vector<uint8_t>& skip) {
  LightTailPages out;
  LightTailStats& stats = out.stats;
  Stopwatch watch;
  const CutLights c = cutLights(in.scene, in.eval, skip);
  stats.lights = c.tree.size();
  if (c.tree.empty() || options.samples <= 0) return out;
  // Two independent halves of the draws, each stratified with its own shift: their difference tells the noise of
  // their mean, filtered or not. One draw cannot be split: it is its own half and reports no noise.
  const int halfA = std::max(1, options.samples / 2), halfB = options.samples - halfA;
  // Each half its own candidates, in proportion to its rays.
  const int candidates = options.candidates > 0 ? std::max(options.candidates, options.samples) : 0;
  const int candidatesA = candidates > 0 ? std::max(halfA, candidates * halfA / options.samples) : 0;
  std::atomic<size_t> rays{0};
  for (size_t p = 0; p < maps.size() && p < in.texels.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    const Lightmap& map = maps[p];
    const size_t layer = ts.layerSize();
    std::vector<glm::vec3> a(layer, glm::vec3(0.0f)), b(layer, glm::vec3(0.0f)), u(layer, glm::vec3(0.0f));
    std::vector<uint8_t> valid(layer, 0);
    const double perUnit = options.allocate && candidates > 0
                               ? pageRaysPerUnit(in, c, ts, std::max(candidatesA, 4), 4096, hashSeed(options.seed, p)) : 0.0;
    // Texels in runs along a row, each run in order: a texel draws candidates in proportion to the unshadowed
    // tail of the texels just before it in its run (a decaying mean; the page's mean at a run's start), the
    // page's mean `candidates`, so the walks go where the tail is (Neyman's allocation, as the rays). Those
    // texels' draws are independent of its own: its estimate stays unbiased. Runs are fixed, so is the bake.
    constexpr size_t kRun = 256;
    const double pageMean = perUnit > 0.0 ? 1.0 / perUnit : 0.0;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, (layer + kRun - 1) / kRun), [&](const tbb::blocked_range<size_t>& runs) {
      size_t traced = 0;
      Candidates rooms[2];
      for (size_t run = runs.begin(); run < runs.end(); ++run) {
        double recent = pageMean;
        for (size_t t = run * kRun; t < std::min(layer, (run + 1) * kRun); ++t) {
          if (ts.width > 0 && t % size_t(ts.width) == 0) recent = pageMean;  // a new row: the last texel is far
          if (t >= ts.valid.size() || !ts.valid[t]) continue;
          valid[t] = 1;  // the page's own validity, so the bake's filter plan serves it
          Rng rng(hashSeed(options.seed, p, t));
          const int m = pageMean > 0.0 && options.allocateCandidates ? candidatesFor(candidates, recent / pageMean, options.samples) : candidates;
          const int mA = m > 0 ? std::max(halfA, m * halfA / options.samples) : 0;
          const int mB = m > 0 ? std::max(halfB, m - mA) : 0;
          TexelDraws da, db;
          if (ts.supersample == 1 && halfB > 0 && m > 0) {
            const int count[2] = {halfA, halfB}, perHalf[2] = {mA, mB};
            TexelDraws pair[2];
            drawTexelPair(in, c, ts, t, count, perHalf, perUnit, rng, rooms, traced, pair);
            da = pair[0], db = pair[1];
          } else {
            da = drawTexel(in, c, ts, t, 0, halfA, mA, perUnit, rng, rooms[0], traced);
            db = halfB > 0 ? drawTexel(in, c, ts, t, halfA, halfB, mB, perUnit, rng, rooms[0], traced) : da;
          }
          if (da.any && db.any) {
            a[t] = glm::vec3(da.mean), b[t] = glm::vec3(db.mean);
            const double unshadowed = 0.5 * (da.unshadowed + db.unshadowed);
            u[t] = glm::vec3(float(unshadowed));
            recent = 0.5 * (recent + unshadowed);
          }
        }
      }
      rays += traced;
    });
    if (options.filterRadius > 0) {
      TexelFilterOptions fo;
      fo.radius = options.filterRadius;
      auto filtered = filterOnSurface(in.surfaceFilters, ts, std::vector<const std::vector<glm::vec3>*>{&a, &b, &u}, valid, fo);
      a = std::move(filtered[0]), b = std::move(filtered[1]), u = std::move(filtered[2]);
    }
    std::vector<glm::vec3>& added = out.added.emplace_back(layer, glm::vec3(0.0f));
    std::vector<float>& unshadowed = out.unshadowed.emplace_back(layer, 0.0f);
    for (size_t t = 0; t < layer; ++t) {
      if (!valid[t] || t >= map.valid.size() || !map.valid[t]) continue;
      const glm::vec3 mean = 0.5f * (a[t] + b[t]);
      const double half = halfB > 0 ? 0.5 * channelMean(a[t] - b[t]) : 0.0;
      added[t] = mean, unshadowed[t] = u[t].x;
      ++stats.texels, stats.variance += half * half, stats.added += channelMean(mean);
    }
  }
  stats.rays = rays.load();
  stats.seconds = watch.seconds();
  return out;
}

void addLightTailPages(const LightTailPages& tail, std::vector<Lightmap>& maps) {
  for (size_t p = 0; p < maps.size() && p < tail.added.size(); ++p)
    for (size_t t = 0; t < maps[p].size() && t < tail.added[p].size(); ++t) maps[p].texels[t] += tail.added[p][t];
}

LightTailStats addLightTail(const BakeInputs& in, std::vector<Lightmap>& maps, const LightTailOptions& options,
                            const std::vector<uint8_t>& skip) {
  const LightTailPages tail = traceLightTail(in, maps, options, skip);
  addLightTailPages(tail, maps);
  return tail.stats;
}

}  // namespace irbake
