// The bake plan: every "auto" of the options and every rule between stages settled in one place, each with
// its reason. The stages read their options from the plan, never from each other's. The plan goes into the
// log, into report.json ("plan") and into --dump-config.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "pipeline/backend_choice.h"
#include "pipeline/bake_options.h"
#include "post/post.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/gather/final_gather.h"
#include "stages/shadow_edges/shadow_edges.h"
#include "stages/shadow_mask/shadow_mask.h"
#include "stages/sky/sky_light.h"
#include "vpl/vpl.h"

namespace irbake {

// One settled choice: the value as the report shows it and why.
struct PlanChoice {
  nlohmann::json value;
  std::string reason;
  bool automatic = true;  // the bake chose it (false: an option fixed it)
};

struct BakePlan {
  BackendKind backend = BackendKind::Auto;  // never Auto once planned
  bool finalGather = false;                 // bounced light gathered from the map (stages/gather)
  bool compensate = false;                  // the clamp compensation stage runs
  bool overlapCompensation = false;         // its rays traced while the GL evaluator bakes
  bool skyByGather = false;                 // the final gather's escaping rays count a uniform sky
  bool directional = false;                 // L1 pages beside the map
  WalkOptions walk;                         // the light paths as walked (paths settled)
  ClampCompensationOptions compensation;    // as the compensation stage runs
  SkyLightOptions sky;                      // as the sky stage runs
  FinalGatherOptions gather;                // as the final gather runs
  ShadowEdgeOptions shadowEdges;            // as the shadow-edge stage runs
  ProbeOptions probes;                      // as the probe stage runs (spacing and box settled when enabled)
  PostOptions post;                         // dilation and seams
  // Mixed lighting, settled once the texels are known (settleLightModes):
  std::vector<LightMode> lightModes;        // per scene light
  std::vector<uint8_t> leftOut;             // per scene light, 1: its direct light is left out of what is
                                            // written (indirect, shadowmask); empty: every light is baked
  ShadowMaskOptions shadowMask;             // as the shadow-mask stage runs
  ShadowMaskChannels maskChannels;          // the shadow-mask lights' channels
  // Settled once the walk's VPLs are known (settleClamp, settleBlocks):
  VplEvalOptions eval;                      // with the clamp bound
  double clampK = 0.0;                      // k of deriveClampBound (0: the clamp was not derived)
  bool clampDerived = false;
  double importanceFactor = 1.0;            // candidates per kept VPL (1: the plain walk)
  int interleave = 1;                       // n×n texel classes

  std::map<std::string, PlanChoice> choices;  // by option name ("backend", "paths", ...) or rule name

  // Records a settled choice and logs it when the bake made it.
  void settle(const std::string& key, nlohmann::json value, const std::string& reason, bool automatic = true);
  // {"key": {"value", "reason", "automatic"}, ...}
  nlohmann::json toJson() const;
};

// The first see-through material (MASK cut-outs, BLEND, transmission) a primitive uses, as a phrase for the
// log; empty when there is none.
std::string seeThroughMaterials(const Scene& scene);
// FinalGatherMode::Auto's choice for the scene on a VPL backend: on without small emitters or see-through
// surfaces (light groups settle it once for the whole scene, so that every group's bake gathers alike).
bool finalGatherAutoOn(const Scene& scene);
// The clamp's k (BakeOptions::clampVplsPerMean) where the options leave it 0, for the scene (same reason).
double autoClampVplsPerMean(const Scene& scene, bool biasCompensation);

// Settles what the scene, the options and the machine decide before any light is traced: evaluator, final
// gather, paths, compensation and its overlap, the sky's share, each stage's options. probeGl makes the GL
// context (the caller keeps it) and is called where the choice depends on it.
BakePlan planBake(const Scene& scene, const RayTracer& rayTracer, const BakeOptions& options,
                  const std::function<GlProbe()>& probeGl);
// The same before any ray tracer is built: transmission says whether a surface is see-through to shadow rays
// (RayTracer::hasTransmission, as hasTransmissiveMaterial finds it).
BakePlan planBake(const Scene& scene, bool transmission, const BakeOptions& options,
                  const std::function<GlProbe()>& probeGl);
// Whether a primitive's material lets light through (BLEND or KHR_materials_transmission), as the ray tracer finds it.
bool hasTransmissiveMaterial(const Scene& scene);

// Each punctual light's mode (--light-mode, extras, baked) and the shadow-mask channels; a shadow-mask light
// that gets no channel falls back to indirect with a warning naming it. Throws Error(Usage) for a bad name or
// a mode other than baked with the reference backend or --directional (not supported yet).
void settleLightModes(BakePlan& plan, const BakeOptions& options, const Scene& scene,
                      const std::vector<TexelSamples>& texels, const LightGrid* grid = nullptr);
// The checks of settleLightModes that need no texels, made before anything is traced.
void checkLightModes(const BakeOptions& options, const Scene& scene);

// The clamp: fixed, off, or derived from the scene and a VPL count (clampBoundForCount; sets plan.eval.clampBound).
void settleClamp(BakePlan& plan, const BakeOptions& options, const Scene& scene, double vplCount);

// The interleave classes, from the texels and the clamp (the evaluator settles its own options after it).
void settleBlocks(BakePlan& plan, const BakeOptions& options, const std::vector<TexelSamples>& texels,
                  SurfaceFilterCache* filters);

}  // namespace irbake
