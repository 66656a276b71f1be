#include "evaluators/embree/embree_backend.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "transport/directional.h"
#include "transport/geometry_term.h"
#include "common/error.h"

namespace irbake {

namespace {

// Kahan-compensated float accumulator: 1e5 VPL terms stay within ~1e-7 of the exact sum, where a plain
// float sum drifts by up to N·ε. The extra adds are free next to a shadow ray.
struct KahanSum {
  glm::vec3 sum{0.0f}, carry{0.0f};
  void add(const glm::vec3& v) {
    glm::vec3 y = v - carry;
    glm::vec3 t = sum + y;
    carry = (t - sum) - y;
    sum = t;
  }
};

// The clamped map value of VPL v at (x, n) before visibility; false when it cannot contribute
// (behind either surface, or no power). Shared by the packet and single-ray gathers.
bool unshadowedVplValue(const Vpl& v, float bound, const glm::vec3& x, const glm::vec3& n, glm::vec3& value) {
  float g = vplGeometryTerm(x, n, v.position, v.normal);
  if (g <= 0.0f) return false;
  value = vplMapValue(v.power, clampGeometryTerm(g, bound));
  return value.x > 0.0f || value.y > 0.0f || value.z > 0.0f;
}

// Visits the VPLs [begin, end) visible from (x, n) with their (transmitted) map value, visit(value, vpl),
// tracing the shadow rays in packets of 8.
template <typename Visit>
void visitVplsPackets(const BakeInputs& in, float bound, const glm::vec3& x, const glm::vec3& n, size_t begin,
                      size_t end, Visit&& visit) {
  const auto& vpls = in.vpls.vpls;
  constexpr size_t kBatch = 64;
  ShadowRay rays[kBatch];
  glm::vec3 values[kBatch];
  size_t which[kBatch];
  uint8_t blocked[kBatch];
  size_t count = 0;
  auto flush = [&]() {
    in.rayTracer.occludedPackets(rays, count, blocked);
    const bool seeThrough = in.rayTracer.hasTransmission();
    for (size_t i = 0; i < count; ++i)
      if (!blocked[i])
        visit(seeThrough ? values[i] * in.rayTracer.transmittance(rays[i].origin, rays[i].dir, 0.0f, rays[i].tmax)
                         : values[i],
              vpls[which[i]]);
    count = 0;
  };
  for (size_t k = begin; k < end; ++k) {
    const Vpl& v = vpls[k];
    glm::vec3 value;
    if (!unshadowedVplValue(v, bound, x, n, value)) continue;
    if (!in.rayTracer.visibilityRay(x, n, v.position, v.normal, rays[count])) {
      visit(value, v);  // closer than ε: visible
      continue;
    }
    which[count] = k;
    values[count++] = value;
    if (count == kBatch) flush();
  }
  if (count) flush();
}

// Visits the VPLs [begin, end) visible from (x, n) with their (transmitted) map value, one shadow ray each.
template <typename Visit>
void visitVpls(const BakeInputs& in, float bound, const glm::vec3& x, const glm::vec3& n, size_t begin, size_t end,
               Visit&& visit) {
  const auto& vpls = in.vpls.vpls;
  for (size_t k = begin; k < end; ++k) {
    const Vpl& v = vpls[k];
    glm::vec3 value;
    if (!unshadowedVplValue(v, bound, x, n, value)) continue;
    ShadowRay ray;
    if (in.rayTracer.visibilityRay(x, n, v.position, v.normal, ray)) {
      if (in.rayTracer.occluded(ray.origin, ray.dir, 0.0f, ray.tmax)) continue;
      value *= in.rayTracer.transmittance(ray.origin, ray.dir, 0.0f, ray.tmax);
    }
    visit(value, v);
  }
}

// What one texel sample gathers: the map value (Kahan, float: the map's bits do not depend on whether the
// L1 part is wanted) and, for directional maps, the irradiance vector g (transport/directional.h) in
// double: thousands of small VPL terms, 9 numbers per sample.
struct SampleGather {
  KahanSum map;
  std::array<glm::dvec3, 3> g{};
  // A source of map value `value` in direction toSource (unit) from a receiver of normal n.
  void addDirectional(const glm::vec3& value, const glm::vec3& toSource, const glm::vec3& n) {
    const float c = glm::dot(n, toSource);
    if (!(c > 0.0f)) return;
    const glm::dvec3 e = glm::dvec3(value) / double(c);  // E / π facing the source
    for (int k = 0; k < 3; ++k) g[k] += e * double(toSource[k]);
  }
  L1Vectors tangential(const glm::vec3& n) const {
    return tangentialPart(L1Vectors{glm::vec3(g[0]), glm::vec3(g[1]), glm::vec3(g[2])}, n);
  }
};

// Adds the VPLs [begin, end) seen from (x, n) into acc (and its irradiance vector when directional).
void gatherVplBlock(const BakeInputs& in, float bound, const glm::vec3& x, const glm::vec3& n, size_t begin,
                    size_t end, bool packets, bool directional, SampleGather& acc) {
  auto visit = [&](const glm::vec3& value, const Vpl& v) {
    acc.map.add(value);
    if (directional) acc.addDirectional(value, glm::normalize(v.position - x), n);
  };
  if (packets) visitVplsPackets(in, bound, x, n, begin, end, visit);
  else visitVpls(in, bound, x, n, begin, end, visit);
}

// Visits the punctual lights visible from (x, n): visit(map value, unit direction towards the light).
template <typename Visit>
void visitDirect(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, Visit&& visit) {
  const float eps = in.rayTracer.epsilon();
  for (uint32_t i : in.lightsNear(x)) {
    if (!in.eval.directIncludes(i)) continue;
    PunctualContribution c = punctualDirect(in.scene.lights[i], x, n);
    if (c.mapValue == glm::vec3(0.0f)) continue;
    glm::vec3 origin = x + n * eps;
    float tmax = shadowRayLength(c, eps);
    if (tmax > 0.0f && in.rayTracer.occluded(origin, c.toLight, 0.0f, tmax)) continue;
    visit(tmax > 0.0f ? c.mapValue * in.rayTracer.transmittance(origin, c.toLight, 0.0f, tmax) : c.mapValue,
          c.toLight);
  }
}

glm::vec3 directAt(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n) {
  glm::vec3 sum(0.0f);
  visitDirect(in, x, n, [&](const glm::vec3& value, const glm::vec3&) { sum += value; });
  return sum;
}

glm::vec3 vplSumAt(const BakeInputs& in, float bound, const glm::vec3& x, const glm::vec3& n, bool packets) {
  SampleGather acc;
  gatherVplBlock(in, bound, x, n, 0, in.vpls.vpls.size(), packets, false, acc);
  return acc.map.sum;
}

float clampBoundFor(const BakeInputs& in) { return in.eval.includeVpls ? in.eval.clampBound : 0.0f; }

// A texel sample's position moved ε into its triangle: samples snapped onto an edge (a texel centre
// outside every triangle takes the nearest point) would otherwise start rays on the plane of the
// neighbouring face at concave corners and see behind it.
glm::vec3 samplePosition(const BakeInputs& in, const TexelSamples& ts, size_t s) {
  glm::vec3 x(ts.positionWeight[s]);
  if (s >= ts.primitive.size() || s >= ts.triangle.size()) return x;
  uint32_t p = ts.primitive[s], t = ts.triangle[s];
  if (p >= in.scene.primitives.size() || t >= in.scene.primitives[p].triangleCount()) return x;
  return in.rayTracer.insetPoint(p, t, x);
}

}  // namespace

PointShading shadePointEmbree(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, const EmbreeOptions& options) {
  PointShading s;
  if (in.eval.includeDirect) s.direct = directAt(in, x, n);
  if (in.eval.includeVpls) s.vpl = vplSumAt(in, clampBoundFor(in), x, n, options.packets);
  return s;
}

PointShading shadePointEmbree(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, Rng& /*unused*/,
                              const EmbreeOptions& options) {
  return shadePointEmbree(in, x, n, options);
}

std::vector<Lightmap> bakeEmbree(const BakeInputs& inputs, const EmbreeOptions& options) {
  return EmbreeEvaluator(options).evaluate(inputs);
}

std::vector<Lightmap> EmbreeEvaluator::evaluate(const BakeInputs& in, const EvaluationRequest& request) const {
  const EmbreeOptions& options = options_;
  std::vector<Lightmap> maps;
  const bool directional = request.directional != nullptr;
  if (directional)
    for (auto& axis : *request.directional) axis.clear();
  size_t totalSlots = 0, doneSlots = 0;
  for (const auto& t : in.texels) totalSlots += t.slotCount();
  std::atomic<size_t> progressSlots{0};
  const float bound = clampBoundFor(in);
  const size_t block = static_cast<size_t>(std::max(1, options.vplBlock));
  const size_t tile = static_cast<size_t>(std::max(1, options.tileSlots));
  const size_t numVpls = in.eval.includeVpls ? in.vpls.vpls.size() : 0;

  for (size_t page = 0; page < in.texels.size(); ++page) {
    const TexelSamples& ts = in.texels[page];
    Lightmap map = blankLightmap(ts);
    const size_t slots = ts.slotCount(), layer = std::max<size_t>(1, ts.layerSize());
    std::vector<glm::vec3> slotValue(slots, glm::vec3(0.0f));
    std::vector<L1Vectors> slotL1(directional ? slots : 0, L1Vectors{});
    const std::vector<uint8_t>* subset =
        request.texelSubset && page < request.texelSubset->size() ? &(*request.texelSubset)[page] : nullptr;
    auto wanted = [&](size_t t) { return !subset || (t < subset->size() && (*subset)[t] != 0); };

    tbb::parallel_for(tbb::blocked_range<size_t>(0, slots, tile), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<size_t> active;
      for (size_t s = r.begin(); s != r.end(); ++s)
        if (ts.positionWeight[s].w > 0.0f && wanted(s % layer)) active.push_back(s);
      std::vector<SampleGather> acc(active.size());
      // VPLs in blocks: one block stays hot in cache while every sample of the tile loops over it.
      for (size_t b0 = 0; b0 < numVpls; b0 += block) {
        size_t b1 = std::min(numVpls, b0 + block);
        for (size_t a = 0; a < active.size(); ++a) {
          size_t s = active[a];
          glm::vec3 x = samplePosition(in, ts, s), n(ts.normal[s]);
          gatherVplBlock(in, bound, x, n, b0, b1, options.packets, directional, acc[a]);
        }
      }
      for (size_t a = 0; a < active.size(); ++a) {
        size_t s = active[a];
        glm::vec3 x = samplePosition(in, ts, s), n(ts.normal[s]);
        glm::vec3 v = acc[a].map.sum;
        if (in.eval.includeDirect) {
          // Summed apart and added once, as directAt does: the map's bits as without directional.
          glm::vec3 direct(0.0f);
          visitDirect(in, x, n, [&](const glm::vec3& value, const glm::vec3& toLight) {
            direct += value;
            if (directional) acc[a].addDirectional(value, toLight, n);
          });
          v += direct;
        }
        slotValue[s] = v;
        if (directional) slotL1[s] = acc[a].tangential(n);
      }
      size_t d = progressSlots.fetch_add(r.size()) + r.size();
      if (in.progress) in.progress("embree", static_cast<double>(doneSlots + d) / std::max<size_t>(1, totalSlots));
    });
    doneSlots += slots;
    progressSlots = 0;

    // The texel means of one per-sample quantity into `into` (only texels wanted and valid).
    auto resolve = [&](Lightmap& into, const char* what, auto&& sampleValue) {
      for (size_t t = 0; t < ts.layerSize(); ++t) {
        glm::vec3 value;
        if (!wanted(t)) continue;
        if (!texelMean(ts, t, sampleValue, value)) continue;
        if (!ts.valid.empty() && ts.valid[t] == 0) continue;
        if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z))
          throw Error(ErrorCode::NumericError, in.scene.sourcePath,
                      std::string("embree backend produced a non-finite ") + what + " at page " +
                          std::to_string(ts.page) + " texel " + std::to_string(t % ts.width) + "," +
                          std::to_string(t / ts.width));
        into.texels[t] = value;
        into.valid[t] = 1;
      }
    };
    resolve(map, "value", [&](size_t s) { return slotValue[s]; });
    maps.push_back(std::move(map));
    if (directional)
      for (int k = 0; k < 3; ++k) {
        Lightmap axis = blankLightmap(ts);
        resolve(axis, "directional value", [&](size_t s) { return slotL1[s][k]; });
        (*request.directional)[k].push_back(std::move(axis));
      }
  }
  if (in.progress) in.progress("embree", 1.0);
  return maps;
}

}  // namespace irbake
