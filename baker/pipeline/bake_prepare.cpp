// The preparation of a bake: atlas, ray tracer, texel samples, the plan and its evaluator, the walk and its
// importance selection, the clamp, the replicates, the VPL blocks.
#include <algorithm>
#include <cmath>

#include "atlas/atlas_from_bake.h"
#include "pipeline/bake_state.h"
#include "transport/geometry_term.h"

namespace irbake {
namespace {

void buildGeometry(BakeState& s) {
  timed(s, "atlas", [&] {
    AtlasOptions o = s.options.atlas;
    o.progress = withProgress(s, o.progress);
    if (s.options.atlasApplied) s.atlas = *s.options.atlasApplied;
    else s.atlas = s.options.atlasFrom.empty() ? buildAtlas(s.scene, o)
                                               : atlasFromBake(s.scene, readBakedAtlas(s.options.atlasFrom), o);
  });
  timed(s, "raytrace", [&] { s.rayTracer = std::make_unique<RayTracer>(s.scene); });
  timed(s, "texels", [&] {
    TexelSampleOptions o = s.options.texels;
    o.progress = withProgress(s, o.progress);
    s.texels = buildTexelSamples(s.scene, *s.rayTracer, o);
  });
}

// Each light's reach, the cut lights' fade and the grid every stage's per-light loop reads.
void settleLightCull(BakeState& s) {
  const Bounds3 bounds = s.scene.bounds();
  s.lightReach = settleLightReach(s.scene, bounds, s.options.lightCull);
  applyLightCutoffs(s.scene, s.lightReach);
  s.lightGrid = std::make_unique<LightGrid>(s.scene, s.lightReach, bounds);
  if (!s.lightGrid->culls()) return;
  const size_t cut = s.lightReach.cutLights();
  s.plan.settle("light-cull", s.options.lightCull.fraction,
                cut ? std::to_string(cut) + " lights without range end where their light falls to the fraction of " +
                          std::to_string(s.lightReach.reference) + " (docs/units.md)"
                    : std::string("the lights' ranges"),
                false);
}

// The plan and its evaluator (a GL context is made here where GL may run: its time counts to the backend).
void chooseBackend(BakeState& s) {
  s.plan = planBake(s.scene, *s.rayTracer, s.options, [&] {
    GlProbe probe;
    part(s, "context", [&] { probe = s.devices.probeGl(); });
    return probe;
  });
  EvaluatorSettings settings;
  settings.gl = s.options.gl;
  settings.reference.spp = s.options.referenceSpp;
  settings.reference.seed = s.options.walk.seed;
  const auto make = [&] { s.evaluator = makeEvaluator(s.plan.backend, settings, &s.devices); };
  if (s.plan.backend == BackendKind::Gl) part(s, "context", make);  // GL's context counts to the backend
  else make();
  s.devices.release();
}

// Importance-driven selection: where the plain walk's VPLs matter unevenly (its pilot), the walk again with f
// times the paths, then about the plain walk's count kept where they matter (transport/vpl_importance.h).
// Settles f from the walk at seed 0 (s.sceneWalk), as the clamp: one choice per scene, whatever the seed.
void settleImportanceFactor(BakeState& s) {
  if (s.plan.backend == BackendKind::Reference || !s.options.eval.includeVpls || s.vpls.vpls.empty()) return;
  double evenness = 0.0;
  // auto: only under the final gather. Without it the selection thins the VPLs that light bright texels,
  // which costs a plain bake's close-ups more than it gives; under the final gather the close-ups hold
  // and the gallery's seed-to-seed swing goes (docs/units.md, "Importance-driven VPL selection").
  const bool pilot = !s.options.vplImportance.candidateFactor;  // auto; a fixed factor needs none
  if (!pilot || s.plan.finalGather) {
    if (pilot) {
      settleClamp(s.plan, s.options, s.scene, static_cast<double>(litVplCount(s.sceneWalk)));
      evenness = vplImportanceEvenness(s.scene, *s.rayTracer, s.texels, s.sceneWalk.vpls, s.options.vplImportance,
                                       s.plan.eval.clampBound, 0);
    }
    s.plan.importanceFactor = chooseCandidateFactor(s.options.vplImportance, s.vpls.vpls.size(), evenness);
  }
  s.importanceStats.evenness = evenness;
  s.plan.settle("vpl-importance", s.plan.importanceFactor,
                !pilot                          ? "asked for"
                : !s.plan.finalGather           ? "auto: only under the final gather"
                : s.plan.importanceFactor > 1.0 ? "auto: the pilot found the walk's VPLs uneven"
                                                : "auto: the pilot found the walk's VPLs even enough",
                pilot);
}

// The walk that the derived clamp's count and the importance pilot read, once per scene: the plan's walk (all its
// paths) at seed 0, the bake's own where it is that one. Neither then follows the seed, nor the estimate's halved
// replicates (whose counts scatter over seeds and would halve the bound), so bakes at two seeds share the clamp's
// bias as the two halves of one bake do (docs/units.md, "Estimated error").
void walkOncePerScene(BakeState& s) {
  WalkOptions o = s.plan.walk;
  if (o.seed == 0 && !estimating(s)) {
    s.sceneWalk = s.vpls;
    return;
  }
  o.seed = 0;
  o.progress = {};
  s.sceneWalk = generateVpls(s.scene, *s.rayTracer, o);
}

// The clamp's count for the VPLs evaluated: the importance selection keeps about keepShare of the plain walk's.
double evaluatedClampCount(const BakeState& s) {
  const double lit = static_cast<double>(litVplCount(s.sceneWalk));
  return s.plan.importanceFactor > 1.0 ? lit * s.options.vplImportance.keepShare : lit;
}

// The walk (replicate 0's with an estimate), again with f times the paths where the importance selection runs.
void walkVpls(BakeState& s) {
  WalkOptions o = replicateWalk(s, 0);
  o.progress = withProgress(s, o.progress);
  s.vpls = generateVpls(s.scene, *s.rayTracer, o);
  walkOncePerScene(s);
  settleImportanceFactor(s);
  if (s.plan.importanceFactor > 1.0) {
    o.paths = static_cast<int>(std::min(double(1 << 26), std::round(o.paths * s.plan.importanceFactor)));
    s.vpls = generateVpls(s.scene, *s.rayTracer, o);
  }
}

// The walk's automatic bounce count and split, as walked.
void settleWalk(BakeState& s) {
  if (s.plan.backend == BackendKind::Reference) return;
  const WalkOptions& asked = s.options.walk;
  s.plan.settle("bounces", s.vpls.bounces,
                asked.maxBounces ? "asked for" : "until the light not yet placed is negligible, the rest added as a tail",
                !asked.maxBounces);
  s.plan.settle("walk-split", s.vpls.split,
                asked.split ? "asked for"
                : s.plan.walk.minAutoSplit > 1 && s.vpls.split == s.plan.walk.minAutoSplit
                    ? "at least " + std::to_string(s.plan.walk.minAutoSplit) +
                          " without the final gather: the deep bounces' carriers"
                    : std::string("from the share of bounce-1 light that meets the scene again"),
                !asked.split);
}

// The candidates thinned to about the plain walk's count, where they matter.
void selectByImportance(BakeState& s) {
  // The candidates are measured with the kept set's bound (about 1/f of theirs: B ∝ VPL count).
  settleClamp(s.plan, s.options, s.scene, evaluatedClampCount(s));
  VplSelection selection;
  selection.keepFraction = s.options.vplImportance.keepShare / s.plan.importanceFactor;
  selection.clampBound = s.plan.eval.clampBound;
  selection.seed = estimating(s) ? replicateWalk(s, 0).seed : s.options.walk.seed;
  s.candidateBound = selection.clampBound;
  s.importanceStats.factor = s.plan.importanceFactor;
  selectVplsByImportance(s.scene, *s.rayTracer, s.texels, s.vpls, s.options.vplImportance, selection,
                         &s.importanceStats);
}

// Every page and VPL as the stages after the evaluators read them (the gather keeps a reference to its
// inputs, so they live as long as the bake).
void makeWholeInputs(BakeState& s) {
  s.wholeInputs = std::make_unique<BakeInputs>(inputs(s, s.texels, s.vpls, s.plan.eval));
  s.surfaceFilters = std::make_unique<SurfaceFilterCache>(s.texels);
  s.wholeInputs->surfaceFilters = s.surfaceFilters.get();
  if (s.plan.compensate || s.plan.finalGather) {
    s.footprintAlbedo = std::make_unique<FootprintAlbedo>(s.scene);
    s.wholeInputs->footprintAlbedo = s.footprintAlbedo.get();
  }
}

// The estimate and its target in the plan, with their reasons.
void settleErrorEstimate(BakeState& s) {
  const ErrorEstimateOptions& e = s.options.errorEstimate;
  if (!e.enabled) return;
  s.plan.settle("error-estimate", estimating(s),
                estimating(s) ? (e.targetError > 0.0 ? "implied by --target-error" : "asked for")
                             : "no VPLs to split into independent replicates (reference backend or no VPL light)",
                false);
  if (e.targetError > 0.0)
    s.plan.settle("target-error", e.targetError,
                  "asked for: rounds of " + std::to_string(replicateWalk(s, 0).paths) + " + " +
                      std::to_string(replicateWalk(s, 1).paths) + " paths, or of more compensation and final gather "
                      "rays where their noise dominates, until the estimate is at most it, at most " +
                      std::to_string(e.maxRounds) + " rounds" +
                      (e.maxSeconds > 0.0 ? ", " + std::to_string(e.maxSeconds) + " s" : ""),
                  false);
}

// Interleave classes and the fixed blocks of each class's VPLs: the units shards and checkpoints split.
void planBlocks(BakeState& s) {
  if (s.plan.backend == BackendKind::Reference || !s.plan.eval.includeVpls || s.vpls.vpls.empty()) return;
  settleBlocks(s.plan, s.options, s.texels, s.surfaceFilters.get());
  // Once for every block, from the first class's pages (the first blocks' own).
  for (const EvaluatorChoice& c : s.evaluator->settle(inputs(s, pagesOf(s, 0), s.vpls, s.plan.eval)))
    s.plan.settle(c.key, c.value, c.reason);
  for (size_t r = 0; r < std::max<size_t>(1, s.replicates.size()); ++r) appendBlocks(s, r);
  s.interleaveStats.classes = static_cast<int>(s.classVpls[0].size());
}

}  // namespace

void prepare(BakeState& s) {
  // The preflight first: a bake predicted over --max-memory is refused before any work.
  s.prediction = predictBake(s.scene, s.options, bakeCores(), /*weighRays=*/false);
  checkMemoryLimit(s.prediction, s.options.maxMemoryGB, s.scene.sourcePath);
  buildGeometry(s);
  weighRays(s.prediction, s.scene, *s.rayTracer);  // with the bake's own tracer
  // The backend first (the GL context is made here: its time counts to the backend, as it did): the
  // reference backend reads no VPLs, so it needs no VPL selection.
  timed(s, "backend", [&] { chooseBackend(s); });
  settleLightCull(s);
  settleLightModes(s.plan, s.options, s.scene, s.texels, s.lightGrid.get());
  const bool autoDensity = !(s.options.atlas.texelsPerUnit > 0.0);
  s.plan.settle("texels-per-unit", s.atlas.stats.texelsPerUnit,
                s.options.atlasApplied ? "the atlas of the first light group's bake"
                : !s.options.atlasFrom.empty() ? "the atlas of --atlas-from's bake"
                : autoDensity ? "the density rule: the preset's texels per metre, more for a small scene, less to fit "
                              "--max-texels (docs/guide.md, \"Texel density\")"
                            : "asked for",
                autoDensity && s.options.atlasFrom.empty() && !s.options.atlasApplied);  // --atlas-from's density is not given again
  timed(s, "vpls", [&] { walkVpls(s); });
  settleWalk(s);
  if (s.plan.importanceFactor > 1.0) timed(s, "vplImportance", [&] { selectByImportance(s); });
  settleClamp(s.plan, s.options, s.scene, evaluatedClampCount(s));
  s.sceneWalk = VplSet{};  // settled: nothing reads it again
  if (estimating(s)) timed(s, "vpls", [&] { startReplicates(s); });
  makeWholeInputs(s);
  timed(s, "backend", [&] { part(s, "blocks", [&] { planBlocks(s); }); });
  if (estimating(s) && !s.blocks.empty()) s.halfB = zeroSums(s);
  settleErrorEstimate(s);
}

}  // namespace irbake
