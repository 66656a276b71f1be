#include "stages/shadow_edges/shadow_edges.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "common/progress.h"
#include "stages/shadow_edges/texel_square.h"
#include "transport/geometry_term.h"

namespace irbake {

namespace {

float channelMax(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// One page's cut light (CutLightPages), or none.
struct PageCut {
  const std::vector<glm::vec3>* shadowed = nullptr;
  const std::vector<float>* unshadowed = nullptr;
  glm::vec2 at(size_t t) const {  // (shadowed, unshadowed) at texel t
    if (!unshadowed || t >= unshadowed->size() || t >= shadowed->size()) return glm::vec2(0.0f);
    return glm::vec2(float(channelMean((*shadowed)[t])), (*unshadowed)[t]);
  }
};

// The visible share with the cut lights' left-out light (shadowed, unshadowed) on both sides.
float shareWith(float visible, float unshadowed, glm::vec2 cut) {
  return unshadowed + cut.y > 0.0f ? (visible + cut.x) / (unshadowed + cut.y) : -1.0f;
}

// A light facing a texel's centre: its light there (channel max) and its contribution.
struct Facing {
  float value;
  uint32_t light;
  PunctualContribution c;
};

// The lights near x that give it anything, with their light there, into facing; returns all of their light.
glm::vec3 facingLights(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, std::vector<Facing>& facing) {
  facing.clear();
  glm::vec3 unshadowed(0.0f);
  for (uint32_t i : in.lightsNear(x)) {
    const PunctualContribution c = punctualDirect(in.scene.lights[i], x, n);
    unshadowed += c.mapValue;
    if (c.mapValue != glm::vec3(0.0f)) facing.push_back({channelMax(c.mapValue), i, c});
  }
  return unshadowed;
}

// The faintest facing lights, together under `budget` (channel max, the centre's), go first: facing sorted by
// their light, and how many of its first entries are faint. All of them shadowed at once, or lit, cannot move
// the texel by more than the budget.
size_t sortFaintFirst(std::vector<Facing>& facing, float budget) {
  std::sort(facing.begin(), facing.end(), [](const Facing& a, const Facing& b) {
    return a.value < b.value || (a.value == b.value && a.light < b.light);
  });
  size_t faint = 0;
  for (; faint < facing.size() && facing[faint].value <= budget; ++faint) budget -= facing[faint].value;
  return faint;
}

// Whether a shadow or a lit strip narrower than a texel crosses texel t's square although its centre agrees with
// its neighbours (between two centres, where no neighbour sees a jump): the visible share of 2×2 sub-points on
// the centre's triangle against the centre's, both traced alike, differ by more than `jump`. facing: the lights
// facing the centre x, unshadowed: their light there (channel max). The faintest lights, together under
// faintShare × `jump` of the centre's unshadowed light (the cut's included), count as visible on both sides with
// their centre's light, no ray and no evaluation at the sub-points: all of them shadowed at once cannot make the
// probe jump, and a level's many faint lamps cost nothing. Without a brighter light there is nothing to probe.
bool subTexelJump(const BakeInputs& in, const TexelSamples& ts, size_t t, const glm::vec3& x, const glm::vec3& n,
                  float unshadowed, float jump, float faintShare, glm::vec2 cut, std::vector<Facing>& facing,
                  std::vector<uint32_t>& bright) {
  const RayTracer& rt = in.rayTracer;
  const float eps = rt.epsilon();
  auto lit = [&](const glm::vec3& origin, const PunctualContribution& c) {
    const float tmax = shadowRayLength(c, eps);
    return !(tmax > 0.0f) || !rt.occluded(origin, c.toLight, 0.0f, tmax);
  };
  glm::vec3 centre[2] = {glm::vec3(0.0f), glm::vec3(0.0f)}, faintLight(0.0f);  // visible, unshadowed
  const size_t faint = sortFaintFirst(facing, faintShare * jump * (unshadowed + cut.y));
  bright.clear();
  for (size_t k = 0; k < facing.size(); ++k) {
    const Facing& f = facing[k];
    centre[1] += f.c.mapValue;
    if (k < faint) {
      faintLight += f.c.mapValue;
    } else {
      bright.push_back(f.light);
      if (lit(x + n * eps, f.c)) centre[0] += f.c.mapValue;
    }
  }
  if (bright.empty()) return false;
  centre[0] += faintLight;
  auto visit = [&](const glm::vec3& xs, const glm::vec3& nx, const glm::vec3& origin, glm::vec3* values) {
    values[0] += faintLight, values[1] += faintLight;
    for (uint32_t i : bright) {
      const PunctualContribution c = punctualDirect(in.scene.lights[i], xs, nx);
      values[1] += c.mapValue;
      if (c.mapValue != glm::vec3(0.0f) && lit(origin, c)) values[0] += c.mapValue;
    }
    return true;  // no covered test here: the full refinement drops what a surface cuts off
  };
  SquareMean mean;
  if (!averageOverTexelSquare(in, ts, t, 2, nullptr, visit, mean) || mean.kept == 0) return false;
  const float k = float(mean.kept);
  const float probe = shareWith(channelMax(glm::vec3(mean.sum[0])) / k, channelMax(glm::vec3(mean.sum[1])) / k, cut);
  const float here = shareWith(channelMax(centre[0]), channelMax(centre[1]), cut);
  return probe >= 0.0f && here >= 0.0f && std::abs(probe - here) > jump;
}

// Per texel, the share of the punctual lights' unshadowed value that reached it (their visibility, weighted by
// each light's value; -1 where no light faces the texel). Smooth falloff (a point light's 1/r²) keeps it at 1;
// a shadow edge makes it jump. cut: the page's cut lights' left-out light per texel, or none. In the same pass,
// from the same evaluation of the lights, probed: 1 where subTexelJump finds a jump within the texel.
struct TexelShares {
  std::vector<float> share;
  std::vector<uint8_t> probed;
};
TexelShares visibleShare(const BakeInputs& in, const TexelSamples& ts, const Lightmap& map,
                         const std::vector<uint8_t>& valid, const PageCut& cut, const ShadowEdgeOptions& options) {
  TexelShares out{std::vector<float>(map.size(), -1.0f), std::vector<uint8_t>(map.size(), 0)};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, map.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Facing> facing;
    std::vector<uint32_t> bright;
    for (size_t t = r.begin(); t != r.end(); ++t) {
      if (!valid[t] || ts.positionWeight[t].w <= 0.0f) continue;
      glm::vec3 x(ts.positionWeight[t]);
      if (ts.primitive[t] < in.scene.primitives.size()) x = in.rayTracer.insetPoint(ts.primitive[t], ts.triangle[t], x);
      const glm::vec3 n(ts.normal[t]);
      const glm::vec3 unshadowed = facingLights(in, x, n, facing);
      out.share[t] = shareWith(channelMax(map.texels[t]), channelMax(unshadowed), cut.at(t));
      if (out.share[t] >= 0.0f)
        out.probed[t] = subTexelJump(in, ts, t, x, n, channelMax(unshadowed), options.jump, options.faintShare,
                                     cut.at(t), facing, bright) ? 1 : 0;
    }
  });
  return out;
}

// A thread's room for refineTexel.
struct RefineRoom {
  std::vector<Facing> facing;
  std::vector<uint8_t> faint;  // per scene light, 1: faint at the texel being refined
};

// Texel t's mean of the lights' shadowed light over its square (averageOverTexelSquare, S×S sub-points): each
// sub-point traces the lights that reach it, except the faintest at the centre, together under faintShare × `jump`
// of the centre's unshadowed light (the cut's included, as the probe's): those are traced once, at the centre, and
// their light there counts at every sub-point (all of them shadowed at once, or lit, cannot move the texel by
// more). values[1]: the part's lights alone.
bool refineTexel(const BakeInputs& in, const TexelSamples& ts, size_t t, const SquareTriangles& squares,
                 const ShadowEdgePart* part, const ShadowEdgeOptions& options, glm::vec2 cut, RefineRoom& room,
                 SquareMean& mean) {
  const RayTracer& rt = in.rayTracer;
  const float eps = rt.epsilon();
  // Whether c's light reaches origin, and in v what arrives (through what transmits).
  auto arrives = [&](const glm::vec3& origin, const PunctualContribution& c, glm::vec3& v) {
    const float tmax = shadowRayLength(c, eps);
    if (tmax > 0.0f && rt.occluded(origin, c.toLight, 0.0f, tmax)) return false;
    v = tmax > 0.0f && rt.hasTransmission() ? c.mapValue * rt.transmittance(origin, c.toLight, 0.0f, tmax) : c.mapValue;
    return true;
  };
  glm::vec3 faintLight[2] = {glm::vec3(0.0f), glm::vec3(0.0f)};  // the faint lights' at the centre: all, the part's
  room.facing.clear();
  if (ts.positionWeight[t].w > 0.0f && ts.primitive[t] < in.scene.primitives.size()) {
    const glm::vec3 x = rt.insetPoint(ts.primitive[t], ts.triangle[t], glm::vec3(ts.positionWeight[t]));
    const glm::vec3 n(ts.normal[t]);
    const glm::vec3 unshadowed = facingLights(in, x, n, room.facing);
    const float budget = options.faintShare * options.jump * (channelMax(unshadowed) + cut.y);
    room.facing.resize(sortFaintFirst(room.facing, budget));
    for (const Facing& f : room.facing) {
      room.faint[f.light] = 1;
      glm::vec3 v;
      if (!arrives(x + n * eps, f.c, v)) continue;
      faintLight[0] += v;
      if (part && (*part->lights)[f.light]) faintLight[1] += v;
    }
  }
  auto visit = [&](const glm::vec3& xs, const glm::vec3& nx, const glm::vec3& origin, glm::vec3* values) {
    values[0] += faintLight[0], values[1] += faintLight[1];
    bool anyLit = false;  // of the lights traced here: a sub-point they all miss gets the covered test
    for (uint32_t i : in.lightsNear(xs)) {
      if (room.faint[i]) continue;
      const PunctualContribution c = punctualDirect(in.scene.lights[i], xs, nx);
      glm::vec3 v;
      if (c.mapValue == glm::vec3(0.0f) || !arrives(origin, c, v)) continue;
      anyLit = true;
      values[0] += v;
      if (part && (*part->lights)[i]) values[1] += v;
    }
    return anyLit;
  };
  const bool sampled = averageOverTexelSquare(in, ts, t, options.subSamples, &squares, visit, mean);
  for (const Facing& f : room.facing) room.faint[f.light] = 0;
  return sampled;
}

}  // namespace

ShadowEdgeStats refineShadowEdges(const BakeInputs& in, std::vector<Lightmap>& directPages,
                                  const ShadowEdgeOptions& options, const ShadowEdgePart* part,
                                  const CutLightPages* cutLight) {
  ShadowEdgeStats stats;
  const int S = options.subSamples;
  if (S <= 1 || in.scene.lights.empty()) return stats;
  Stopwatch watch;
  std::atomic<size_t> edges{0}, points{0}, dropped{0};
  for (size_t p = 0; p < directPages.size() && p < in.texels.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    Lightmap& map = directPages[p];
    if (ts.supersample != 1 || map.size() != ts.layerSize()) continue;
    const std::vector<uint8_t>& valid = map.valid.size() == map.size() ? map.valid : ts.valid;
    PageCut cut;
    if (cutLight && cutLight->shadowed && cutLight->unshadowed && p < cutLight->unshadowed->size() &&
        p < cutLight->shadowed->size())
      cut = {&(*cutLight->shadowed)[p], &(*cutLight->unshadowed)[p]};
    const TexelShares shares = visibleShare(in, ts, map, valid, cut, options);
    std::vector<uint8_t> edge = edgeTexels(shares.share, ts.width, ts.height, options.jump);
    for (size_t t = 0; t < edge.size() && t < shares.probed.size(); ++t) edge[t] |= shares.probed[t];
    const SquareTriangles squares = squareTriangles(in.scene, ts, edge);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.layerSize(), 256), [&](const tbb::blocked_range<size_t>& r) {
      RefineRoom room;
      room.faint.assign(in.scene.lights.size(), 0);
      for (size_t t = r.begin(); t != r.end(); ++t) {
        if (!edge[t]) continue;
        SquareMean mean;
        const bool sampled = refineTexel(in, ts, t, squares, part, options, cut.at(t), room, mean);
        points += static_cast<size_t>(mean.points);
        dropped += static_cast<size_t>(mean.dropped);
        if (!sampled || mean.kept == 0) continue;  // no sub-point on the chart in the square: the centre's value stays
        map.texels[t] = glm::vec3(mean.sum[0] / double(mean.kept));
        if (part) (*part->pages)[p].texels[t] = glm::vec3(mean.sum[1] / double(mean.kept));
        ++edges;
      }
    });
  }
  stats.edgeTexels = edges;
  stats.subPoints = points;
  stats.droppedInside = dropped;
  stats.seconds = watch.seconds();
  return stats;
}

}  // namespace irbake
