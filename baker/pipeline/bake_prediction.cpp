// The preflight: atlas estimate, plan, cost and warnings, before any unwrapping or tracing.
#include "pipeline/bake_prediction.h"

#include <cstdio>

#include <tbb/global_control.h>

#include "atlas/atlas_from_bake.h"
#include "common/error.h"
#include "common/log.h"
#include "pipeline/ray_pilot.h"

namespace irbake {

namespace {

// Restores the log level when it goes: the plan settles its choices quietly here (the bake logs its own).
struct QuietLog {
  log::Level before = log::level();
  QuietLog() {
    if (before < log::Level::Warn) log::setLevel(log::Level::Warn);
  }
  ~QuietLog() { log::setLevel(before); }
};

constexpr double kMiBPerGB = 1e9 / (1024.0 * 1024.0);

std::string gbText(double mib) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g GB", mib / kMiBPerGB);
  return text;
}

// The choices the bake makes from what it builds, as the plan shows them before it.
void markSettledAtBake(BakePlan& plan, const BakeOptions& options, const AtlasEstimate& atlas, bool probedGl) {
  const bool automaticDensity = !(options.atlas.texelsPerUnit > 0.0);
  plan.settle("texels-per-unit", atlas.texelsPerUnit,
              automaticDensity ? "predicted from the surface area (the atlas settles it at bake)" : "asked for",
              automaticDensity);
  if (probedGl)
    for (const char* key : {"backend", "compensation-overlap"})
      if (plan.choices.count(key)) plan.choices[key].reason += " (predicted: the GL probe is settled at bake)";
  const bool vpls = plan.backend != BackendKind::Reference && options.eval.includeVpls;
  if (!vpls) return;
  plan.settle("bounces", kSettledAtBake, "the walk's light decides", !options.walk.maxBounces);
  plan.settle("walk-split", kSettledAtBake, "the walk's bounce-1 light decides", !options.walk.split);
  if (plan.finalGather && !options.vplImportance.candidateFactor)
    plan.settle("vpl-importance", kSettledAtBake, "the walk's pilot decides");
  if (options.clamp == ClampMode::Derived) plan.settle("clamp", kSettledAtBake, "derived from the walk's VPLs");
  if (!options.interleave) plan.settle("interleave", kSettledAtBake, "from the texel spacing and the clamp radius");
  if (!options.lightModes.empty()) plan.settle("light-modes", kSettledAtBake, "shadow-mask channels need the texels");
}

std::vector<std::string> predictedWarnings(const Scene& scene, const BakeOptions& options, const AtlasEstimate& atlas) {
  std::vector<std::string> warnings;
  for (const std::string& w : atlas.warnings) warnings.push_back("atlas: " + w);
  if (options.atlas.maxTexels > 0 && atlas.pageTexels > double(options.atlas.maxTexels))
    warnings.push_back("atlas: about " + std::to_string(long(atlas.pageTexels)) + " page texels predicted, over --max-texels " +
                       std::to_string(options.atlas.maxTexels) + ": the bake may refuse the density");
  const std::string seeThrough = seeThroughMaterials(scene);
  if (!seeThrough.empty()) warnings.push_back(seeThrough + ": its texels go to rays, and the final gather stays off");
  return warnings;
}

}  // namespace

double bakeCores() {
  return double(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

nlohmann::json BakePrediction::toJson() const {
  return {{"atlas", {{"texelsPerMetre", atlas.texelsPerUnit}, {"texels", atlas.texels}, {"pageTexels", atlas.pageTexels},
                     {"pageSize", atlas.pageSize}, {"pages", atlas.pages}}},
          {"plan", plan.toJson()},
          {"inputs", inputs.toJson()},
          {"prediction", cost.toJson()},
          {"warnings", warnings}};
}

void weighRays(BakePrediction& p, const Scene& scene, const RayTracer& rt) {
  const RayPilot pilot = measureRayPilot(scene, rt);
  p.inputs.rayCost = pilot.rayCost;
  p.inputs.pilotHitFraction = pilot.hitFraction;
  p.cost = predictCost(p.inputs);
}

BakePrediction predictBake(const Scene& scene, const BakeOptions& options, double cores, bool weighRays) {
  const QuietLog quiet;
  BakePrediction p;
  checkLightModes(options, scene);
  // --atlas-from: the earlier bake's pages, read back (the bake checks the geometry against them)
  p.atlas = options.atlasFrom.empty() ? estimateAtlas(scene, options.atlas)
                                      : estimateBakedAtlas(scene, readBakedAtlas(options.atlasFrom));
  bool probedGl = false;
  p.plan = planBake(scene, hasTransmissiveMaterial(scene), options, [&] {
    probedGl = true;
    return GlProbe{};  // a working software renderer, the machines' usual case
  });
  markSettledAtBake(p.plan, options, p.atlas, probedGl);
  p.inputs = costInputs(scene, p.atlas, p.plan, options.lightCull, cores);
  p.cost = predictCost(p.inputs);
  if (weighRays) irbake::weighRays(p, scene, RayTracer(scene));
  p.warnings = predictedWarnings(scene, options, p.atlas);
  return p;
}

void checkMemoryLimit(const BakePrediction& prediction, double maxMemoryGB, const std::string& scenePath) {
  if (!(maxMemoryGB > 0.0)) return;
  const double peak = prediction.cost.memoryPeakMiB;
  if (peak <= maxMemoryGB * kMiBPerGB) return;
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g GB", maxMemoryGB);
  throw Error(ErrorCode::Usage, scenePath,
              "the bake is predicted to need " + gbText(peak) + " of memory at its peak, over --max-memory " + limit +
                  " (about " + std::to_string(long(prediction.atlas.pageTexels)) + " page texels, " +
                  std::to_string(long(prediction.inputs.triangles)) +
                  " triangles): lower the density (--texels-per-unit, --quality preview) or raise --max-memory");
}

}  // namespace irbake
