#include "stages/gather/final_gather.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "lightmap/lightmap_read.h"
#include "texels/sample_lattice.h"
#include "common/error.h"
#include "common/maths.h"
#include "common/progress.h"
#include "texels/surface_filter_cache.h"
#include "sampling/sampling.h"

namespace irbake {
namespace {

constexpr uint64_t kGatherStream = 0xf9;        // the gather's lattice rotations (forEachSampleLattice)
constexpr uint64_t kPreGatherStream = 0xfa;     // the first pass's (independent of the final pass's)
constexpr int kSpreadPasses = 3;  // the outliers' excess: box filters of radius 5 in turn, a soft ~31-texel window
                                  // whose centre keeps 1/214 of a texel's excess (1/121 for one or two passes)

}  // namespace

namespace {

// The base colour per texel of each page: the coverage-weighted mean over its samples of in.albedoAtHit at the
// sample (valid texels; others 0). The gather reads ρ M from one packed map instead of ρ at every hit and M
// beside it: a texture read fewer per hit (the footprint albedo is already a map texel's mean, so a
// bilinear read of ρ M differs from ρ(hit) × a bilinear read of M only across a material border in a texel).
std::vector<std::vector<glm::vec3>> texelAlbedo(const BakeInputs& in) {
  const Scene& scene = in.scene;
  std::vector<std::vector<glm::vec3>> albedo(in.texels.size());
  for (size_t p = 0; p < in.texels.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    albedo[p].assign(ts.layerSize(), glm::vec3(0.0f));
    tbb::parallel_for(size_t(0), ts.layerSize(), [&](size_t t) {
      if (!ts.valid[t]) return;
      texelMean(ts, t, [&](size_t s) {
        RayHit hit;
        hit.hit = true;
        hit.primitive = ts.primitive[s];
        hit.triangle = ts.triangle[s];
        const Primitive& prim = scene.primitives[hit.primitive];
        const uint32_t* idx = &prim.indices[3 * static_cast<size_t>(hit.triangle)];
        const glm::vec3 a = prim.positions[idx[0]], e1 = prim.positions[idx[1]] - a, e2 = prim.positions[idx[2]] - a;
        const glm::vec3 d = glm::vec3(ts.positionWeight[s]) - a;
        // Barycentrics of the sample's projection onto the triangle's plane, held inside it.
        const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
        const float det = d11 * d22 - d12 * d12;
        glm::vec2 b(1.0f / 3.0f);
        if (det > 0.0f) {
          const float p1 = glm::dot(d, e1), p2 = glm::dot(d, e2);
          b = glm::vec2((d22 * p1 - d12 * p2) / det, (d11 * p2 - d12 * p1) / det);
          b = glm::clamp(b, 0.0f, 1.0f);
          if (b.x + b.y > 1.0f) b /= b.x + b.y;
        }
        hit.barycentric = b;
        return in.albedoAtHit(hit);
      }, albedo[p][t]);
    });
  }
  return albedo;
}

// ρ M per page, packed for the gather's reads.
std::vector<PackedLightmap> packReflected(const std::vector<Lightmap>& maps,
                                          const std::vector<std::vector<glm::vec3>>& albedo) {
  std::vector<PackedLightmap> packed;
  packed.reserve(maps.size());
  for (size_t p = 0; p < maps.size(); ++p)
    packed.emplace_back(maps[p], [&](size_t t) { return albedo[p][t] * maps[p].texels[t]; });
  return packed;
}

// gatherAt over ρ M packed (the gather's passes pack their source once).
glm::vec3 gatherAtPacked(const BakeInputs& in, const std::vector<PackedLightmap>& maps, const std::vector<int32_t>& mapOfPage,
                         const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2,
                         const glm::vec3& missRadiance, L1Vectors* tangential, glm::vec3* emitted = nullptr) {
  const Scene& scene = in.scene;
  const RayTracer& rt = in.rayTracer;
  const glm::vec3 origin = x + n * rt.epsilon();
  glm::vec3 sum(0.0f), emittedSum(0.0f);
  L1Vectors t{};
  CosineLattice lattice(n, rays, r1, r2);
  constexpr int kChunk = 32;  // rays traced together, 8 to a packet (one origin: the packets stay coherent)
  glm::vec3 dirs[kChunk];
  RayHit hits[kChunk];
  for (int begin = 0; begin < rays; begin += kChunk) {
    const int count = std::min(kChunk, rays - begin);
    for (int k = 0; k < count; ++k) dirs[k] = lattice.next();
    rt.intersectPackets(origin, dirs, static_cast<size_t>(count), hits, RayTracer::HitDetail::Surface,
                        RayTracer::Traversal::Fast);
    for (int k = 0; k < count; ++k) {
      const RayHit& hit = hits[k];
      if (!hit.hit) {
        sum += missRadiance;
        continue;
      }
      if (hit.backFace) continue;  // back faces hold no map
      const Primitive& prim = scene.primitives[hit.primitive];
      glm::vec3 L = scene.emissionAt(prim, hit.triangle, hit.barycentric);
      emittedSum += L;
      const MapPoint point = mapPointOf(scene, mapOfPage, in.texels, hit);
      if (point.map >= 0 && static_cast<size_t>(point.map) < maps.size())
        L += maps[point.map].read(point.texel);  // ρ M, the albedo at the texel's footprint folded in
      sum += L;
      if (tangential) {
        constexpr float kMinCos = 0.1f;  // as the compensation's: bounds 1/cosθ near the horizon
        const float c = glm::dot(dirs[k], n);
        const glm::vec3 w = (dirs[k] - c * n) / std::max(c, kMinCos);
        for (int a = 0; a < 3; ++a) t[a] += L * w[a];
      }
    }
  }
  const float inv = 1.0f / static_cast<float>(std::max(1, rays));
  if (tangential)
    for (int a = 0; a < 3; ++a) (*tangential)[a] = t[a] * inv;
  if (emitted) *emitted = emittedSum * inv;
  return sum * inv;
}

}  // namespace

glm::vec3 gatherAt(const BakeInputs& in, const std::vector<Lightmap>& maps, const std::vector<int32_t>& mapOfPage,
                   const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2,
                   const glm::vec3& missRadiance, L1Vectors* tangential) {
  return gatherAtPacked(in, packReflected(maps, texelAlbedo(in)), mapOfPage, x, n, rays, r1, r2, missRadiance, tangential);
}

namespace {

// value's texels above ratio × their window's mean (radius r, the texel in it) held there; three rounds, so
// that the mean a texel is held to no longer carries its own outlier (the excess shrinks by about ratio / n a
// round, n the window's texels). Returns per texel the share kept (1 where untouched).
std::vector<float> holdOutliers(SurfaceFilterCache* cache, const TexelSamples& ts, std::vector<glm::vec3>& value,
                                const std::vector<uint8_t>& valid, float ratio, int r) {
  std::vector<float> kept(value.size(), 1.0f);
  TexelFilterOptions fo;
  fo.radius = r;
  fo.symmetric = false;  // a texel at a chart border or corner is held against the neighbours it has
  for (int round = 0; round < 3; ++round) {
    const std::vector<glm::vec3> mean = filterOnSurface(cache, ts, value, valid, fo);
    tbb::parallel_for(size_t(0), value.size(), [&](size_t t) {
      const float v = channelMean(value[t]), limit = ratio * channelMean(mean[t]);
      if (!valid[t] || !(v > limit) || !std::isfinite(v)) return;
      const float share = limit / v;
      value[t] *= share;
      kept[t] *= share;
    });
  }
  return kept;
}

// A page's gathered sets (the light, then its L1 axes if any) filtered as options say. With outlierRatio, the
// outliers of the light less its emitted part are held first (holdOutliers; the L1 axes scaled alike: emitters
// are the pipeline's reason to leave the gather off, and forced on their light is left as it was) and what was taken is spread by
// passes of the widest window (kSpreadPasses of SurfaceFilterPlan::kMaxRadius) and added
// back: one ray on a tiny, very bright surface is seen as a faint wide glow instead of a bright square.
// stats: outlierTexels counted; spread: Σ channelMean of the light spread.
void filterGathered(SurfaceFilterCache* cache, const TexelSamples& ts, const std::vector<std::vector<glm::vec3>*>& sets,
                    const std::vector<glm::vec3>& emitted, const std::vector<uint8_t>& valid,
                    const FinalGatherOptions& options, bool holdThem, FinalGatherStats& stats, double& spread) {
  std::vector<std::vector<glm::vec3>> excess;
  if (holdThem && options.outlierRatio > 0.0f) {
    const std::vector<glm::vec3> before = *sets[0];
    std::vector<glm::vec3>& value = *sets[0];
    for (size_t t = 0; t < value.size(); ++t) value[t] -= emitted[t];
    const std::vector<float> kept = holdOutliers(cache, ts, value, valid, options.outlierRatio,
                                                 std::max(1, options.filterRadius));
    for (size_t t = 0; t < value.size(); ++t) value[t] += emitted[t];
    excess.assign(sets.size(), std::vector<glm::vec3>(before.size(), glm::vec3(0.0f)));
    for (size_t t = 0; t < kept.size(); ++t) {
      if (kept[t] >= 1.0f) continue;
      ++stats.outlierTexels;
      spread += channelMean(before[t] - value[t]);
      excess[0][t] = before[t] - value[t];
      const float before1 = channelMean(before[t]);
      const float share = before1 > 0.0f ? channelMean(value[t]) / before1 : 1.0f;  // the L1 scaled alike
      for (size_t k = 1; k < sets.size(); ++k) {
        excess[k][t] = (*sets[k])[t] * (1.0f - share);
        (*sets[k])[t] *= share;
      }
    }
  }
  TexelFilterOptions fo;
  fo.radius = options.filterRadius;
  if (fo.radius > 0) {
    const std::vector<const std::vector<glm::vec3>*> in(sets.begin(), sets.end());
    std::vector<std::vector<glm::vec3>> filtered = filterOnSurface(cache, ts, in, valid, fo);
    for (size_t k = 0; k < sets.size(); ++k) *sets[k] = std::move(filtered[k]);
  }
  if (excess.empty()) return;
  TexelFilterOptions wide;
  wide.radius = SurfaceFilterPlan::kMaxRadius;
  wide.symmetric = false;  // every neighbour takes its share, up to a chart border
  std::vector<const std::vector<glm::vec3>*> excessSets;
  for (const auto& e : excess) excessSets.push_back(&e);
  std::vector<std::vector<glm::vec3>> spreadSets;
  for (int pass = 0; pass < kSpreadPasses; ++pass) {
    spreadSets = filterOnSurface(cache, ts, excessSets, valid, wide);
    for (size_t k = 0; k < spreadSets.size(); ++k) excess[k] = std::move(spreadSets[k]);
  }
  for (size_t k = 0; k < sets.size(); ++k)
    for (size_t t = 0; t < excess[k].size(); ++t)
      if (valid[t]) (*sets[k])[t] += excess[k][t];
}

// One gather: maps ← D + gather(source) at valid texels, the lattice rotations from stream.
// albedo: texelAlbedo(in), made once for both passes.
void gatherPass(const BakeInputs& in, const std::vector<Lightmap>& direct, const std::vector<Lightmap>& source,
                const std::vector<std::vector<glm::vec3>>& albedo, std::vector<Lightmap>& maps,
                const FinalGatherOptions& options, uint64_t stream, FinalGatherStats& stats, const L1Pages* directL1,
                L1Pages* l1) {
  const std::vector<int32_t> mapOfPage = mapIndexOfPages(in.texels);
  const size_t samples = weightedSampleCount(in.texels);
  int rays = std::max(1, options.rays);
  if (options.rayBudget > 0 && samples > 0)
    rays = static_cast<int>(std::clamp<size_t>(options.rayBudget / samples, static_cast<size_t>(std::clamp(options.minRays, 1, rays)),
                                               static_cast<size_t>(rays)));
  const bool directional = l1 && directL1;
  // Every page's gather reads the source as it came in (it may be maps), so the new pages are built apart.
  std::vector<std::vector<glm::vec3>> gathered(maps.size());
  std::array<std::vector<std::vector<glm::vec3>>, 3> gatheredL1;
  const std::vector<PackedLightmap> packedSource = packReflected(source, albedo);
  double spread = 0.0;  // Σ channelMean of the outliers' light spread (filterGathered)
  if (directional)
    for (auto& axis : gatheredL1) axis.resize(maps.size());
  for (size_t p = 0; p < maps.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    std::vector<glm::vec3> slotValue(ts.slotCount(), glm::vec3(0.0f)), slotEmitted(ts.slotCount(), glm::vec3(0.0f));
    std::vector<L1Vectors> slotVector(directional ? ts.slotCount() : 0, L1Vectors{});
    // Interleaved rotations (sample_lattice.h): every filter window averages one stratified lattice of rays
    // instead of independent rays per sample, so the filter removes more of their noise.
    const InterleavedRotations interleaved(ts, options.seed, stream, options.interleave ? options.filterRadius : 0, rays);
    forEachSampleLattice(in.rayTracer, ts, options.seed, stream,
                         [&](size_t s, const glm::vec3& x, const glm::vec3& n, double r1, double r2) {
                           slotValue[s] = gatherAtPacked(in, packedSource, mapOfPage, x, n, rays, r1, r2, options.missRadiance,
                                                   directional ? &slotVector[s] : nullptr, &slotEmitted[s]);
                         },
                         &interleaved);
    std::vector<glm::vec3>& value = gathered[p];
    value.assign(ts.layerSize(), glm::vec3(0.0f));
    const std::vector<uint8_t>& valid = maps[p].valid;
    tbb::parallel_for(size_t(0), ts.layerSize(), [&](size_t t) {
      if (valid[t]) texelMean(ts, t, [&](size_t s) { return slotValue[s]; }, value[t]);
    });
    std::vector<glm::vec3> emitted(ts.layerSize(), glm::vec3(0.0f));  // the emitters' share, not held
    tbb::parallel_for(size_t(0), ts.layerSize(), [&](size_t t) {
      if (valid[t]) texelMean(ts, t, [&](size_t s) { return slotEmitted[s]; }, emitted[t]);
    });
    std::vector<std::vector<glm::vec3>*> sets = {&value};
    std::array<std::vector<glm::vec3>, 3> axes;
    if (directional)
      for (int k = 0; k < 3; ++k) {
        axes[k].assign(ts.layerSize(), glm::vec3(0.0f));
        tbb::parallel_for(size_t(0), ts.layerSize(), [&](size_t t) {
          if (valid[t]) texelMean(ts, t, [&](size_t s) { return slotVector[s][k]; }, axes[k][t]);
        });
        sets.push_back(&axes[k]);
      }
    filterGathered(in.surfaceFilters, ts, sets, emitted, valid, options, stream == kGatherStream, stats, spread);
    if (directional)
      for (int k = 0; k < 3; ++k) gatheredL1[k][p] = std::move(axes[k]);
  }
  double total = 0.0, gatheredSum = 0.0, change = 0.0, before = 0.0;
  for (size_t p = 0; p < maps.size(); ++p)
    for (size_t t = 0; t < maps[p].size(); ++t) {
      if (!maps[p].valid[t]) continue;
      const glm::vec3 next = direct[p].texels[t] + gathered[p][t];
      if (!std::isfinite(next.x) || !std::isfinite(next.y) || !std::isfinite(next.z)) continue;  // post reports
      before += channelMean(maps[p].texels[t]);
      change += channelMean(glm::abs(next - maps[p].texels[t]));
      gatheredSum += channelMean(gathered[p][t]);
      total += channelMean(next);
      maps[p].texels[t] = next;
      if (directional)
        for (int k = 0; k < 3; ++k) {
          const glm::vec3 v = (*directL1)[k][p].texels[t] + gatheredL1[k][p][t];
          if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) (*l1)[k][p].texels[t] = v;
        }
    }
  stats.rays = samples * static_cast<size_t>(rays);
  stats.raysPerSample = rays;
  stats.filterRadius = options.filterRadius;
  stats.gatheredFraction = total > 0.0 ? gatheredSum / total : 0.0;
  stats.changeFraction = before > 0.0 ? change / before : 0.0;
  stats.outlierFraction = total > 0.0 ? spread / total : 0.0;
}

}  // namespace

void finalGather(const BakeInputs& in, const std::vector<Lightmap>& direct, std::vector<Lightmap>& maps,
                 const FinalGatherOptions& options, FinalGatherStats* stats, const L1Pages* directL1, L1Pages* l1) {
  Stopwatch watch;
  if (maps.size() != in.texels.size() || direct.size() != maps.size())
    throw Error(ErrorCode::InvalidData, "", "final gather: " + std::to_string(maps.size()) + " maps and " +
                                                std::to_string(direct.size()) + " direct pages for " +
                                                std::to_string(in.texels.size()) + " texel pages");
  for (size_t p = 0; p < maps.size(); ++p)
    if (maps[p].size() != in.texels[p].layerSize() || maps[p].valid.size() != maps[p].size() ||
        direct[p].size() != maps[p].size())
      throw Error(ErrorCode::InvalidData, "", "final gather: page " + std::to_string(p) + " does not match its texels");
  if (l1 && directL1)
    for (int k = 0; k < 3; ++k)
      if ((*l1)[k].size() != maps.size() || (*directL1)[k].size() != maps.size())
        throw Error(ErrorCode::InvalidData, "", "final gather: the L1 pages do not match the maps");
  const std::vector<std::vector<glm::vec3>> albedo = texelAlbedo(in);
  // The first pass: M1, the map the final pass reads; the stats' "before" stays M, the maps as they came in.
  FinalGatherStats first;
  std::vector<Lightmap> firstMaps;
  if (options.preRays > 0) {
    firstMaps = maps;
    FinalGatherOptions o = options;
    o.rays = options.preRays;
    o.filterRadius = options.preFilterRadius;
    gatherPass(in, direct, maps, albedo, firstMaps, o, kPreGatherStream, first, nullptr, nullptr);
  }
  FinalGatherStats last;
  gatherPass(in, direct, options.preRays > 0 ? firstMaps : maps, albedo, maps, options, kGatherStream, last, directL1, l1);
  if (stats) {
    *stats = last;
    stats->rays += first.rays;
    stats->preRaysPerSample = first.raysPerSample;
    stats->seconds = watch.seconds();
  }
}

}  // namespace irbake
