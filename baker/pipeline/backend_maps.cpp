// The evaluator's calls (the VPL blocks into the exact sums, the punctual lights' direct light, the
// reference) and the maps made of them: the classes mixed, the sky added.
#include <algorithm>

#include <tbb/parallel_for.h>

#include "common/error.h"
#include "pipeline/bake_state.h"
#include "sampling/sampling.h"
#include "stages/interleave/interleaved_sampling.h"

namespace irbake {
namespace {

// The evaluation flags each backend call gets, decided here once: VPL blocks evaluate the clamped VPL sum
// only, the direct call the punctual lights only, and no backend compensates the clamp (that is its own
// stage, stages/compensation, after either backend).
VplEvalOptions vplBlockEval(const VplEvalOptions& eval) {
  VplEvalOptions e = eval;
  e.includeDirect = false;
  e.biasCompensation = false;
  return e;
}
VplEvalOptions directEval(const VplEvalOptions& eval) {
  VplEvalOptions e = eval;
  e.includeVpls = false;
  e.biasCompensation = false;
  return e;
}

// One call of the VPL evaluator; with l1, the same pass also gives the L1 pages (--directional).
std::vector<Lightmap> runVplBackend(BakeState& s, const BakeInputs& in, L1Pages* l1 = nullptr) {
  EvaluationRequest request;
  request.directional = l1;
  std::vector<Lightmap> maps = s.evaluator->evaluate(in, request);
  ++s.interleaveStats.backendCalls;
  return maps;
}

// One direct call over the lights marked in `lights` (empty: all), or blank pages (none).
std::vector<Lightmap> directCall(BakeState& s, L1Pages* l1, const std::vector<uint8_t>& lights, bool none = false) {
  if (!none && s.plan.eval.includeDirect && !s.scene.lights.empty()) {
    const VplSet noVpls;
    VplEvalOptions e = directEval(s.plan.eval);
    e.directLights = lights;
    return runVplBackend(s, inputs(s, s.texels, noVpls, e), l1);
  }
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : s.texels) {
    maps.push_back(blankLightmap(ts));
    maps.back().valid = ts.valid;
  }
  if (l1)
    for (auto& axis : *l1) axis = maps;
  return maps;
}

// The cut lights' left-out light for the punctual lights' pages, traced before their shadow edges (which weigh
// a texel's jump against it) and added after them (they refine the lights within reach), before D is kept for the
// final gather. The L1 pages keep the lights within reach: the tail comes from many far directions. Lights left
// out of the map keep their cut.
LightTailPages lightTailStage(BakeState& s, StageContext& ctx, const std::vector<Lightmap>& maps) {
  if (!s.plan.eval.includeDirect || !s.lightGrid || !s.lightGrid->culls() || s.lightReach.cutLights() == 0) return {};
  LightTailPages tail;
  ctx.timed("lightTail", [&] {
    LightTailOptions o = s.options.lightTail;
    o.seed = hashSeed(s.options.walk.seed, 0x7a11);
    tail = traceLightTail(ctx.inputs, maps, o, s.plan.leftOut);
    s.lightTail = tail.stats;
    ctx.report["lightTail"] = s.lightTail.toJson();
    ctx.report["lightTail"]["samples"] = o.samples;
  });
  return tail;
}

std::vector<Lightmap> referenceStage(BakeState& s) { return s.evaluator->evaluate(inputs(s, s.texels, s.vpls, s.plan.eval)); }

// The backend stage's result: punctual lights plus the VPL sums, classes mixed (or the reference). With
// l1 (--directional) the L1 pages alike, each coefficient mixed on its own. Each page's sums are freed
// once rounded: with four coefficients they are the largest thing alive here.
std::vector<Lightmap> backendMaps(BakeState& s, ExactVplSums& sums, nlohmann::json& report, L1Pages* l1) {
  if (s.plan.backend == BackendKind::Reference) return referenceStage(s);
  if (!s.replicates.empty() && !s.halfB.pages.empty()) s.halves = mixedHalves(s, sums);
  std::vector<Lightmap> maps;
  part(s, "direct", [&] { maps = s.cachedDirect.empty() || l1 ? directStage(s, l1) : std::move(s.cachedDirect); });
  s.cachedDirect = {};
  if (maps.size() != s.texels.size() || (l1 && (*l1)[0].size() != s.texels.size()))
    throw Error(ErrorCode::InvalidData, s.scene.sourcePath, "the backend returned " + std::to_string(maps.size()) +
                                                              " pages for " + std::to_string(s.texels.size()));
  // On the punctual lights alone, before D is kept for the final gather: its sources see the same edges.
  StageContext ctx = stageContext(s, report);
  LightTailPages tail = lightTailStage(s, ctx, maps);
  const CutLightPages cut{&tail.added, &tail.unshadowed};
  shadowEdgeStage(ctx, maps, l1, s.leftOutDirect.empty() ? nullptr : &s.leftOutDirect,
                  tail.unshadowed.empty() ? nullptr : &cut);
  ctx.timed("lightTail", [&] { addLightTailPages(tail, maps); });
  tail = {};
  if (s.plan.finalGather) {
    s.directMaps = maps;
    for (size_t p = 0; p < s.directMaps.size(); ++p)
      if (s.directMaps[p].valid.size() != s.directMaps[p].size()) s.directMaps[p].valid = s.texels[p].valid;
    if (l1) s.directL1 = *l1;
  }
  const int coefficients = l1 ? sums.coefficients : 1;
  for (size_t p = 0; p < maps.size(); ++p) {
    std::vector<Lightmap*> pages;  // this page's map, then its L1 pages
    for (int c = 0; c < coefficients; ++c) {
      Lightmap& map = c == 0 ? maps[p] : (*l1)[c - 1][p];
      map.page = static_cast<int>(p);
      if (map.valid.size() != map.size()) map.valid = s.texels[p].valid;
      pages.push_back(&map);
    }
    if (s.blocks.empty()) continue;
    const float share = s.replicates.empty() ? 1.0f : 1.0f / static_cast<float>(s.replicates.size());  // their mean
    std::vector<std::vector<glm::vec3>> vplParts(coefficients, std::vector<glm::vec3>(s.texels[p].layerSize()));
    std::vector<const std::vector<glm::vec3>*> parts;
    for (int c = 0; c < coefficients; ++c) {
      tbb::parallel_for(size_t(0), vplParts[c].size(), [&](size_t t) { vplParts[c][t] = sums.value(p, t, c) * share; });
      parts.push_back(&vplParts[c]);
    }
    std::vector<uint8_t> vplValid = std::move(sums.pages[p].valid);
    sums.pages[p] = {};
    addMixedClasses(s.texels[p], s.plan.interleave, parts, vplValid, pages, s.surfaceFilters.get());
  }
  return maps;
}

}  // namespace

void evaluateBlock(BakeState& s, size_t index, ExactVplSums& sums, ProgressCallback progress) {
  const VplBlock& block = s.blocks[index];
  const VplSet& classSet = s.classVpls[block.replicate][static_cast<size_t>(block.vplClass)];
  VplSet set;
  set.meanReflectivity = classSet.meanReflectivity;
  set.bounces = classSet.bounces;
  set.emittedPower = classSet.emittedPower;
  set.vpls.assign(classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.begin),
                  classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.end));
  const std::vector<TexelSamples>& pages = pagesOf(s, block.vplClass);
  L1Pages l1;
  const std::vector<Lightmap> maps =
      runVplBackend(s, inputs(s, pages, set, vplBlockEval(s.plan.eval), std::move(progress)), s.plan.directional ? &l1 : nullptr);
  const int n = s.plan.interleave, cx = block.vplClass % n, cy = block.vplClass / n;
  for (size_t p = 0; p < maps.size() && p < s.texels.size(); ++p) {
    const Lightmap& m = maps[p];
    const int fullWidth = s.texels[p].width;
    for (int y = 0; y < m.height; ++y)
      for (int x = 0; x < m.width; ++x) {
        const size_t ct = static_cast<size_t>(y) * m.width + x;
        if (ct >= m.valid.size() || !m.valid[ct]) continue;
        const size_t t = static_cast<size_t>(n * y + cy) * fullWidth + (n * x + cx);
        glm::vec3 value[ExactVplSums::kMaxCoefficients] = {m.texels[ct]};  // L0, then L1x, L1y, L1z
        if (s.plan.directional)
          for (int k = 0; k < 3; ++k) value[1 + k] = l1[k][p].texels[ct];
        if (!sums.add(p, t, value) || (block.replicate % 2 == 1 && !s.halfB.add(p, t, value)))
          throw Error(ErrorCode::NumericError, s.scene.sourcePath,
                      "VPL block " + std::to_string(index) + " gave a non-finite or absurd value (≥ 2^40) at page " +
                          std::to_string(p) + " texel " + std::to_string(t % fullWidth) + "," +
                          std::to_string(t / fullWidth));
      }
  }
}

// Punctual lights on every texel, exact and unfiltered (blank valid pages when there are none); with l1,
// their L1 pages too. With lights left out of the map (plan.leftOut) they are evaluated apart, into
// leftOutDirect, and added: the stages after read every light's direct light, the written map lacks theirs.
std::vector<Lightmap> directStage(BakeState& s, L1Pages* l1) {
  if (s.plan.leftOut.empty()) return directCall(s, l1, {});
  std::vector<uint8_t> written(s.plan.leftOut.size());
  for (size_t i = 0; i < written.size(); ++i) written[i] = !s.plan.leftOut[i];
  std::vector<Lightmap> maps = std::find(written.begin(), written.end(), 1) != written.end() ? directCall(s, nullptr, written)
                                                                                              : directCall(s, nullptr, {}, true);
  s.leftOutDirect = directCall(s, nullptr, s.plan.leftOut);
  for (size_t p = 0; p < maps.size() && p < s.leftOutDirect.size(); ++p)
    for (size_t t = 0; t < maps[p].size() && t < s.leftOutDirect[p].size(); ++t) maps[p].texels[t] += s.leftOutDirect[p].texels[t];
  return maps;
}

void mapsFromSums(BakeState& s, ExactVplSums sums, BakeResult& r, nlohmann::json& report) {
  timed(s, "backend", [&] {
    part(s, "maps", [&] { r.maps = backendMaps(s, sums, report, s.plan.directional ? &r.directional : nullptr); });
  });
  StageContext ctx = stageContext(s, report);
  // The estimate's second sky trace once: a round of paths traces the same sky again.
  std::vector<Lightmap> sky;
  const bool measure = !s.halves[0].empty() && !s.skyNoiseMeasured;
  skyStage(ctx, r.maps, s.directMaps, measure ? &sky : nullptr);
  if (!sky.empty()) timed(s, "errorEstimate", [&] { skyRayNoise(s, sky); });
}

}  // namespace irbake
