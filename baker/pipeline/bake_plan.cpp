// The bake plan: each automatic choice and cross-stage rule, with its reason.
#include "pipeline/bake_plan.h"
#include "scene/triangle_area.h"

#include <algorithm>
#include <cstdio>

#include "common/error.h"
#include "common/log.h"
#include "pipeline/light_modes.h"
#include "stages/interleave/interleaved_sampling.h"
#include "transport/geometry_term.h"

namespace irbake {

void BakePlan::settle(const std::string& key, nlohmann::json value, const std::string& reason, bool automatic) {
  if (automatic) log::info("plan: " + key + " = " + (value.is_string() ? value.get<std::string>() : value.dump()) + " (" + reason + ")");
  choices[key] = PlanChoice{std::move(value), reason, automatic};
}

nlohmann::json BakePlan::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [key, c] : choices) j[key] = {{"value", c.value}, {"reason", c.reason}, {"automatic", c.automatic}};
  return j;
}

std::string seeThroughMaterials(const Scene& scene) {
  for (const Primitive& p : scene.primitives) {
    const Material& m = scene.materials[p.material];
    if (m.alphaMode == AlphaMode::Mask) return "material '" + m.name + "' is alpha MASK";
    if (m.alphaMode == AlphaMode::Blend) return "material '" + m.name + "' is alpha BLEND (see-through)";
    if (m.transmission > 0.0f) return "material '" + m.name + "' is transmissive";
  }
  return {};
}

namespace {

const char* onOff(bool on) { return on ? "on" : "off"; }

// --backend auto: GL where it is both right and fast, Embree otherwise.
void settleBackend(BakePlan& plan, const Scene& scene, const BakeOptions& options,
                   const std::function<GlProbe()>& probeGl) {
  plan.backend = options.backend;
  if (plan.backend != BackendKind::Auto) {
    plan.settle("backend", toString(plan.backend), "asked for", false);
    return;
  }
  const AutoBackendChoice choice = chooseAutoBackend(scene.triangleCount(), seeThroughMaterials(scene), probeGl);
  plan.backend = choice.backend;
  plan.settle("backend", toString(plan.backend), choice.reason);
}

// The final gather: on where asked, or (auto) where its rays find every emitter reliably (none, or emitters
// covering at least kGatheredEmitterShare of the surface: in a closed scene a ray meets an emitter with about
// that probability, so small emitters would be found by chance) and no surface is see-through (the gather
// reads the glass's own map, not what lies behind).
constexpr double kGatheredEmitterShare = 0.5;

double emissiveAreaShare(const Scene& scene) {
  double emitting = 0.0, all = 0.0;
  for (const Primitive& p : scene.primitives) {
    const bool emits = scene.materials[p.material].isEmissive();
    for (uint32_t t = 0; t < p.triangleCount(); ++t) {
      const double area = triangleArea(p, t);
      all += area;
      if (emits) emitting += area;
    }
  }
  return all > 0.0 ? emitting / all : 0.0;
}

// Emitters a gather's rays would find only by chance: emissive surfaces covering less than kGatheredEmitterShare.
bool hasSmallEmitters(const Scene& scene) {
  return scene.hasEmissiveSurface() && emissiveAreaShare(scene) < kGatheredEmitterShare;
}

void settleFinalGather(BakePlan& plan, const Scene& scene, const BakeOptions& options) {
  const bool vplBackend = plan.backend != BackendKind::Reference && options.eval.includeVpls;
  const std::string seeThrough = seeThroughMaterials(scene);
  const double emitterShare = emissiveAreaShare(scene);
  const bool smallEmitters = hasSmallEmitters(scene);
  plan.finalGather = vplBackend && (options.finalGather == FinalGatherMode::On ||
                                    (options.finalGather == FinalGatherMode::Auto && !smallEmitters &&
                                     seeThrough.empty()));
  char share[96];
  std::snprintf(share, sizeof share, "emitters cover %.1f%% of the surface", 100.0 * emitterShare);
  std::string reason;
  if (!vplBackend) reason = "no VPLs to gather from";
  else if (options.finalGather != FinalGatherMode::Auto) reason = "asked for";
  else if (smallEmitters) reason = std::string("auto: ") + share + " (its rays would find them by chance)";
  else if (!seeThrough.empty()) reason = "auto: " + seeThrough;
  else if (scene.hasEmissiveSurface()) reason = std::string("auto: ") + share + " (its rays find them)";
  else reason = "auto: no emissive or see-through surface";
  plan.settle("final-gather", onOff(plan.finalGather), reason, options.finalGather == FinalGatherMode::Auto);
}

// The auto walk split's least children per path where the final gather does not run (docs/units.md, "The
// walk's random numbers and the split past bounce 1").
constexpr int kMinSplitWithoutGather = 4;
// There the walk also follows kWalkFactor times the evaluated paths and resamples each bounce to the count
// of a plain walk of those (docs/units.md, "Walking more paths than are evaluated"): the bounces' totals rest
// on the big walk, the evaluation's cost on the kept VPLs. The evaluated paths are the preset's halved, and
// the emitters' VPLs half of those: the final gather is off where emitters are small, so theirs lie close together.
constexpr int kWalkFactorWithoutGather = 8;
constexpr int kEvaluatedPathsDivisor = 2;
constexpr double kEmitterShareWithoutGather = 0.5;

// The walk's paths: finalGatherPaths where the final gather runs (it reads their map averaged).
void settleWalk(BakePlan& plan, const Scene& scene, const BakeOptions& options) {
  plan.walk = options.walk;
  // Without the final gather the VPL sum is the map's bounced light, and its seed-to-seed noise is the deep
  // bounces' few carriers (M_j = N ρ̄^j paths): they fork past bounce 1 even in a closed scene, and the walk
  // follows more paths than are evaluated where emitters are its only sources. A punctual light or a sky
  // leaves VPLs of other powers (a sun's on a closed room's roof), which resampling by power would favour.
  const bool splitDeep = !plan.finalGather && !options.walk.split;
  const bool resample = splitDeep && scene.lights.empty() && !scene.environment.present();
  if (splitDeep) plan.walk.minAutoSplit = std::max(plan.walk.minAutoSplit, kMinSplitWithoutGather);
  if (resample) {
    plan.walk.walkFactor = std::max(plan.walk.walkFactor, kWalkFactorWithoutGather);
    plan.walk.evaluatedEmitterShare = std::min(plan.walk.evaluatedEmitterShare, kEmitterShareWithoutGather);
  }
  // finalGatherPaths is set where the paths were left to the quality preset.
  const bool automatic = options.finalGatherPaths.has_value();
  const bool underGather = plan.finalGather && automatic;
  if (underGather || (automatic && splitDeep && !resample)) plan.walk.paths = *options.finalGatherPaths;
  else if (automatic && resample) plan.walk.paths = std::max(1, options.walk.paths / kEvaluatedPathsDivisor);
  plan.settle("paths", plan.walk.paths,
              !automatic   ? "asked for"
              : underGather ? "the preset's paths under the final gather, which reads their map averaged"
              : resample    ? "half the preset's paths evaluated: the walk follows " +
                                std::to_string(kWalkFactorWithoutGather) + "x as many, forks past bounce 1, and is resampled"
              : splitDeep   ? "the preset's reduced paths: past bounce 1 each forks into at least " +
                                std::to_string(kMinSplitWithoutGather)
                            : "the preset's paths",
              automatic);
  if (resample)
    plan.settle("walk-factor", plan.walk.walkFactor,
                "without the final gather the bounces' totals rest on a walk of this many times the paths, resampled", true);
}

// The clamp compensation and whether its rays run beside the GL evaluator. With the final gather its
// refinement is off and its first rays fewer: the gather replaces the residual at the texel and reads it only
// averaged over its rays one bounce away.
void settleCompensation(BakePlan& plan, const BakeOptions& options, const std::function<GlProbe()>& probeGl) {
  plan.compensate = options.eval.biasCompensation && plan.backend != BackendKind::Reference;
  plan.compensation = options.compensation;
  plan.compensation.seed = options.walk.seed;
  plan.compensation.directional = options.directional && !plan.finalGather;  // the gather writes the L1 itself
  if (plan.finalGather) {
    plan.compensation.refineRays = 0;
    plan.compensation.minRays = std::min(plan.compensation.minRays, 2);
    plan.compensation.filterEachSweep = false;
  }
  if (plan.compensate && plan.finalGather)
    plan.settle("comp-refine", 0, "the final gather replaces the residual at the texel; only the map it reads needs it");
  // On a GPU the compensation's rays (geometry only) are traced on the CPU while GL bakes; not on a software
  // renderer, where the trace and the rasteriser share the cores.
  plan.overlapCompensation = false;
  if (plan.compensate && plan.backend == BackendKind::Gl) {
    const bool software = probeGl().softwareRenderer;
    plan.overlapCompensation = options.overlapCompensation == OverlapCompensation::Always ||
                               (options.overlapCompensation == OverlapCompensation::Auto && !software);
    plan.settle("compensation-overlap", onOff(plan.overlapCompensation),
                options.overlapCompensation != OverlapCompensation::Auto ? "asked for"
                : software ? "a software renderer shares the cores with the rays"
                           : "rays on the CPU while the GPU bakes",
                options.overlapCompensation == OverlapCompensation::Auto);
  }
}

// The sky: a uniform sky in a scene without see-through surfaces is counted by the final gather's escaping
// rays (its cosine rays are the sky stage's own estimator), so the sky stage's light is read only at its hits
// and half its rays do.
void settleSky(BakePlan& plan, const Scene& scene, bool transmission, const BakeOptions& options) {
  plan.sky = options.sky;
  plan.sky.seed = options.walk.seed;
  plan.skyByGather = plan.finalGather && scene.environment.present() && scene.environment.isUniform() &&
                     !transmission;
  if (plan.skyByGather) {
    plan.sky.minRays = std::min(plan.sky.minRays, 4);
    plan.settle("sky-by-gather", "on", "a uniform sky: the final gather's escaping rays count it");
  }
  plan.gather = options.gather;
  plan.gather.seed = options.walk.seed;
  if (plan.skyByGather) plan.gather.missRadiance = scene.environment.uniformRadiance();
}

// A length or ratio in short notation for messages: "0.01", "1e+06", "61.3".
std::string shortNumber(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// --probe-box must meet the scene's bounds widened by their largest side on every axis: the probes over a flat
// floor stand in the air above it, but a box farther than the scene's own size from it lights nothing of it.
void checkProbeBoxMeetsScene(const Bounds3& box, const Bounds3& scene) {
  const glm::vec3 e = scene.extent();
  const float margin = std::max({e.x, e.y, e.z});
  for (int a = 0; a < 3; ++a)
    if (box.max[a] < scene.min[a] - margin || box.min[a] > scene.max[a] + margin) {
      auto point = [](const glm::vec3& p) { return shortNumber(p.x) + "," + shortNumber(p.y) + "," + shortNumber(p.z); };
      throw Error(ErrorCode::Usage, "", "--probe-box " + point(box.min) + "," + point(box.max) +
                                            " does not come within the scene's size (" + shortNumber(margin) +
                                            " m) of its bounds (" + point(scene.min) + " to " + point(scene.max) +
                                            "): its probes would light nothing of it");
    }
}

// The probes' grid: its volume (the box asked for, else the scene's bounds) and spacing, checked here so that a
// spacing too small for the volume is refused before the bake rather than after it.
void settleProbes(BakePlan& plan, const Scene& scene, const BakeOptions& options) {
  plan.probes = options.probes;
  plan.probes.seed = options.walk.seed;
  if (!plan.probes.enabled) return;
  const Bounds3 volume = options.probes.box ? *options.probes.box : scene.bounds();
  if (options.probes.box) checkProbeBoxMeetsScene(volume, scene.bounds());
  const bool automatic = !options.probes.spacing;
  const double count = autoProbeCount(options.probes, scene.lights);
  const float spacing = automatic ? chooseProbeSpacing(volume, count) : *options.probes.spacing;
  const LightProbeGrid grid = probeGridOver(volume, spacing, plan.probes.maxProbes);
  if (static_cast<double>(grid.size()) > static_cast<double>(plan.probes.budget)) {
    const std::string n = std::to_string(grid.size());
    throw Error(ErrorCode::Usage, "", std::string(automatic ? "the automatic probe spacing" : "--probes " + shortNumber(spacing)) +
                                          " gives " + n + " probes, about " + shortNumber(grid.size() / count) +
                                          " times the automatic grid's " + std::to_string(static_cast<long>(count)) +
                                          ", over the probe budget of " + std::to_string(plan.probes.budget) +
                                          ": raise it with --probe-budget " + n + " to bake them, or choose a larger spacing");
  }
  plan.probes.spacing = spacing;
  plan.probes.box = volume;
  const std::string n = std::to_string(static_cast<long>(count));
  const std::string why = !automatic ? "asked for"
                          : "about " + n + " probes over the volume" +
                                (count == options.probes.autoProbesSun ? " (a directional light's shadows)" : "") +
                                ": cbrt(volume / " + n + ")";
  plan.settle("probe-spacing", spacing,
              why + ": " + std::to_string(grid.counts.x) + " x " + std::to_string(grid.counts.y) + " x " +
                  std::to_string(grid.counts.z) + " probes",
              automatic);
}

}  // namespace

BakePlan planBake(const Scene& scene, const RayTracer& rayTracer, const BakeOptions& options,
                  const std::function<GlProbe()>& probeGl) {
  return planBake(scene, rayTracer.hasTransmission(), options, probeGl);
}

bool hasTransmissiveMaterial(const Scene& scene) {
  for (const Primitive& p : scene.primitives)
    if (scene.materials[p.material].isTransmissive()) return true;
  return false;
}

BakePlan planBake(const Scene& scene, bool transmission, const BakeOptions& options,
                  const std::function<GlProbe()>& probeGl) {
  BakePlan plan;
  plan.directional = options.directional;
  settleBackend(plan, scene, options, probeGl);
  settleFinalGather(plan, scene, options);
  settleWalk(plan, scene, options);
  settleCompensation(plan, options, probeGl);
  settleSky(plan, scene, transmission, options);
  plan.shadowEdges = options.shadowEdges;
  settleProbes(plan, scene, options);
  plan.shadowMask = options.shadowMask;
  plan.post.dilate = options.postDilate;
  plan.post.stitchSeams = options.postSeams;
  plan.eval = options.eval;
  return plan;
}

void settleClamp(BakePlan& plan, const BakeOptions& options, const Scene& scene, double vplCount) {
  plan.eval = options.eval;
  if (options.clamp != ClampMode::Derived) {
    plan.eval.clampBound = options.clamp == ClampMode::Fixed ? options.clampBound : 0.0f;
    plan.settle("clamp", plan.eval.clampBound, options.clamp == ClampMode::Fixed ? "asked for" : "no clamp asked for", false);
    return;
  }
  const bool given = options.clampVplsPerMean > 0.0;
  // The tighter clamp wherever no small emitter is near: none, or emitters the gathers' rays meet anyway.
  const bool smallEmitters = hasSmallEmitters(scene);
  plan.clampK = given                           ? options.clampVplsPerMean
                : !plan.eval.biasCompensation  ? kClampVplsPerMean
                : smallEmitters                ? kCompensatedClampVplsPerMean
                                               : kCompensatedClampVplsPerMeanNoEmitters;
  plan.eval.clampBound = clampBoundForCount(scene, vplCount, plan.clampK);
  plan.clampDerived = true;
  plan.settle("clamp-k", plan.clampK,
              given                         ? "asked for"
              : !plan.eval.biasCompensation ? "no bias compensation: a loose clamp keeps the bias small"
              : smallEmitters               ? "compensated, with small emissive surfaces"
              : scene.hasEmissiveSurface()  ? "compensated, emitters cover at least half the surface (the gathers meet them)"
                                            : "compensated, no emissive surfaces",
              !given);
  plan.settle("clamp", plan.eval.clampBound, "derived from the walk at seed 0, once per scene: no VPL adds more than 1/k of the mean (1/m²)");
}

void settleBlocks(BakePlan& plan, const BakeOptions& options, const std::vector<TexelSamples>& texels,
                  SurfaceFilterCache* filters) {
  plan.interleave = options.interleave ? *options.interleave : chooseInterleave(texels, plan.eval.clampBound, filters);
  plan.settle("interleave", plan.interleave,
              options.interleave ? "asked for" : "from the texel spacing and the clamp radius", !options.interleave);
  plan.compensation.classMix = plan.interleave;  // the residual mixed like the classes' VPL sum it completes
}

void checkLightModes(const BakeOptions& options, const Scene& scene) {
  const std::vector<RequestedLightMode> modes = resolveLightModes(scene, options.lightModes);
  for (size_t i = 0; i < modes.size(); ++i) {
    if (modes[i].mode == LightMode::Baked) continue;
    const std::string what = "light '" + lightModeName(scene.lights[i]) + "' in mode " + toString(modes[i].mode) +
                             " (" + modes[i].reason + ")";
    // The reference integrator finds every light itself, and the L1 pages hold every light's direct term (they
    // have no split by light), so both are refused before anything is traced.
    if (options.backend == BackendKind::Reference)
      throw Error(ErrorCode::Usage, scene.sourcePath, what + ": needs a VPL backend (gl, embree or auto), not reference");
    if (options.directional)
      throw Error(ErrorCode::Usage, scene.sourcePath, what + ": --directional bakes every light's direct term into its L1 pages; leave out --directional or the mode");
  }
}

void settleLightModes(BakePlan& plan, const BakeOptions& options, const Scene& scene,
                      const std::vector<TexelSamples>& texels, const LightGrid* grid) {
  checkLightModes(options, scene);
  const std::vector<RequestedLightMode> modes = resolveLightModes(scene, options.lightModes);
  plan.lightModes.assign(modes.size(), LightMode::Baked);
  std::vector<uint8_t> wants(modes.size(), 0);
  for (size_t i = 0; i < modes.size(); ++i) {
    plan.lightModes[i] = modes[i].mode;
    wants[i] = modes[i].mode == LightMode::ShadowMask;
  }
  plan.maskChannels = assignShadowMaskChannels(scene, texels, wants, plan.shadowMask, grid);
  for (size_t i : plan.maskChannels.fellBack) {
    plan.lightModes[i] = LightMode::Indirect;
    log::warn("light '" + lightModeName(scene.lights[i]) + "' falls back from shadowmask to indirect: its light meets " +
              std::to_string(kShadowMaskChannels) + " other shadow-mask lights' at some texel and the mask has " +
              std::to_string(kShadowMaskChannels) + " channels");
  }
  bool anyLeftOut = false;
  for (LightMode m : plan.lightModes) anyLeftOut |= m != LightMode::Baked;
  plan.leftOut.clear();
  if (anyLeftOut)
    for (LightMode m : plan.lightModes) plan.leftOut.push_back(m != LightMode::Baked);
  for (size_t i = 0; i < modes.size(); ++i) {
    const bool fell = std::find(plan.maskChannels.fellBack.begin(), plan.maskChannels.fellBack.end(), i) !=
                      plan.maskChannels.fellBack.end();
    const std::string reason = fell ? modes[i].reason + "; no shadow-mask channel left: indirect" : modes[i].reason;
    plan.settle("light-mode " + lightModeName(scene.lights[i]) + " #" + std::to_string(i), toString(plan.lightModes[i]),
                reason, fell);
  }
  if (!plan.maskChannels.channel.empty() && (plan.maskChannels.used() > 0 || !plan.maskChannels.fellBack.empty()))
    plan.settle("shadow-mask-channels", plan.maskChannels.toJson(scene),
                "the shadow-mask lights' overlap graph coloured with 4 channels, brightest first");
}

bool finalGatherAutoOn(const Scene& scene) { return !hasSmallEmitters(scene) && seeThroughMaterials(scene).empty(); }

double autoClampVplsPerMean(const Scene& scene, bool biasCompensation) {
  return !biasCompensation ? kClampVplsPerMean
         : hasSmallEmitters(scene) ? kCompensatedClampVplsPerMean
                                   : kCompensatedClampVplsPerMeanNoEmitters;
}

}  // namespace irbake
