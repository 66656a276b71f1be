#include "stages/compensation/clamp_compensation.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "lightmap/lightmap_read.h"
#include "common/error.h"
#include "common/log.h"
#include "common/maths.h"
#include "common/progress.h"
#include "texels/surface_filter_cache.h"
#include "transport/geometry_term.h"
#include "sampling/sampling.h"

namespace irbake {
namespace {


// A hit inside the clamp radius, kept for the sweeps: residual(slot) += Le + albedo ⊙ M(page, texel).
// Le and albedo are already multiplied by w / (rays of the slot). 24 bytes: the kept hits are the
// compensation's memory (a few per texel), and few of them see an emitter, so Le lives apart
// (EmittedHit) instead of 12 zero bytes in every hit.
struct KeptHit {
  uint16_t slotInTile = 0;   // slot − Tile::begin (< kTileSlots)
  int16_t map = -1;          // index into maps (< kMaxPages); -1: the hit surface has no light map (Le only)
  glm::vec2 texel{0.0f};     // continuous texel coordinates (u·W − ½, v·H − ½)
  glm::vec3 albedo{0.0f};
};

// Le of a kept hit whose emission is not zero.
struct EmittedHit {
  uint32_t hit = 0;          // index into its tile's hits
  glm::vec3 emitted{0.0f};
};

constexpr size_t kTileSlots = 256;  // slots per tile (KeptHit::slotInTile is 16 bits)
constexpr size_t kMaxPages = 32767;  // KeptHit::map is 16 bits

// Kept hits of one tile of slots (a tile owns its slots, so tiles are traced and swept in parallel).
struct Tile {
  size_t page = 0, begin = 0, end = 0;
  std::vector<KeptHit> hits;
  std::vector<EmittedHit> emitted;  // in hit order; hits not listed have Le = 0
  std::vector<glm::vec3> tangent;   // directional only, per hit: (ω − (ω·n)n) / cosθ
};

// Ray counts of the two rounds, after the budget.
struct RayPlan {
  int baseRays = 0;    // first round, per active sample
  int extraRays = 0;   // second round, per refined sample (before the budget of that round)
  int refineHits = 0;  // first-round hits inside the clamp radius that make a sample a refinement candidate
};

RayPlan planRays(const std::vector<TexelSamples>& texels, const ClampCompensationOptions& options) {
  size_t activeSamples = 0;
  for (const TexelSamples& ts : texels)
    for (size_t s = 0; s < ts.slotCount(); ++s) activeSamples += ts.positionWeight[s].w > 0.0f;
  RayPlan plan;
  plan.baseRays = std::max(1, options.rays);
  if (options.rayBudget > 0 && activeSamples > 0)
    plan.baseRays = static_cast<int>(std::clamp<size_t>(options.rayBudget / activeSamples,
                                                        static_cast<size_t>(std::clamp(options.minRays, 1, plan.baseRays)),
                                                        static_cast<size_t>(plan.baseRays)));
  const double rayScale = static_cast<double>(plan.baseRays) / std::max(1, options.rays);
  plan.extraRays = static_cast<int>(std::lround(std::max(0, options.refineRays) * rayScale));
  plan.refineHits = static_cast<int>(std::ceil(options.refineFraction * plan.baseRays));
  return plan;
}

}  // namespace

struct ClampGather::Impl {
  const BakeInputs& in;
  ClampCompensationOptions options;
  bool enabled = false;
  float bound = 0.0f;              // the clamp bound B (1/m²)
  std::vector<int32_t> mapOfPage;  // light-map page number → index of its texel page (= its map)
  std::vector<Tile> tiles;         // kept hits, by tile of slots
  std::vector<std::vector<uint16_t>> raysOf;  // rays traced per slot
  std::vector<int> radii;          // residual filter radius per page
  // The bake's surface filters (in.surfaceFilters), or this gather's own where the inputs have none.
  mutable std::unique_ptr<SurfaceFilterCache> ownFilters;
  SurfaceFilterCache* filters() const {
    if (in.surfaceFilters) return in.surfaceFilters;
    if (!ownFilters) ownFilters = std::make_unique<SurfaceFilterCache>(in.texels);
    return ownFilters.get();
  }
  int filterRadius = 0, baseRays = 0;
  size_t rays = 0, refined = 0;
  double traceSeconds = 0.0;
  Impl(const BakeInputs& i, const ClampCompensationOptions& o) : in(i), options(o) {}

  void makeTiles();
  void chooseFilters();
  int traceSlot(size_t page, size_t slot, int count, uint64_t round, Tile& out) const;
  std::vector<std::vector<uint16_t>> traceFirstRound();
  void traceRefinement(const std::vector<std::vector<uint16_t>>& firstHits, const RayPlan& plan);
  void divideByRaysOfSlot();
};

// Per page, per tile of slots, one list of kept hits (tiles own their slots, so they trace in parallel).
void ClampGather::Impl::makeTiles() {
  constexpr size_t kTile = kTileSlots;
  for (size_t p = 0; p < in.texels.size(); ++p)
    for (size_t b = 0; b < in.texels[p].slotCount(); b += kTile)
      tiles.push_back({p, b, std::min(in.texels[p].slotCount(), b + kTile), {}, {}, {}});
}

// Auto filter: only where the window stays well inside the clamp radius r_c = 1/√B (the residual varies
// on the scale of the distance to the nearest edge, so a window of r_c/20 keeps edges sharp) and the
// per-sample ray count is low. At most 4 texels (9×9): on a level's millions of texels the ray budget
// leaves few rays per sample, and a narrower window let their noise show in close-ups. Radius and texel
// geometry per page, once for all sweeps.
void ClampGather::Impl::chooseFilters() {
  const float clampRadius = 1.0f / std::sqrt(bound);
  radii.assign(in.texels.size(), 0);
  for (size_t p = 0; p < in.texels.size(); ++p) {
    const std::optional<int>& fixedRadius = options.filterRadius;
    if (fixedRadius ? *fixedRadius <= 0 : baseRays >= 32) continue;
    const float h = filters()->spacing(in.texels[p]);
    radii[p] = fixedRadius ? *fixedRadius
               : h > 0.0f ? static_cast<int>(std::min(4.0f, std::floor(0.05f * clampRadius / h)))
                          : 0;
    filterRadius = std::max(filterRadius, radii[p]);
  }
}

// Traces `count` cosine rays from slot s of page p (a rotated Fibonacci lattice: well stratified over
// the hemisphere for any count) and appends the hits inside the clamp radius, not yet divided by the
// slot's ray count. Returns how many it kept.
int ClampGather::Impl::traceSlot(size_t p, size_t s, int count, uint64_t round, Tile& out) const {
  const Scene& scene = in.scene;
  const RayTracer& rt = in.rayTracer;
  const TexelSamples& ts = in.texels[p];
  glm::vec3 n(ts.normal[s]);
  glm::vec3 x(ts.positionWeight[s]);
  if (s < ts.primitive.size() && ts.primitive[s] < scene.primitives.size())
    x = rt.insetPoint(ts.primitive[s], ts.triangle[s], x);
  const glm::vec3 origin = x + n * rt.epsilon();
  Rng rng(hashSeed(options.seed, (static_cast<uint64_t>(ts.page) << 8) | round, s));
  const double r1 = rng.uniform(), r2 = rng.uniform();
  int keptCount = 0;
  CosineLattice lattice(n, count, r1, r2);
  for (int i = 0; i < count; ++i) {
    const glm::vec3 dir = lattice.next();
    RayHit hit = rt.intersect(origin, dir, 0.0f, 1e30f);
    if (!hit.hit || hit.backFace) continue;
    // The same G as the clamp the VPL sum applied (0 when either surface faces away, so never kept).
    const float g = vplGeometryTerm(x, n, hit.position, hit.geometricNormal);
    if (g <= bound) continue;
    KeptHit kept;
    kept.slotInTile = static_cast<uint16_t>(s - out.begin);
    float w = 1.0f - bound / g;
    const Primitive& prim = scene.primitives[hit.primitive];
    const glm::vec3 emitted = w * scene.emissionAt(prim, hit.triangle, hit.barycentric);
    if (emitted != glm::vec3(0.0f)) out.emitted.push_back({static_cast<uint32_t>(out.hits.size()), emitted});
    kept.albedo = w * in.albedoAtHit(hit);
    const MapPoint point = mapPointOf(scene, mapOfPage, in.texels, hit);
    kept.map = static_cast<int16_t>(point.map);
    kept.texel = point.texel;
    out.hits.push_back(kept);
    if (options.directional) {
      constexpr float kMinCos = 0.1f;  // bounds the 1/cosθ of the irradiance vector's cosine-ray estimator
      const float c = glm::dot(dir, n);
      out.tangent.push_back((dir - c * n) / std::max(c, kMinCos));
    }
    ++keptCount;
  }
  return keptCount;
}

// Round 1: every sample, baseRays each. Fills raysOf (rays traced per slot, 0: empty slot) and returns the
// hits each slot kept, which choose the samples of round 2.
std::vector<std::vector<uint16_t>> ClampGather::Impl::traceFirstRound() {
  raysOf.resize(in.texels.size());
  std::vector<std::vector<uint16_t>> firstHits(in.texels.size());
  for (size_t p = 0; p < in.texels.size(); ++p) {
    raysOf[p].assign(in.texels[p].slotCount(), 0);
    firstHits[p].assign(in.texels[p].slotCount(), 0);
  }
  std::atomic<size_t> traced{0};
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t ti) {
    Tile& tile = tiles[ti];
    const TexelSamples& ts = in.texels[tile.page];
    size_t tracedHere = 0;
    for (size_t s = tile.begin; s < tile.end; ++s) {
      if (!(ts.positionWeight[s].w > 0.0f)) continue;
      int keptCount = traceSlot(tile.page, s, baseRays, 0, tile);
      tracedHere += baseRays;
      raysOf[tile.page][s] = static_cast<uint16_t>(baseRays);
      firstHits[tile.page][s] = static_cast<uint16_t>(std::min(keptCount, 65535));
    }
    traced += tracedHere;
  });
  rays += traced;
  return firstHits;
}

// Which samples round 2 refines: those with a sample of their own texel or of the 8 around it (any of its
// S×S layers) whose first rays found clamped transport, the sample itself left out. A sample's own first rays
// must not choose it: every hit is divided by its slot's ray count, so refining only the samples whose own
// rays hit would average those hits with more rays where they happened to land and leave the rest at 0,
// short of the residual by (1 − P(hit)) · extra / (base + extra) where first rays find it by chance
// (ClampCompensation.RefinementKeepsTheResidualUnbiased). The neighbours' rays are independent of the
// sample's: any of its estimates, refined or not, stays unbiased.
namespace {
std::vector<std::vector<uint8_t>> refinedSlots(const std::vector<TexelSamples>& texels,
                                               const std::vector<std::vector<uint16_t>>& firstHits, int refineHits) {
  std::vector<std::vector<uint8_t>> refine(texels.size());
  for (size_t p = 0; p < texels.size(); ++p) {
    const TexelSamples& ts = texels[p];
    const int W = ts.width, H = ts.height, layers = ts.supersample * ts.supersample;
    const size_t layer = ts.layerSize();
    auto found = [&](size_t s) { return firstHits[p][s] > 0 && firstHits[p][s] >= refineHits; };
    refine[p].assign(ts.slotCount(), 0);
    tbb::parallel_for(0, H, [&](int y) {
      for (int x = 0; x < W; ++x)
        for (int l = 0; l < layers; ++l) {
          const size_t s = static_cast<size_t>(l) * layer + static_cast<size_t>(y) * W + x;
          if (!(ts.positionWeight[s].w > 0.0f)) continue;
          bool any = false;
          for (int dy = -1; dy <= 1 && !any; ++dy)
            for (int dx = -1; dx <= 1 && !any; ++dx) {
              const int xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
              for (int m = 0; m < layers && !any; ++m) {
                const size_t o = static_cast<size_t>(m) * layer + static_cast<size_t>(yy) * W + xx;
                any = o != s && found(o);
              }
            }
          refine[p][s] = any ? 1 : 0;
        }
    });
  }
  return refine;
}
}  // namespace

// Round 2: more rays where the first rays of the samples around found clamped transport, within the same
// budget again.
void ClampGather::Impl::traceRefinement(const std::vector<std::vector<uint16_t>>& firstHits, const RayPlan& plan) {
  const std::vector<std::vector<uint8_t>> refine = refinedSlots(in.texels, firstHits, plan.refineHits);
  size_t candidates = 0;
  for (const std::vector<uint8_t>& page : refine)
    for (uint8_t r : page) candidates += r;
  int extra = std::min(plan.extraRays, 65535 - baseRays);
  if (options.rayBudget > 0 && candidates > 0)
    extra = static_cast<int>(std::min<size_t>(static_cast<size_t>(std::max(extra, 0)), options.rayBudget / candidates));
  if (extra <= 0 || candidates == 0) return;
  std::atomic<size_t> traced{0}, refinedSamples{0};
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t ti) {
    Tile& tile = tiles[ti];
    size_t tracedHere = 0, refinedHere = 0;
    for (size_t s = tile.begin; s < tile.end; ++s) {
      if (!refine[tile.page][s]) continue;
      traceSlot(tile.page, s, extra, 1, tile);
      tracedHere += extra;
      raysOf[tile.page][s] = static_cast<uint16_t>(raysOf[tile.page][s] + extra);
      ++refinedHere;
    }
    traced += tracedHere;
    refinedSamples += refinedHere;
  });
  rays += traced;
  refined += refinedSamples;
}

// Each hit stands for 1 / (rays of its slot) of the hemisphere.
void ClampGather::Impl::divideByRaysOfSlot() {
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t ti) {
    Tile& tile = tiles[ti];
    auto invRays = [&](const KeptHit& kept) {
      return 1.0f / static_cast<float>(std::max<uint16_t>(1, raysOf[tile.page][tile.begin + kept.slotInTile]));
    };
    for (EmittedHit& e : tile.emitted) e.emitted *= invRays(tile.hits[e.hit]);
    for (KeptHit& kept : tile.hits) kept.albedo *= invRays(kept);
    // Exact size from here on: the doubling slack of the traced lists would stay for the sweeps.
    tile.hits.shrink_to_fit();
    tile.emitted.shrink_to_fit();
    tile.tangent.shrink_to_fit();
  });
}

ClampGather::~ClampGather() = default;
double ClampGather::traceSeconds() const { return impl_->traceSeconds; }

ClampGather::ClampGather(const BakeInputs& in, const ClampCompensationOptions& options)
    : impl_(std::make_unique<Impl>(in, options)) {
  Stopwatch clock;
  Impl& gather = *impl_;
  gather.bound = in.eval.clampBound;
  gather.enabled = in.eval.includeVpls && gather.bound > 0.0f;
  if (!gather.enabled) return;
  if (in.texels.size() > kMaxPages)
    throw Error(ErrorCode::InvalidData, "", "clamp compensation: more than " + std::to_string(kMaxPages) + " light-map pages");
  gather.mapOfPage = mapIndexOfPages(in.texels);
  gather.makeTiles();
  const RayPlan plan = planRays(in.texels, options);
  gather.baseRays = plan.baseRays;
  gather.chooseFilters();
  const std::vector<std::vector<uint16_t>> firstHits = gather.traceFirstRound();
  gather.traceRefinement(firstHits, plan);
  gather.divideByRaysOfSlot();
  gather.traceSeconds = clock.seconds();
}

namespace {

// One sweep's gather: each texel sample's residual, Σ over its kept hits of (emitted + albedo × map read).
void gatherSlotResiduals(const std::vector<Tile>& tiles, const std::vector<PackedLightmap>& packed,
                         std::vector<std::vector<glm::vec3>>& slotResidual) {
  tbb::parallel_for(size_t(0), tiles.size(), [&](size_t ti) {
    const Tile& tile = tiles[ti];
    auto& res = slotResidual[tile.page];
    for (size_t s = tile.begin; s < tile.end; ++s) res[s] = glm::vec3(0.0f);
    size_t e = 0;  // next EmittedHit
    for (size_t h = 0; h < tile.hits.size(); ++h) {
      const KeptHit& kept = tile.hits[h];
      glm::vec3 L(0.0f);
      if (e < tile.emitted.size() && tile.emitted[e].hit == h) L = tile.emitted[e++].emitted;
      if (kept.map >= 0) L += kept.albedo * packed[kept.map].read(kept.texel);
      res[tile.begin + kept.slotInTile] += L;
    }
  });
}

// A sweep's residual per texel as the map adds it: filtered (radius 0: not), then mixed like the interleave's
// classes (classMix > 1).
std::vector<glm::vec3> filteredResidual(SurfaceFilterCache& filters, const TexelSamples& ts,
                                        const std::vector<glm::vec3>& residual, const std::vector<uint8_t>& valid,
                                        const TexelFilterOptions& filter, int classMix) {
  std::vector<glm::vec3> out = filter.radius > 0 ? filters.apply(ts, residual, valid, filter) : residual;
  if (classMix > 1) out = filters.apply(ts, out, valid, classMixFilter(classMix));
  return out;
}

// current = map + filter(current − map) on the valid texels: the residual filtered once, after the sweeps.
void filterResidual(const Lightmap& map, std::vector<glm::vec3>& current, SurfaceFilterCache& filters,
                    const TexelSamples& texels, const TexelFilterOptions& options) {
  std::vector<glm::vec3> r(map.size(), glm::vec3(0.0f));
  for (size_t t = 0; t < r.size(); ++t)
    if (map.valid[t]) r[t] = current[t] - map.texels[t];
  r = filters.apply(texels, r, map.valid, options);
  for (size_t t = 0; t < r.size(); ++t)
    if (map.valid[t]) current[t] = map.texels[t] + r[t];
}

// The sweeps' geometric tail, texel by texel: step_{k+1} = T step_k converges at each texel with its own
// ratio (a corner's near field keeps more of its light than an open edge's: furnace ρ 0.9, 0.45 against 0.29
// for the whole map), so each texel adds step · q/(1 − q) with q its own last two steps' ratio (channel
// means), held to [0, qMax]. Where that ratio is undefined (a step of 0 or a sign change: ray noise) the map's
// ratio `mapRatio` stands in.
void addTexelTails(std::vector<std::vector<glm::vec3>>& current, const std::vector<std::vector<glm::vec3>>& previous,
                   const std::vector<std::vector<float>>& stepBefore, const std::vector<Lightmap>& maps,
                   double mapRatio, double qMax) {
  for (size_t p = 0; p < maps.size(); ++p)
    tbb::parallel_for(size_t(0), current[p].size(), [&](size_t t) {
      if (t >= maps[p].valid.size() || !maps[p].valid[t]) return;
      const glm::vec3 step = current[p][t] - previous[p][t];
      const float now = channelMean(step), before = stepBefore[p][t];
      const double q = now > 0.0f && before > 0.0f ? std::min(static_cast<double>(now / before), qMax) : mapRatio;
      current[p][t] += static_cast<float>(q / (1.0 - q)) * step;
    });
}

// Per texel, the channel mean of current − previous (the last sweep's step).
std::vector<std::vector<float>> texelSteps(const std::vector<std::vector<glm::vec3>>& current,
                                           const std::vector<std::vector<glm::vec3>>& previous) {
  std::vector<std::vector<float>> steps(current.size());
  for (size_t p = 0; p < current.size(); ++p) {
    steps[p].resize(current[p].size());
    for (size_t t = 0; t < current[p].size(); ++t) steps[p][t] = channelMean(current[p][t] - previous[p][t]);
  }
  return steps;
}

// maps = current on the valid, finite texels (post's finite check reports the others); `before` and `added`
// sum the channel means of the maps before and of what was added.
void writeFinite(std::vector<Lightmap>& maps, const std::vector<std::vector<glm::vec3>>& current, double& before,
                 double& added) {
  for (size_t p = 0; p < maps.size(); ++p) {
    for (size_t t = 0; t < maps[p].size(); ++t) {
      if (!maps[p].valid[t]) continue;
      const glm::vec3 c = current[p][t];
      if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
      before += channelMean(maps[p].texels[t]);
      added += channelMean(c - maps[p].texels[t]);
      maps[p].texels[t] = c;
    }
  }
}

}  // namespace

void ClampGather::apply(std::vector<Lightmap>& maps, ClampCompensationStats* stats) const {
  Stopwatch clock;
  const Impl& g = *impl_;
  const BakeInputs& in = g.in;
  const ClampCompensationOptions& options = g.options;
  if (!g.enabled || maps.size() != in.texels.size()) return;
  for (size_t p = 0; p < maps.size(); ++p)
    if (maps[p].width != in.texels[p].width || maps[p].height != in.texels[p].height ||
        maps[p].valid.size() != maps[p].size())
      throw Error(ErrorCode::InvalidData, "", "clamp compensation: map " + std::to_string(p) + " does not match its texel page");
  const std::vector<Tile>& tiles = g.tiles;
  const auto& radii = g.radii;

  // Sweeps: residual per slot from the current maps, folded into texels; the next sweep reads base + residual.
  // The base is maps[p].texels itself (unchanged until the end): no third copy of every page.
  std::vector<std::vector<glm::vec3>> current(maps.size());
  for (size_t p = 0; p < maps.size(); ++p) current[p] = maps[p].texels;
  auto base = [&](size_t p) -> const std::vector<glm::vec3>& { return maps[p].texels; };
  std::vector<std::vector<glm::vec3>> slotResidual(maps.size());
  for (size_t p = 0; p < maps.size(); ++p) slotResidual[p].assign(in.texels[p].slotCount(), glm::vec3(0.0f));
  size_t kept = 0;
  for (const Tile& t : tiles) kept += t.hits.size();

  // Σ over valid texels of the map before the residual (channel mean): the scale of the stopping test.
  double mapTotal = 0.0;
  for (size_t p = 0; p < maps.size(); ++p)
    for (size_t t = 0; t < maps[p].size(); ++t)
      if (maps[p].valid[t]) mapTotal += channelMean(base(p)[t]);
  double lastAdded = 0.0, lastStep = 0.0, stepBefore = 0.0;
  int sweepsDone = 0;
  bool tailAdded = false;
  constexpr int kFirstTailSweep = 3;  // at least 4 sweeps before the tail: the ratio creeps up over the first few
  std::vector<std::vector<glm::vec3>> previous(maps.size());  // current before the sweep (for the tail)
  std::vector<std::vector<float>> texelStepBefore;           // each texel's step of the sweep before (for the tail)
  // The filter's neighbour tests are made once for all sweeps (otherwise most of a sweep's time) and shared
  // with the bake's other filters: the page's plan in SurfaceFilterCache.
  std::vector<TexelFilterOptions> filterOptions(maps.size());
  for (size_t p = 0; p < maps.size(); ++p) filterOptions[p].radius = radii[p];
  for (int sweep = 0; sweep < std::max(1, options.sweeps); ++sweep) {
    if (options.extrapolateTail && sweep >= kFirstTailSweep - 1) previous = current;
    const std::vector<PackedLightmap> packed = packLightmaps(maps, current);  // the hits' reads (lightmap_read.h)
    gatherSlotResiduals(tiles, packed, slotResidual);
    double added = 0.0;  // Σ residual (channel mean) = what this sweep's map adds to the base
    for (size_t p = 0; p < maps.size(); ++p) {
      const TexelSamples& ts = in.texels[p];
      const Lightmap& m = maps[p];
      const size_t layer = ts.layerSize();
      // The lookups of this sweep are done, so the page's current map is free until rebuilt below:
      // the residual is gathered into it, and current = base + residual is written over it texel by
      // texel (separate residual and "next" maps held two more copies of the page at the peak).
      std::vector<glm::vec3>& residual = current[p];
      residual.assign(layer, glm::vec3(0.0f));
      tbb::parallel_for(size_t(0), layer, [&](size_t t) {
        if (t < m.valid.size() && m.valid[t]) texelMean(ts, t, [&](size_t s) { return slotResidual[p][s]; }, residual[t]);
      });
      const TexelFilterOptions noFilter{0};
      const std::vector<glm::vec3> residualUsed = filteredResidual(
          *g.filters(), ts, residual, m.valid, options.filterEachSweep ? filterOptions[p] : noFilter, options.classMix);
      const std::vector<glm::vec3>& baseMap = base(p);
      for (size_t t = 0; t < layer; ++t) {
        if (t < m.valid.size() && m.valid[t]) {
          const glm::vec3 r = residualUsed[t];
          current[p][t] = baseMap[t] + r;
          added += channelMean(r);
        } else {
          current[p][t] = baseMap[t];
        }
      }
    }
    ++sweepsDone;
    const double step = added - lastAdded;  // what this sweep's bounce added (sweep 0: the first bounce)
    log::debug("compensation sweep " + std::to_string(sweep) + ": added " + std::to_string(added / mapTotal) +
               " of the map");
    // Each sweep adds one more bounce inside the clamp radius: stop once that changes the map by less
    // than the tolerance (a narrow gap needs more bounces than an open corner).
    const double tolerance = options.sweepTolerance * std::abs(mapTotal);
    const bool converged = sweep > 0 && std::abs(step) <= tolerance;
    // Or add the rest at once: the steps are a Neumann series, step_{k+1} = T step_k, so once their
    // ratio q has settled the remaining sweeps add step_k · q/(1 − q), texel by texel with each texel's own
    // ratio (addTexelTails; the map's q where a texel's is undefined). Settled: the
    // tails predicted by this ratio and the last one differ by at most the tolerance (the ratio creeps up
    // over the first few sweeps as longer paths reach narrower gaps).
    if (!converged && options.extrapolateTail && sweep >= kFirstTailSweep && lastStep > 0.0 && step > 0.0) {
      const double q = step / lastStep, qBefore = lastStep / stepBefore;
      auto tailOf = [&](double r) { return step * r / (1.0 - r); };
      if (q < 0.9 && qBefore > 0.0 && qBefore < 0.9 && std::abs(tailOf(q) - tailOf(qBefore)) <= tolerance) {
        addTexelTails(current, previous, texelStepBefore, maps, q, 0.9);
        tailAdded = true;
        break;
      }
    }
    if (options.extrapolateTail && sweep >= kFirstTailSweep - 1) texelStepBefore = texelSteps(current, previous);
    stepBefore = lastStep;
    lastStep = step;
    lastAdded = added;
    if (converged) break;
  }

  // Or once, after the last sweep (linear: the same in expectation, noisier between sweeps).
  if (!options.filterEachSweep)
    for (size_t p = 0; p < maps.size(); ++p)
      if (radii[p] > 0) filterResidual(maps[p], current[p], *g.filters(), in.texels[p], filterOptions[p]);
  double before = 0.0, added = 0.0;
  writeFinite(maps, current, before, added);
  if (stats) {
    stats->raysTraced = g.rays;
    stats->samplesRefined = g.refined;
    stats->hitsKept = kept;
    stats->raysPerSample = g.baseRays;
    stats->filterRadius = g.filterRadius;
    stats->sweeps = sweepsDone;
    stats->tailExtrapolated = tailAdded;
    stats->addedFraction = before > 0.0 ? added / before : 0.0;
    stats->seconds = g.traceSeconds + clock.seconds();
  }
}

void ClampGather::applyDirectional(const std::vector<Lightmap>& maps, L1Pages& axes) const {
  const Impl& g = *impl_;
  const BakeInputs& in = g.in;
  if (!g.enabled || !g.options.directional || maps.size() != in.texels.size()) return;
  for (const auto& pages : axes)
    if (pages.size() != maps.size()) return;
  // Per slot, per axis k: Σ term · τ_k (an RGB triple each), the hits' terms read from the final maps.
  std::array<std::vector<std::vector<glm::vec3>>, 3> slotVector;
  for (auto& v : slotVector) {
    v.resize(maps.size());
    for (size_t p = 0; p < maps.size(); ++p) v[p].assign(in.texels[p].slotCount(), glm::vec3(0.0f));
  }
  tbb::parallel_for(size_t(0), g.tiles.size(), [&](size_t ti) {
    const Tile& tile = g.tiles[ti];
    size_t e = 0;
    for (size_t h = 0; h < tile.hits.size() && h < tile.tangent.size(); ++h) {
      const KeptHit& kept = tile.hits[h];
      glm::vec3 L(0.0f);
      if (e < tile.emitted.size() && tile.emitted[e].hit == h) L = tile.emitted[e++].emitted;
      if (kept.map >= 0) L += kept.albedo * readLightmap(maps[kept.map], maps[kept.map].texels, kept.texel);
      const size_t s = tile.begin + kept.slotInTile;
      for (int k = 0; k < 3; ++k) slotVector[k][tile.page][s] += L * tile.tangent[h][k];
    }
  });
  for (size_t p = 0; p < maps.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    const Lightmap& m = maps[p];
    const size_t layer = ts.layerSize();
    std::array<std::vector<glm::vec3>, 3> texelVector;
    for (int k = 0; k < 3; ++k) {
      texelVector[k].assign(layer, glm::vec3(0.0f));
      tbb::parallel_for(size_t(0), layer, [&](size_t t) {
        if (t < m.valid.size() && m.valid[t])
          texelMean(ts, t, [&](size_t s) { return slotVector[k][p][s]; }, texelVector[k][t]);
      });
    }
    TexelFilterOptions fo;
    fo.radius = g.radii[p];
    for (const TexelFilterOptions& f : {fo, classMixFilter(g.options.classMix)}) {  // the map's filter, then its mix
      if (f.radius <= 0) continue;
      std::vector<std::vector<glm::vec3>> filtered =
          g.filters()->apply(in.texels[p], {&texelVector[0], &texelVector[1], &texelVector[2]}, m.valid, f);
      for (int k = 0; k < 3; ++k) texelVector[k] = std::move(filtered[k]);
    }
    for (int k = 0; k < 3; ++k) {
      Lightmap& page = axes[k][p];
      for (size_t t = 0; t < layer && t < page.texels.size(); ++t) {
        const glm::vec3 v = texelVector[k][t];
        if (t < m.valid.size() && m.valid[t] && std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))
          page.texels[t] += v;
      }
    }
  }
}

}  // namespace irbake
