// The bake, stage by stage, with the report the benchmarks and users read.
#include "pipeline/bake.h"
#include "pipeline/bake_report.h"
#include "pipeline/bake_stages.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <memory>

#include <tbb/parallel_for.h>

#include "stages/compensation/clamp_compensation.h"
#include "stages/gather/final_gather.h"
#include "transport/geometry_term.h"
#include "transport/vpl_importance.h"
#include "stages/interleave/interleaved_sampling.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "common/maths.h"
#include "pipeline/evaluator_factory.h"
#include "post/post.h"
#include "raytrace/ray_tracer.h"
#include "sampling/sampling.h"
#include "stages/error_estimate/error_estimate.h"

namespace irbake {
namespace {

// The values an option holds when it is set must make sense: unset is "automatic", never a number.
void checkOptionRanges(const BakeOptions& o) {
  auto atLeast = [](const std::optional<int>& value, int lowest, const char* name) {
    if (value && *value < lowest)
      throw Error(ErrorCode::Usage, "", std::string(name) + " must be at least " + std::to_string(lowest) + " (got " +
                                            std::to_string(*value) + ")");
  };
  atLeast(o.interleave, 1, "interleave");
  atLeast(o.gl.cubeFaceSize, 1, "GL cube face size");
  atLeast(o.walk.maxBounces, 0, "bounce count");
  atLeast(o.compensation.filterRadius, 0, "compensation filter radius");
  if (o.directional && o.backend == BackendKind::Reference)  // the L1 pages come from the VPL backends' passes
    throw Error(ErrorCode::Usage, "", "--directional needs a VPL backend (gl, embree or auto), not reference");
  if (o.clamp == ClampMode::Fixed && !(o.clampBound > 0.0f))
    throw Error(ErrorCode::Usage, "", "a fixed clamp bound must be positive (got " + std::to_string(o.clampBound) +
                                          "; ClampMode::Off for no clamp)");
}

}  // namespace

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: kilobytes
}

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

// A contiguous range of one interleave class's VPLs, of one replicate of the walk (0 without an error estimate).
struct VplBlock {
  int vplClass = 0;
  size_t begin = 0, end = 0;
  size_t replicate = 0;
};

}  // namespace

struct StagedBake::State {
  BakeOptions options;
  Scene scene;
  AtlasResult atlas;
  std::unique_ptr<RayTracer> rayTracer;
  std::vector<TexelSamples> texels;
  VplSet vpls;
  BakePlan plan;              // every automatic choice, settled once
  VplImportanceStats importanceStats;
  std::vector<std::vector<VplSet>> classVpls;       // per replicate of the walk, per interleave class
  // The error estimate (stages/error_estimate): the walk as independent replicates, each a whole estimate of
  // the VPL light; the even ones form half A, the odd ones half B, and their spread is the estimate.
  std::vector<VplSet> replicates;                   // empty without an estimate
  ExactVplSums halfB;                               // the odd replicates' sum (the bake's sums hold them all)
  std::array<std::vector<Lightmap>, 2> halves;      // both halves mixed like the map (finish)
  float candidateBound = 0.0f;                      // the importance selection's bound, for every replicate
  double gatherNoiseRatio = 0.0;                    // the final gather's noise over the mixed halves' (once)
  std::vector<Lightmap> cachedDirect;               // the punctual lights' pages, made once for the rounds
  nlohmann::json rounds = nlohmann::json::array();  // the estimate after each round
  std::string stoppedBy;
  double roundSeconds = 0.0;                        // the last round of paths' blocks (the time cap's forecast)
  double stageRays = 1.0;                           // --target-error: the ray stages' rays over the plan's
  ClampCompensationOptions planCompensation;        // the plan's ray stages, before the target raised their rays
  FinalGatherOptions planGather;
  nlohmann::json stageNoise = nlohmann::json::object();  // a stage's own ray noise (RMS on bins, map units)
  nlohmann::json stageNoiseInterior = nlohmann::json::object();  // the same on interior bins (BinTexels)
  int pagesClass = -1;                     // the class classPages holds (blocks run class by class, so one
  std::vector<TexelSamples> classPages;    // class's texel copy at a time: 1/n² of the samples' memory)
  std::vector<VplBlock> blocks;
  EvaluatorDevices devices;                // the GL context, while the plan may choose GL
  std::unique_ptr<Evaluator> evaluator;    // the plan's, made once it is chosen (it keeps its own figures)
  InterleaveStats interleaveStats;
  std::unique_ptr<FootprintAlbedo> footprintAlbedo;  // hit albedo for the compensation and the gather (one for both)
  std::unique_ptr<BakeInputs> wholeInputs;          // every page and VPL: the sky and the gather read them
  std::unique_ptr<SurfaceFilterCache> surfaceFilters;  // each page's neighbour tests, made once for all filters
  std::future<std::unique_ptr<ClampGather>> gather;  // traced while the GL backend bakes (GPU only)
  std::vector<Lightmap> directMaps;                 // the final gather's D: punctual lights and sky, exact
  std::vector<Lightmap> leftOutDirect;              // mixed lighting: the direct light of the lights not baked,
                                                    // in every stage's map, taken out of what is written
  L1Pages directL1;                                 // with --directional: D's L1 pages
  nlohmann::json seconds = nlohmann::json::object();
  nlohmann::json backendParts = nlohmann::json::object();  // the backend stage's split (report timings.backendParts)
  Stopwatch total;

  ProgressCallback withProgress(ProgressCallback cb) const { return cb ? cb : options.progress; }
  BakeInputs inputs(const std::vector<TexelSamples>& pages, const VplSet& set, const VplEvalOptions& e,
                    ProgressCallback progress = {}) const {
    return BakeInputs{scene, *rayTracer, pages, set, e, std::move(progress)};
  }

  // Each stage records its wall time under its name.
  template <class Stage>
  void timed(const char* name, Stage&& stage) {
    Stopwatch watch;
    stage();
    seconds[name] = seconds.value(name, 0.0) + watch.seconds();
  }
  // A part of the backend stage (inside its timed call): the GL context, the blocks' plan, the evaluator
  // calls, the maps (the punctual lights' "direct" call, their shadow edges and the classes' mix).
  template <class Part>
  void part(const char* name, Part&& work) {
    Stopwatch watch;
    work();
    backendParts[name] = backendParts.value(name, 0.0) + watch.seconds();
  }

  void prepare() {
    timed("atlas", [&] {
      AtlasOptions o = options.atlas;
      o.progress = withProgress(o.progress);
      atlas = buildAtlas(scene, o);
    });
    timed("raytrace", [&] { rayTracer = std::make_unique<RayTracer>(scene); });
    timed("texels", [&] {
      TexelSampleOptions o = options.texels;
      o.progress = withProgress(o.progress);
      texels = buildTexelSamples(scene, *rayTracer, o);
    });
    // The backend first (the GL context is made here: its time counts to the backend, as it did): the
    // reference backend reads no VPLs, so it needs no VPL selection.
    timed("backend", [&] { chooseBackend(); });
    settleLightModes(plan, options, scene, texels);
    const bool autoDensity = !(options.atlas.texelsPerUnit > 0.0);
    plan.settle("texels-per-unit", atlas.stats.texelsPerUnit,
                autoDensity ? "about one page at the preset's size, more for many triangles" : "asked for", autoDensity);
    timed("vpls", [&] {
      WalkOptions o = replicateWalk(0);
      o.progress = withProgress(o.progress);
      vpls = generateVpls(scene, *rayTracer, o);
      // Importance-driven selection: where the plain walk's VPLs matter unevenly (its pilot), the walk again
      // with f times the paths, then about the plain walk's count kept where they matter
      // (transport/vpl_importance.h).
      if (plan.backend != BackendKind::Reference && options.eval.includeVpls && !vpls.vpls.empty()) {
        double evenness = 0.0;
        // auto: only under the final gather. Without it the selection thins the VPLs that light bright texels,
        // which costs a plain bake's close-ups more than it gives; under the final gather the close-ups hold
        // and the gallery's seed-to-seed swing goes (docs/units.md, "Importance-driven VPL selection").
        const bool pilot = !options.vplImportance.candidateFactor;  // auto; a fixed factor needs none
        if (!pilot || plan.finalGather) {
          if (pilot) {
            settleClamp(plan, options, scene, vpls);
            evenness = vplImportanceEvenness(scene, *rayTracer, texels, vpls.vpls, options.vplImportance,
                                             plan.eval.clampBound, options.walk.seed);
          }
          plan.importanceFactor = chooseCandidateFactor(options.vplImportance, vpls.vpls.size(), evenness);
        }
        importanceStats.evenness = evenness;
        plan.settle("vpl-importance", plan.importanceFactor,
                    !pilot ? "asked for"
                    : !plan.finalGather ? "auto: only under the final gather"
                    : plan.importanceFactor > 1.0 ? "auto: the pilot found the walk's VPLs uneven"
                                                  : "auto: the pilot found the walk's VPLs even enough",
                    pilot);
      }
      if (plan.importanceFactor > 1.0) {
        o.paths = static_cast<int>(std::min(double(1 << 26), std::round(o.paths * plan.importanceFactor)));
        vpls = generateVpls(scene, *rayTracer, o);
      }
    });
    if (plan.backend != BackendKind::Reference) {
      plan.settle("bounces", vpls.bounces,
                  options.walk.maxBounces ? "asked for" : "until the light not yet placed is negligible, the rest added as a tail",
                  !options.walk.maxBounces);
      plan.settle("walk-split", vpls.split,
                  options.walk.split ? "asked for"
                  : plan.walk.minAutoSplit > 1 && vpls.split == plan.walk.minAutoSplit
                      ? "at least " + std::to_string(plan.walk.minAutoSplit) + " without the final gather: the deep bounces' carriers"
                      : std::string("from the share of bounce-1 light that meets the scene again"),
                  !options.walk.split);
    }
    if (plan.importanceFactor > 1.0)
      timed("vplImportance", [&] {
        settleClamp(plan, options, scene, vpls);  // the candidates' bound: the kept set's is about 1/f of it (B ∝ VPL count)
        VplSelection selection;
        selection.keepFraction = options.vplImportance.keepShare / plan.importanceFactor;
        selection.clampBound = plan.clampDerived ? static_cast<float>(plan.eval.clampBound * selection.keepFraction)
                                                 : plan.eval.clampBound;
        selection.seed = estimating() ? replicateWalk(0).seed : options.walk.seed;
        candidateBound = selection.clampBound;
        importanceStats.factor = plan.importanceFactor;
        selectVplsByImportance(scene, *rayTracer, texels, vpls, options.vplImportance, selection, &importanceStats);
      });
    settleClamp(plan, options, scene, vpls);
    if (estimating()) timed("vpls", [&] { startReplicates(); });
    // The gather keeps a reference to its inputs, so they live as long as the bake.
    wholeInputs = std::make_unique<BakeInputs>(inputs(texels, vpls, plan.eval));
    surfaceFilters = std::make_unique<SurfaceFilterCache>(texels);
    wholeInputs->surfaceFilters = surfaceFilters.get();
    if (plan.compensate || plan.finalGather) {
      footprintAlbedo = std::make_unique<FootprintAlbedo>(scene);
      wholeInputs->footprintAlbedo = footprintAlbedo.get();
    }
    timed("backend", [&] { part("blocks", [&] { planBlocks(); }); });
    if (estimating() && !blocks.empty()) halfB = zeroSums();
    settleErrorEstimate();
  }

  // The estimate and its target in the plan, with their reasons.
  void settleErrorEstimate() {
    const ErrorEstimateOptions& e = options.errorEstimate;
    if (!e.enabled) return;
    plan.settle("error-estimate", estimating(),
                estimating() ? (e.targetError > 0.0 ? "implied by --target-error" : "asked for")
                             : "no VPLs to split into independent replicates (reference backend or no VPL light)",
                false);
    if (e.targetError > 0.0)
      plan.settle("target-error", e.targetError,
                  "asked for: rounds of " + std::to_string(replicateWalk(0).paths) + " + " +
                      std::to_string(replicateWalk(1).paths) + " paths, or of more compensation and final gather "
                      "rays where their noise dominates, until the estimate is at most it, at most " +
                      std::to_string(e.maxRounds) + " rounds" +
                      (e.maxSeconds > 0.0 ? ", " + std::to_string(e.maxSeconds) + " s" : ""),
                  false);
  }

  // Zero sums for every texel a backend can return valid (GL and Embree keep the samples' valid flags).
  ExactVplSums zeroSums() const {
    std::vector<std::vector<uint8_t>> receivers;
    for (const TexelSamples& ts : texels)
      receivers.push_back(ts.valid.size() == ts.layerSize() ? ts.valid : std::vector<uint8_t>(ts.layerSize(), 1));
    return ExactVplSums::zeros(receivers, coefficients());
  }

  // Both halves' VPL sums (even and odd replicates), each scaled to a whole estimate, mixed like the map.
  std::array<std::vector<Lightmap>, 2> mixedHalves(const ExactVplSums& sums) const {
    std::array<std::vector<Lightmap>, 2> out;
    const float scale = 2.0f / static_cast<float>(replicates.size());
    for (size_t p = 0; p < texels.size(); ++p) {
      for (auto& half : out) {
        half.push_back(blankLightmap(texels[p]));
        half.back().page = static_cast<int>(p);
        if (half.back().valid.size() != half.back().size()) half.back().valid = texels[p].valid;
      }
      std::vector<glm::vec3> a(texels[p].layerSize()), b(texels[p].layerSize());
      tbb::parallel_for(size_t(0), a.size(), [&](size_t t) {
        const glm::vec3 odd = halfB.value(p, t);
        a[t] = (sums.value(p, t) - odd) * scale;
        b[t] = odd * scale;
      });
      addMixedClasses(texels[p], plan.interleave, {&a, &b}, sums.pages[p].valid, {&out[0][p], &out[1][p]},
                      surfaceFilters.get());
    }
    return out;
  }

  // The halves through the final gather alone (no direct light, rays that escape bring nothing): the map's
  // noise under the gather, since the gather is linear in the map it reads (emitters' Le cancels in the spread).
  std::vector<std::vector<Lightmap>> gatheredHalves() const {
    FinalGatherOptions g = plan.gather;
    g.missRadiance = glm::vec3(0.0f);
    std::vector<Lightmap> none = halves[0];
    for (Lightmap& m : none) std::fill(m.texels.begin(), m.texels.end(), glm::vec3(0.0f));
    std::vector<std::vector<Lightmap>> out = {halves[0], halves[1]};
    for (auto& half : out) finalGather(*wholeInputs, none, half, g);
    return out;
  }

  // The estimate between rounds: the mixed halves' spread (under the final gather scaled by the gather's
  // noise ratio, measured once) over their mean plus the punctual lights. The sky and the compensation are
  // left out of the normaliser, so it is at least the finished bake's figure.
  double roundEstimate(const ExactVplSums& sums) {
    halves = mixedHalves(sums);
    if (cachedDirect.empty()) cachedDirect = directStage(nullptr);
    std::vector<Lightmap> value = replicateMean({halves[0], halves[1]});
    for (size_t p = 0; p < value.size() && p < cachedDirect.size(); ++p)
      for (size_t t = 0; t < value[p].size() && t < cachedDirect[p].size(); ++t) value[p].texels[t] += cachedDirect[p].texels[t];
    const int bin = options.errorEstimate.bin;
    const BinnedError e = replicateError({halves[0], halves[1]}, &value, bin);
    if (plan.finalGather && gatherNoiseRatio == 0.0)
      gatherNoiseRatio = e.noiseRms > 0.0 ? replicateError(gatheredHalves(), nullptr, bin).noiseRms / e.noiseRms : 1.0;
    return e.relative * (plan.finalGather ? gatherNoiseRatio : 1.0);
  }

  // A stage's own ray noise: the stage again with rays of another seed on the same input; one stage's
  // variance per bin is half the two results' squared difference (twice replicateError's s²/2 of the pair).
  // Recorded as `stage` on every valid texel's bins and on the interior ones.
  void rayNoise(const std::string& stage, const std::vector<Lightmap>& once, const std::vector<Lightmap>& twice) {
    const int bin = options.errorEstimate.bin;
    stageNoise[stage] = std::sqrt(2.0) * replicateError({once, twice}, nullptr, bin).noiseRms;
    stageNoiseInterior[stage] = std::sqrt(2.0) * replicateError({once, twice}, nullptr, bin, 1.0, BinTexels::Interior).noiseRms;
  }
  // before: the compensation's input, replaced by its second run's output.
  void compensationRayNoise(std::vector<Lightmap>& before, const std::vector<Lightmap>& after) {
    ClampCompensationOptions o = plan.compensation;
    o.seed = static_cast<uint32_t>(hashSeed(options.walk.seed, 0x636f6d70ull));  // "comp"
    ClampGather(*wholeInputs, o).apply(before);
    if (!plan.finalGather) rayNoise("compensationRays", after, before);
  }
  void gatherRayNoise(std::vector<Lightmap> before, const std::vector<Lightmap>& after) {
    FinalGatherOptions o = plan.gather;
    o.seed = static_cast<uint32_t>(hashSeed(options.walk.seed, 0x676174686572ull));  // "gather"
    finalGather(*wholeInputs, directMaps, before, o);
    rayNoise(plan.compensate ? "compensationAndGatherRays" : "finalGatherRays", after, before);
  }

  // The finished bake's figure (before post, on the map as the stages left it): the walk's noise and the
  // ray stages' own, on every valid texel's bins and on the interior ones.
  struct Figure {
    BinnedError whole, interior;
    nlohmann::json breakdown, interiorBreakdown;  // each part relative to the same signal
    std::vector<Lightmap> errorPages;             // with --error-map: each texel's standard error
  };
  Figure figure;  // the last one measured

  void measureFigure(const std::vector<Lightmap>& maps) {
    std::vector<std::vector<Lightmap>> reps = plan.finalGather ? gatheredHalves()
                                                               : std::vector<std::vector<Lightmap>>{halves[0], halves[1]};
    const int bin = options.errorEstimate.bin;
    figure = Figure{};
    figure.whole = withStages(replicateError(reps, &maps, bin), stageNoise, figure.breakdown);
    figure.interior = withStages(replicateError(reps, &maps, bin, 1.0, BinTexels::Interior), stageNoiseInterior,
                                 figure.interiorBreakdown);
    if (options.errorEstimate.errorMap) figure.errorPages = standardErrorPages(reps);
  }

  // The last figure into the report and the log.
  void reportFigure(nlohmann::json& report) const {
    const BinnedError& e = figure.whole;
    nlohmann::json& j = report["estimatedError"] = e.toJson();
    j["replicates"] = replicates.size();
    j["breakdown"] = figure.breakdown;
    j["interior"] = figure.interior.toJson();
    j["interior"]["breakdown"] = figure.interiorBreakdown;
    j["interior"]["texels"] = "valid texels whose four neighbours are valid: the chart-border ring left out, as "
                              "bench/cycles/compare.py scores a map";
    j["binTexels"] = options.errorEstimate.bin;
    j["covers"] = "the VPL sum's noise (two independent halves of the walk, mixed and gathered as the map), and the "
                  "compensation's and final gather's own ray noise (each run again with another seed)";
    j["notCovered"] = "bias (the clamp after compensation, the final gather, the geometric tail), the sky's ray noise";
    j["rounds"] = rounds;
    if (options.errorEstimate.targetError > 0.0) {
      j["targetError"] = options.errorEstimate.targetError;
      j["stoppedBy"] = stoppedBy;
      j["stageRays"] = stageRays;
      report["stoppedBy"] = stoppedBy;
    }
    log::info("estimated error " + percent(e.relative) + " (relative RMS on " + std::to_string(options.errorEstimate.bin) +
              "x" + std::to_string(options.errorEstimate.bin) + "-texel bins, " + std::to_string(replicates.size()) +
              " replicates" + (stageRays > 1.0 ? ", the ray stages' rays x" + shortNumber(stageRays) : std::string()) +
              ")");
  }

  // The map from the VPL sums (moved in: freed page by page as they are rounded), with the sky's light.
  void mapsFromSums(ExactVplSums sums, BakeResult& r, nlohmann::json& report) {
    timed("backend", [&] {
      part("maps", [&] { r.maps = backendMaps(sums, report, plan.directional ? &r.directional : nullptr); });
    });
    StageContext ctx = stageContext(report);
    skyStage(ctx, r.maps, directMaps);
  }

  // The stages that trace rays of their own, on r's maps (and L1 pages): the clamp compensation and the final
  // gather; when estimating, each run a second time with another seed, then the figure (into `figure`).
  void rayStages(BakeResult& r, nlohmann::json& report, bool estimate) {
    StageContext ctx = stageContext(report);
    L1Pages* l1 = plan.directional ? &r.directional : nullptr;
    std::vector<Lightmap> beforeStage = estimate && plan.compensate ? r.maps : std::vector<Lightmap>{};
    compensationStage(ctx, r.maps, l1, gather.valid() ? gather.get() : nullptr);
    // Under the final gather the map the gather reads is not written: the compensation's second run is
    // gathered again (with another gather seed), so both stages' ray noise is measured where it shows.
    if (!beforeStage.empty()) timed("errorEstimate", [&] { compensationRayNoise(beforeStage, r.maps); });
    if (estimate && plan.finalGather && beforeStage.empty()) beforeStage = r.maps;
    finalGatherStage(ctx, directMaps, l1 ? &directL1 : nullptr, r.maps, l1);
    if (plan.finalGather && !beforeStage.empty()) timed("errorEstimate", [&] { gatherRayNoise(std::move(beforeStage), r.maps); });
    if (estimate) timed("errorEstimate", [&] { measureFigure(r.maps); });
  }

  bool targeting() const {
    return estimating() && !halfB.pages.empty() && options.errorEstimate.targetError > 0.0;
  }

  // A round's entry in estimatedError.rounds, before its figures.
  nlohmann::json roundEntry() const {
    return {{"round", rounds.size() + 1}, {"replicates", replicates.size()}, {"vpls", vpls.vpls.size()},
            {"stageRays", stageRays}};
  }

  // The compensation's and the final gather's rays (per sample, and their budgets) `factor` times more.
  void raiseStageRays(double factor) {
    if (stageRays == 1.0) {
      planCompensation = plan.compensation;
      planGather = plan.gather;
    }
    stageRays *= factor;
    auto scaled = [this](auto n) { return static_cast<decltype(n)>(std::llround(static_cast<double>(n) * stageRays)); };
    plan.compensation.rays = scaled(planCompensation.rays);
    plan.compensation.refineRays = scaled(planCompensation.refineRays);
    plan.compensation.rayBudget = scaled(planCompensation.rayBudget);  // 0 (no cap) stays 0
    plan.gather.rays = scaled(planGather.rays);
    plan.gather.preRays = scaled(planGather.preRays);  // 0 (no pre-pass) stays 0
    plan.gather.rayBudget = scaled(planGather.rayBudget);
  }

  static std::string shortNumber(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    return text;
  }

  // The walk's figure with the stages' own ray noise added (independent of the walk's: the variances add),
  // each part relative to the same signal in `breakdown`.
  static BinnedError withStages(BinnedError e, const nlohmann::json& stages, nlohmann::json& breakdown) {
    breakdown = {{"vpls", e.relative}};
    double noise2 = e.noiseRms * e.noiseRms;
    for (const auto& [stage, rms] : stages.items()) {
      noise2 += rms.get<double>() * rms.get<double>();
      breakdown[stage] = e.signalRms > 0.0 ? rms.get<double>() / e.signalRms : 0.0;
    }
    e.noiseRms = std::sqrt(noise2);
    e.relative = e.signalRms > 0.0 ? e.noiseRms / e.signalRms : 0.0;
    return e;
  }

  static std::string percent(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f%%", 100.0 * x);
    return text;
  }

  bool estimating() const {
    return options.errorEstimate.enabled && plan.backend != BackendKind::Reference && options.eval.includeVpls;
  }

  // The walk of replicate i: the plan's walk, or with an estimate half its paths and a seed of its own (an
  // independent digit permutation of the Halton points), so that replicates are independent estimates.
  WalkOptions replicateWalk(size_t i) const {
    WalkOptions o = plan.walk;
    if (!estimating()) return o;
    o.paths = std::max(1, o.paths / 2);
    o.seed = static_cast<uint32_t>(hashSeed(options.walk.seed, 0x7265706c6963ull, i));  // "replic"
    return o;
  }

  // Replicate i's VPLs, walked and selected as replicate 0's were (the same factor and bound).
  VplSet walkReplicate(size_t i) {
    WalkOptions o = replicateWalk(i);
    o.progress = withProgress(o.progress);
    if (plan.importanceFactor > 1.0)
      o.paths = static_cast<int>(std::min(double(1 << 26), std::round(o.paths * plan.importanceFactor)));
    VplSet set = generateVpls(scene, *rayTracer, o);
    if (plan.importanceFactor > 1.0) {
      VplSelection selection;
      selection.keepFraction = options.vplImportance.keepShare / plan.importanceFactor;
      selection.clampBound = candidateBound;
      selection.seed = o.seed;
      selectVplsByImportance(scene, *rayTracer, texels, set, options.vplImportance, selection);
    }
    return set;
  }

  // The walk so far as one set (the report's counts; powers as the mean of the replicates).
  void combineReplicates() {
    VplSet all = replicates[0];
    all.vpls.clear();
    const float share = 1.0f / static_cast<float>(replicates.size());
    for (auto& power : all.powerPerBounce) power *= share;
    for (size_t r = 0; r < replicates.size(); ++r) {
      for (size_t b = 0; r > 0 && b < replicates[r].powerPerBounce.size(); ++b) {
        if (b >= all.powerPerBounce.size()) all.powerPerBounce.resize(b + 1, glm::dvec3(0.0));
        all.powerPerBounce[b] += replicates[r].powerPerBounce[b] * double(share);
      }
      for (Vpl v : replicates[r].vpls) {
        v.power *= share;
        all.vpls.push_back(v);
      }
      for (size_t b = 0; r > 0 && b < replicates[r].countPerBounce.size(); ++b) {
        if (b >= all.countPerBounce.size()) all.countPerBounce.resize(b + 1, 0);
        all.countPerBounce[b] += replicates[r].countPerBounce[b];
      }
    }
    vpls = std::move(all);
  }

  // Replicate 0 is the walk just made (its clamp settled); replicate 1 pairs it.
  void startReplicates() {
    replicates = {vpls, walkReplicate(1)};
    combineReplicates();
  }

  // One more round: a replicate for each half, its classes and blocks.
  void addRound() {
    timed("vpls", [&] {
      for (int k = 0; k < 2; ++k) replicates.push_back(walkReplicate(replicates.size()));
      combineReplicates();
    });
    for (size_t r = replicates.size() - 2; r < replicates.size(); ++r) appendBlocks(r);
  }

  // Replicate r's interleave classes and their fixed blocks.
  void appendBlocks(size_t r) {
    const VplSet& set = replicates.empty() ? vpls : replicates[r];
    if (classVpls.size() <= r) classVpls.resize(r + 1);
    classVpls[r] = classVplSubsets(set, plan.interleave);
    const size_t blockSize = static_cast<size_t>(std::max(1, options.vplBlock));
    for (size_t c = 0; c < classVpls[r].size(); ++c)
      for (size_t b0 = 0; b0 < classVpls[r][c].vpls.size(); b0 += blockSize)
        blocks.push_back({static_cast<int>(c), b0, std::min(classVpls[r][c].vpls.size(), b0 + blockSize), r});
  }

  // The plan and its evaluator (a GL context is made here where GL may run: its time counts to the backend).
  void chooseBackend() {
    plan = planBake(scene, *rayTracer, options, [&] {
      GlProbe probe;
      part("context", [&] { probe = devices.probeGl(); });
      return probe;
    });
    EvaluatorSettings settings;
    settings.gl = options.gl;
    settings.reference.spp = options.referenceSpp;
    settings.reference.seed = options.walk.seed;
    part("context", [&] { evaluator = makeEvaluator(plan.backend, settings, &devices); });
    devices.release();
  }

  // Interleave classes and the fixed blocks of each class's VPLs: the units shards and checkpoints split.
  void planBlocks() {
    if (plan.backend == BackendKind::Reference || !plan.eval.includeVpls || vpls.vpls.empty()) return;
    settleBlocks(plan, options, texels, surfaceFilters.get());
    // Once for every block, from the first class's pages (the first blocks' own).
    for (const EvaluatorChoice& c : evaluator->settle(inputs(pagesOf(0), vpls, plan.eval)))
      plan.settle(c.key, c.value, c.reason);
    for (size_t r = 0; r < std::max<size_t>(1, replicates.size()); ++r) appendBlocks(r);
    interleaveStats.classes = static_cast<int>(classVpls[0].size());
  }

  // The texel samples of an interleave class as pages of their own (interleave 1: the pages themselves).
  const std::vector<TexelSamples>& pagesOf(int vplClass) {
    if (plan.interleave <= 1) return texels;
    if (pagesClass != vplClass) {
      classPages = interleaveClass(texels, plan.interleave, vplClass % plan.interleave, vplClass / plan.interleave);
      pagesClass = vplClass;
    }
    return classPages;
  }

  // One call of the VPL evaluator; with l1, the same pass also gives the L1 pages (--directional).
  std::vector<Lightmap> runVplBackend(const BakeInputs& in, L1Pages* l1 = nullptr) {
    EvaluationRequest request;
    request.directional = l1;
    std::vector<Lightmap> maps = evaluator->evaluate(in, request);
    ++interleaveStats.backendCalls;
    return maps;
  }

  // RGB triples per texel in the exact sums: the map, and the three L1 pages with --directional.
  int coefficients() const { return plan.directional ? 1 + 3 : 1; }

  void evaluateBlock(size_t index, ExactVplSums& sums, ProgressCallback progress) {
    const VplBlock& block = blocks[index];
    const VplSet& classSet = classVpls[block.replicate][static_cast<size_t>(block.vplClass)];
    VplSet set;
    set.meanReflectivity = classSet.meanReflectivity;
    set.bounces = classSet.bounces;
    set.emittedPower = classSet.emittedPower;
    set.vpls.assign(classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.begin),
                    classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.end));
    const std::vector<TexelSamples>& pages = pagesOf(block.vplClass);
    L1Pages l1;
    const std::vector<Lightmap> maps =
        runVplBackend(inputs(pages, set, vplBlockEval(plan.eval), std::move(progress)), plan.directional ? &l1 : nullptr);
    const int n = plan.interleave, cx = block.vplClass % n, cy = block.vplClass / n;
    for (size_t p = 0; p < maps.size() && p < texels.size(); ++p) {
      const Lightmap& m = maps[p];
      const int fullWidth = texels[p].width;
      for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
          const size_t ct = static_cast<size_t>(y) * m.width + x;
          if (ct >= m.valid.size() || !m.valid[ct]) continue;
          const size_t t = static_cast<size_t>(n * y + cy) * fullWidth + (n * x + cx);
          glm::vec3 value[ExactVplSums::kMaxCoefficients] = {m.texels[ct]};  // L0, then L1x, L1y, L1z
          if (plan.directional)
            for (int k = 0; k < 3; ++k) value[1 + k] = l1[k][p].texels[ct];
          if (!sums.add(p, t, value) || (block.replicate % 2 == 1 && !halfB.add(p, t, value)))
            throw Error(ErrorCode::NumericError, scene.sourcePath,
                        "VPL block " + std::to_string(index) + " gave a non-finite or absurd value (≥ 2^40) at page " +
                            std::to_string(p) + " texel " + std::to_string(t % fullWidth) + "," +
                            std::to_string(t / fullWidth));
        }
    }
  }

  // Punctual lights on every texel, exact and unfiltered (blank valid pages when there are none); with l1,
  // their L1 pages too. With lights left out of the map (plan.leftOut) they are evaluated apart, into
  // leftOutDirect, and added: the stages after read every light's direct light, the written map lacks theirs.
  std::vector<Lightmap> directStage(L1Pages* l1) {
    if (plan.leftOut.empty()) return directCall(l1, {});
    std::vector<uint8_t> written(plan.leftOut.size());
    for (size_t i = 0; i < written.size(); ++i) written[i] = !plan.leftOut[i];
    std::vector<Lightmap> maps = std::find(written.begin(), written.end(), 1) != written.end() ? directCall(nullptr, written)
                                                                                                : directCall(nullptr, {}, true);
    leftOutDirect = directCall(nullptr, plan.leftOut);
    for (size_t p = 0; p < maps.size() && p < leftOutDirect.size(); ++p)
      for (size_t t = 0; t < maps[p].size() && t < leftOutDirect[p].size(); ++t) maps[p].texels[t] += leftOutDirect[p].texels[t];
    return maps;
  }

  // One direct call over the lights marked in `lights` (empty: all), or blank pages (none).
  std::vector<Lightmap> directCall(L1Pages* l1, const std::vector<uint8_t>& lights, bool none = false) {
    if (!none && plan.eval.includeDirect && !scene.lights.empty()) {
      const VplSet noVpls;
      VplEvalOptions e = directEval(plan.eval);
      e.directLights = lights;
      return runVplBackend(inputs(texels, noVpls, e), l1);
    }
    std::vector<Lightmap> maps;
    for (const TexelSamples& ts : texels) {
      maps.push_back(blankLightmap(ts));
      maps.back().valid = ts.valid;
    }
    if (l1)
      for (auto& axis : *l1) axis = maps;
    return maps;
  }

  std::vector<Lightmap> referenceStage() { return evaluator->evaluate(inputs(texels, vpls, plan.eval)); }

  // The backend stage's result: punctual lights plus the VPL sums, classes mixed (or the reference). With
  // l1 (--directional) the L1 pages alike, each coefficient mixed on its own. Each page's sums are freed
  // once rounded: with four coefficients they are the largest thing alive here.
  std::vector<Lightmap> backendMaps(ExactVplSums& sums, nlohmann::json& report, L1Pages* l1) {
    if (plan.backend == BackendKind::Reference) return referenceStage();
    if (!replicates.empty() && !halfB.pages.empty()) halves = mixedHalves(sums);
    std::vector<Lightmap> maps;
    part("direct", [&] { maps = cachedDirect.empty() || l1 ? directStage(l1) : std::move(cachedDirect); });
    cachedDirect = {};
    if (maps.size() != texels.size() || (l1 && (*l1)[0].size() != texels.size()))
      throw Error(ErrorCode::InvalidData, scene.sourcePath, "the backend returned " + std::to_string(maps.size()) +
                                                                " pages for " + std::to_string(texels.size()));
    // On the punctual lights alone, before D is kept for the final gather: its sources see the same edges.
    StageContext ctx = stageContext(report);
    shadowEdgeStage(ctx, maps, l1, leftOutDirect.empty() ? nullptr : &leftOutDirect);
    if (plan.finalGather) {
      directMaps = maps;
      for (size_t p = 0; p < directMaps.size(); ++p)
        if (directMaps[p].valid.size() != directMaps[p].size()) directMaps[p].valid = texels[p].valid;
      if (l1) directL1 = *l1;
    }
    const int coefficients = l1 ? sums.coefficients : 1;
    for (size_t p = 0; p < maps.size(); ++p) {
      std::vector<Lightmap*> pages;  // this page's map, then its L1 pages
      for (int c = 0; c < coefficients; ++c) {
        Lightmap& map = c == 0 ? maps[p] : (*l1)[c - 1][p];
        map.page = static_cast<int>(p);
        if (map.valid.size() != map.size()) map.valid = texels[p].valid;
        pages.push_back(&map);
      }
      if (blocks.empty()) continue;
      const float share = replicates.empty() ? 1.0f : 1.0f / static_cast<float>(replicates.size());  // their mean
      std::vector<std::vector<glm::vec3>> vplParts(coefficients, std::vector<glm::vec3>(texels[p].layerSize()));
      std::vector<const std::vector<glm::vec3>*> parts;
      for (int c = 0; c < coefficients; ++c) {
        tbb::parallel_for(size_t(0), vplParts[c].size(), [&](size_t t) { vplParts[c][t] = sums.value(p, t, c) * share; });
        parts.push_back(&vplParts[c]);
      }
      std::vector<uint8_t> vplValid = std::move(sums.pages[p].valid);
      sums.pages[p] = {};
      addMixedClasses(texels[p], plan.interleave, parts, vplValid, pages, surfaceFilters.get());
    }
    return maps;
  }

  // What the stages after the evaluators read and where they write.
  StageContext stageContext(nlohmann::json& report) {
    return StageContext{scene, *wholeInputs, plan, options.compensation, options.progress, seconds, report};
  }
};

StagedBake::StagedBake(Scene scene, const BakeOptions& options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = options;
  s.scene = std::move(scene);
  if (s.scene.triangleCount() == 0) throw Error(ErrorCode::EmptyScene, s.scene.sourcePath, "no triangles to bake");
  checkOptionRanges(options);
  checkLightModes(options, s.scene);  // a bad light name costs nothing
  s.prepare();
}

StagedBake::~StagedBake() = default;

size_t StagedBake::blockCount() const { return state_->blocks.size(); }
BackendKind StagedBake::backend() const { return state_->plan.backend; }

ExactVplSums StagedBake::emptySums() const {
  return state_->zeroSums();
}

void StagedBake::evaluateBlocks(size_t begin, size_t end, ExactVplSums& sums,
                                const std::function<void(size_t next)>& afterBlock) {
  State& s = *state_;
  end = std::min(end, s.blocks.size());
  if (s.plan.overlapCompensation && !s.gather.valid() && begin == 0 && end == s.blocks.size()) {
    const ClampCompensationOptions o = s.plan.compensation;
    // The gather reads the pages' texel samples and the geometry only: it runs while the GL backend bakes.
    s.gather = std::async(std::launch::async, [&s, o] { return std::make_unique<ClampGather>(*s.wholeInputs, o); });
  }
  s.timed("backend", [&] {
    for (size_t b = begin; b < end; ++b) {
      ProgressCallback progress;
      if (s.options.progress) {
        const double count = static_cast<double>(std::max<size_t>(1, end - begin));
        progress = [&s, b, begin, count](const char* stage, double f) {
          s.options.progress(stage, (static_cast<double>(b - begin) + std::clamp(f, 0.0, 1.0)) / count);
        };
      }
      s.part("evaluate", [&] { s.evaluateBlock(b, sums, progress); });
      if (afterBlock) afterBlock(b + 1);
    }
  });
}

void StagedBake::refineToTarget(ExactVplSums& sums, const std::function<void(size_t next)>& afterBlock) {
  State& s = *state_;
  const ErrorEstimateOptions& o = s.options.errorEstimate;
  if (!s.targeting()) return;
  s.roundSeconds = s.seconds.value("backend", 0.0);  // the first round's: its blocks
  for (;;) {
    double estimate = 0.0;
    s.timed("errorEstimate", [&] { estimate = s.roundEstimate(sums); });
    s.rounds.push_back(s.roundEntry());
    s.rounds.back()["walkError"] = estimate;
    log::info("round " + std::to_string(s.rounds.size()) + ": " + std::to_string(s.replicates.size()) + " replicates, " +
              std::to_string(s.vpls.vpls.size()) + " VPLs, the walk's estimated error " + State::percent(estimate));
    // The walk's figure is no lower than the finished one's walk part, and the ray stages add their own noise:
    // at most the target, the finished figure decides (finish).
    if (estimate <= o.targetError) return;
    if (static_cast<int>(s.rounds.size()) >= o.maxRounds) s.stoppedBy = "max-rounds";
    else if (o.maxSeconds > 0.0 && s.total.seconds() + s.roundSeconds > o.maxSeconds) s.stoppedBy = "max-time";
    if (!s.stoppedBy.empty()) return;
    Stopwatch watch;
    const size_t begin = s.blocks.size();
    s.addRound();
    evaluateBlocks(begin, s.blocks.size(), sums, afterBlock);
    s.roundSeconds = watch.seconds();
  }
}

namespace {
// --target-error aims a raised part at this fraction of the target (the next figure is itself an estimate,
// and aiming at the target itself would often miss it by a hair and cost another round).
constexpr double kTargetAim = 0.9;
// At most this many times the rays per round, and the ray stages' rays at most this many times the plan's.
constexpr double kMaxStageRaysPerRound = 16.0;
constexpr double kMaxStageRays = 1024.0;
}  // namespace

// After the walk's rounds: the ray stages and the finished figure; while it is above the target, another round
// of what dominates it, more of the compensation's and final gather's rays (the stages run again on the same
// input) or more paths (another two replicates, the map made again), until the figure is at most the target
// (stoppedBy "target") or a cap stops it.
void StagedBake::stagesToTarget(ExactVplSums& sums, BakeResult& r) {
  State& s = *state_;
  const ErrorEstimateOptions& o = s.options.errorEstimate;
  if (s.rounds.empty()) s.rounds.push_back(s.roundEntry());
  for (;;) {
    std::vector<Lightmap> input = r.maps;  // the ray stages' input: more rays run them again on it
    L1Pages inputL1 = r.directional;
    Stopwatch watch;
    s.rayStages(r, r.report, true);
    const double stageSeconds = watch.seconds();
    const double total = s.figure.whole.relative, walk = s.figure.breakdown.value("vpls", 0.0);
    nlohmann::json& round = s.rounds.back();
    round["estimatedError"] = total;
    round["breakdown"] = s.figure.breakdown;
    if (total <= o.targetError) {
      s.stoppedBy = "target";
      return;
    }
    if (!s.stoppedBy.empty()) return;  // a cap stopped the walk's rounds
    const double aim2 = (kTargetAim * o.targetError) * (kTargetAim * o.targetError);
    const double walk2 = walk * walk, stages2 = std::max(0.0, total * total - walk2);
    // The larger part is raised: to what the other leaves of the aim, or to half the aim where the other
    // needs more than half (the other is raised next).
    const bool rays = stages2 > walk2;
    const double factor = !rays ? 1.0
                                : std::min({std::max(2.0, stages2 / (walk2 < aim2 / 2 ? aim2 - walk2 : aim2 / 2)),
                                            kMaxStageRaysPerRound, kMaxStageRays / s.stageRays});
    const double forecast = rays ? stageSeconds * factor : s.roundSeconds + stageSeconds;
    if (static_cast<int>(s.rounds.size()) >= o.maxRounds) s.stoppedBy = "max-rounds";
    else if (rays && factor <= 1.0) s.stoppedBy = "max-rays";
    else if (o.maxSeconds > 0.0 && s.total.seconds() + forecast > o.maxSeconds) s.stoppedBy = "max-time";
    if (!s.stoppedBy.empty()) return;
    round["raised"] = rays ? "stageRays" : "paths";
    log::info("round " + std::to_string(s.rounds.size()) + ": estimated error " + State::percent(total) + " (walk " +
              State::percent(walk) + ", ray stages " + State::percent(std::sqrt(stages2)) + "), above the target: " +
              (rays ? "the ray stages' rays x" + State::shortNumber(factor) : std::string("another round of paths")));
    if (rays) {
      s.raiseStageRays(factor);
      r.maps = std::move(input);
      r.directional = std::move(inputL1);
    } else {
      Stopwatch paths;
      const size_t begin = s.blocks.size();
      s.addRound();
      evaluateBlocks(begin, s.blocks.size(), sums);
      s.roundSeconds = paths.seconds();
      s.mapsFromSums(sums, r, r.report);  // a copy: the next round adds to them
    }
    s.rounds.push_back(s.roundEntry());
  }
}

nlohmann::json StagedBake::backendCounts() const {
  nlohmann::json counts = state_->evaluator->counts();
  counts["backendCalls"] = state_->interleaveStats.backendCalls;
  return counts;
}

void StagedBake::addBackendCounts(const nlohmann::json& counts) {
  state_->evaluator->addCounts(counts);
  state_->interleaveStats.backendCalls += counts.value("backendCalls", 0);
}

BakeResult StagedBake::finish(ExactVplSums sums) {
  State& s = *state_;
  BakeResult r;
  nlohmann::json& report = r.report;
  s.classPages = {};
  s.pagesClass = -1;
  // With a target the sums are kept for more rounds (a copy made into the map); otherwise they are rounded
  // into the maps and freed page by page: not needed at the peak (compensation).
  const bool targeting = s.targeting();
  if (targeting) s.mapsFromSums(sums, r, report);
  else s.mapsFromSums(std::move(sums), r, report);
  const bool estimate = !s.halves[0].empty();
  if (targeting && estimate) stagesToTarget(sums, r);
  else s.rayStages(r, report, estimate);
  sums = {};
  if (estimate) s.timed("errorEstimate", [&] {
      s.reportFigure(report);
      r.standardError = std::move(s.figure.errorPages);
    });
  s.halves = {};
  StageContext ctx = s.stageContext(report);
  leaveOutDirect(r.maps, s.leftOutDirect);
  s.leftOutDirect = {};
  r.shadowMask = shadowMaskStage(ctx);
  r.lightModes = s.plan.lightModes;
  r.maskChannels = s.plan.maskChannels;
  s.directMaps = {};
  s.directL1 = {};
  report["surfaceFilters"] = {{"plans", s.surfaceFilters->plansMade()}, {"fallbacks", s.surfaceFilters->fallbacks()}};
  if (s.plan.directional) directionalStage(ctx, r.directional);
  const PostStats post = postStage(ctx, r.maps);
  probeStage(ctx, r.maps, r.probes);
  if (!r.shadowMask.empty()) shadowMaskPostStage(ctx, r.shadowMask);
  s.seconds["bake"] = s.total.seconds();
  describeBake(BakeFacts{s.scene, s.atlas, s.texels, s.vpls, s.options, s.plan, *s.evaluator, s.interleaveStats,
                         s.blocks.size(), s.importanceStats, post},
               report);
  // Everything that differs between two runs of the same bake lives in "timings" (wall clock per stage,
  // the GL stage split, peak memory); the rest of the report is the same bytes every time.
  report["timings"]["seconds"] = s.seconds;
  report["timings"]["backendParts"] = s.backendParts;
  report["timings"]["memoryPeakMiB"] = peakMemoryMiB();
  r.atlas = std::move(s.atlas);
  r.vpls = std::move(s.vpls);
  s.gather = {};
  s.wholeInputs.reset();
  s.rayTracer.reset();  // it refers to the scene, which moves into the result
  r.scene = std::move(s.scene);
  return r;
}

BakeResult bake(Scene scene, const BakeOptions& options) {
  StagedBake staged(std::move(scene), options);
  ExactVplSums sums = staged.emptySums();
  staged.evaluateBlocks(0, staged.blockCount(), sums);
  staged.refineToTarget(sums);
  return staged.finish(std::move(sums));
}

}  // namespace irbake
