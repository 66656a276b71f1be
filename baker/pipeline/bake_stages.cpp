// The stages after the evaluators, each reading the plan and writing its own report object.
#include "pipeline/bake_stages.h"

#include <algorithm>

#include "common/progress.h"
#include "stages/gather/final_gather.h"
#include "stages/probes/light_probes.h"
#include "stages/shadow_edges/shadow_edges.h"
#include "stages/sky/sky_light.h"

namespace irbake {

void StageContext::timed(const char* name, const std::function<void()>& stage) {
  Stopwatch watch;
  stage();
  seconds[name] = seconds.value(name, 0.0) + watch.seconds();
  cpuSeconds[name] = cpuSeconds.value(name, 0.0) + watch.cpuSeconds();
}

void shadowEdgeStage(StageContext& ctx, std::vector<Lightmap>& maps, L1Pages* l1, std::vector<Lightmap>* leftOut,
                     const CutLightPages* cutLight) {
  const BakePlan& plan = ctx.plan;
  if (!plan.eval.includeDirect || ctx.scene.lights.empty() || plan.shadowEdges.subSamples <= 1) return;
  // The L1 pages keep the centre's direction, scaled with the value per channel so that |L1| stays within
  // what L0 allows (a refined texel's light comes from the same lights; where the centre was dark, L1 is 0).
  const Stopwatch watch;
  std::vector<Lightmap> before;
  if (l1) before = maps;
  ShadowEdgePart part{&plan.leftOut, leftOut};
  const ShadowEdgeStats st = refineShadowEdges(ctx.inputs, maps, plan.shadowEdges, leftOut ? &part : nullptr, cutLight);
  for (size_t p = 0; l1 && p < maps.size(); ++p)
    for (size_t t = 0; t < maps[p].size(); ++t) {
      const glm::vec3 &was = before[p].texels[t], &now = maps[p].texels[t];
      if (was == now) continue;
      const glm::vec3 scale(was.x > 0.0f ? now.x / was.x : 0.0f, was.y > 0.0f ? now.y / was.y : 0.0f,
                            was.z > 0.0f ? now.z / was.z : 0.0f);
      for (int k = 0; k < 3; ++k) (*l1)[k][p].texels[t] *= scale;
    }
  ctx.seconds["shadowEdges"] = st.seconds;
  ctx.cpuSeconds["shadowEdges"] = watch.cpuSeconds();
  ctx.report["shadowEdges"] = {{"subSamples", plan.shadowEdges.subSamples}, {"edgeTexels", st.edgeTexels},
                               {"subPoints", st.subPoints}, {"droppedInside", st.droppedInside}};
}

void skyStage(StageContext& ctx, std::vector<Lightmap>& maps, std::vector<Lightmap>& direct, std::vector<Lightmap>* traced) {
  const Scene& scene = ctx.scene;
  const BakePlan& plan = ctx.plan;
  if (!scene.environment.present() || plan.backend == BackendKind::Reference) return;
  ctx.timed("sky", [&] {
    SkyLightStats stats;
    // An environment map's light goes into D as well under the final gather (its importance sampling beats
    // the gather's cosine rays). A uniform sky stays out of D: the final gather's rays that leave the scene
    // count it.
    const bool intoDirect = plan.finalGather && direct.size() == maps.size() && !plan.skyByGather;
    if (intoDirect || traced) {  // traced once into blank pages, added where it goes
      std::vector<Lightmap> sky = maps;
      for (Lightmap& m : sky) std::fill(m.texels.begin(), m.texels.end(), glm::vec3(0.0f));
      addSkyLight(ctx.inputs, sky, plan.sky, &stats);
      for (size_t p = 0; p < maps.size(); ++p)
        for (size_t t = 0; t < maps[p].size(); ++t) {
          maps[p].texels[t] += sky[p].texels[t];
          if (intoDirect) direct[p].texels[t] += sky[p].texels[t];
        }
      if (traced) *traced = std::move(sky);
    } else {
      addSkyLight(ctx.inputs, maps, plan.sky, &stats);
    }
    nlohmann::json& report = ctx.report["sky"] = stats.toJson();
    report["uniform"] = scene.environment.isUniform();
    report["source"] = scene.environment.source();
    const glm::dvec3 integral = scene.environment.integral();
    report["integral"] = nlohmann::json::array({integral.x, integral.y, integral.z});
  });
}

void compensationStage(StageContext& ctx, std::vector<Lightmap>& maps, L1Pages* l1,
                       std::unique_ptr<ClampGather> traced) {
  BakePlan& plan = ctx.plan;
  if (!plan.compensate) return;
  ctx.timed("compensation", [&] {  // with an overlapped trace: the sweeps (and any trace not yet done)
    ClampCompensationStats stats;
    if (ctx.progress) ctx.progress("compensate", 0.0);  // coarse: start and end of the stage
    std::unique_ptr<ClampGather> g = traced ? std::move(traced) : std::make_unique<ClampGather>(ctx.inputs, plan.compensation);
    g->apply(maps, &stats);
    if (l1 && !plan.finalGather) g->applyDirectional(maps, *l1);  // the final gather writes the L1 itself
    if (ctx.progress) ctx.progress("compensate", 1.0);
    ctx.seconds["compensationTrace"] = g->traceSeconds();
    if (!ctx.askedCompensation.filterRadius)
      plan.settle("comp-filter", stats.filterRadius, "where the rays per sample are few, within 1/20 of the clamp radius");
    ctx.report["compensation"] = stats.toJson();
  });
}

void finalGatherStage(StageContext& ctx, const std::vector<Lightmap>& direct, const L1Pages* directL1,
                      std::vector<Lightmap>& maps, L1Pages* l1) {
  if (!ctx.plan.finalGather || direct.size() != maps.size()) return;
  ctx.timed("finalGather", [&] {
    FinalGatherStats stats;
    if (ctx.progress) ctx.progress("gather", 0.0);
    finalGather(ctx.inputs, direct, maps, ctx.plan.gather, &stats, l1 ? directL1 : nullptr, l1);
    if (ctx.progress) ctx.progress("gather", 1.0);
    ctx.report["finalGather"] = stats.toJson();
  });
}

void leaveOutDirect(std::vector<Lightmap>& maps, const std::vector<Lightmap>& leftOut) {
  for (size_t p = 0; p < maps.size() && p < leftOut.size(); ++p)
    for (size_t t = 0; t < maps[p].size() && t < leftOut[p].size(); ++t)
      maps[p].texels[t] = glm::max(maps[p].texels[t] - leftOut[p].texels[t], glm::vec3(0.0f));
}

ShadowMaskPages shadowMaskStage(StageContext& ctx) {
  ShadowMaskPages pages;
  if (ctx.plan.maskChannels.used() == 0) return pages;
  ctx.timed("shadowMask", [&] {
    ShadowMaskStats stats;
    if (ctx.progress) ctx.progress("shadowmask", 0.0);
    pages = bakeShadowMask(ctx.inputs, ctx.plan.maskChannels, ctx.plan.shadowMask, &stats);
    if (ctx.progress) ctx.progress("shadowmask", 1.0);
    ctx.report["shadowMask"] = stats.toJson();
    ctx.report["shadowMask"]["assignment"] = ctx.plan.maskChannels.toJson(ctx.scene);
  });
  return pages;
}

void shadowMaskPostStage(StageContext& ctx, ShadowMaskPages& mask) {
  ctx.timed("shadowMaskPost", [&] {
    postProcess(ctx.scene, mask.rgb, ctx.plan.post);
    if (!mask.alpha.empty()) postProcess(ctx.scene, mask.alpha, ctx.plan.post);
  });
}

// The evaluators' passes accumulated the L1 pages of the punctual lights and VPLs beside the map, and the
// clamp compensation added its share (ClampGather::applyDirectional): the sky's part is traced here.
void directionalStage(StageContext& ctx, L1Pages& axes) {
  ctx.timed("directional", [&] {
    if (ctx.scene.environment.present()) addSkyLightDirectional(ctx.inputs, axes, ctx.plan.sky);
    PostStats stats;
    for (auto& pages : axes) stats = postProcess(ctx.scene, pages, ctx.plan.post);
    ctx.report["directional"] = {{"pages", axes[0].size() * 3}, {"seamMismatchAfter", stats.seamMismatchAfter}};
  });
}

PostStats postStage(StageContext& ctx, std::vector<Lightmap>& maps) {
  PostStats stats;
  ctx.timed("post", [&] {
    if (ctx.progress) ctx.progress("post", 0.0);
    stats = postProcess(ctx.scene, maps, ctx.plan.post);
    if (ctx.progress) ctx.progress("post", 1.0);
  });
  return stats;
}

void probeStage(StageContext& ctx, const std::vector<Lightmap>& maps, LightProbeGrid& grid) {
  const ProbeOptions& o = ctx.plan.probes;
  if (!o.enabled || !o.spacing || !o.box) return;
  ctx.timed("probes", [&] {
    if (ctx.progress) ctx.progress("probes", 0.0);
    grid = probeGridOver(*o.box, *o.spacing, o.maxProbes);
    ProbeStats stats;
    bakeLightProbes(ctx.inputs, maps, grid, o, &stats);
    if (ctx.progress) ctx.progress("probes", 1.0);
    ctx.report["probes"] = stats.toJson();
    ctx.report["probes"]["counts"] = {grid.counts.x, grid.counts.y, grid.counts.z};
    ctx.report["probes"]["raysPerProbe"] = o.rays;
  });
}

}  // namespace irbake
