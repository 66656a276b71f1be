// What a bake's stages have produced so far, as one plain record (BakeState), and the stage runners that
// fill it: StagedBake (pipeline/bake.h) owns the record and calls the runners in order. Internal to
// baker/pipeline: the record changes as the stages do.
#pragma once
#include <array>
#include <cstddef>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "common/progress.h"
#include "evaluators/evaluator.h"
#include "lightmap/lightmap.h"
#include "pipeline/bake.h"
#include "pipeline/bake_options.h"
#include "pipeline/bake_plan.h"
#include "pipeline/bake_prediction.h"
#include "pipeline/bake_stages.h"
#include "pipeline/evaluator_factory.h"
#include "pipeline/vpl_sums.h"
#include "raytrace/ray_tracer.h"
#include "scene/footprint_albedo.h"
#include "scene/scene.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/error_estimate/error_estimate.h"
#include "stages/gather/final_gather.h"
#include "stages/interleave/interleaved_sampling.h"
#include "texels/surface_filter_cache.h"
#include "texels/texel_samples.h"
#include "transport/vpl_importance.h"
#include "vpl/vpl.h"

namespace irbake {

// A contiguous range of one interleave class's VPLs, of one replicate of the walk (0 without an error estimate).
struct VplBlock {
  int vplClass = 0;
  size_t begin = 0, end = 0;
  size_t replicate = 0;
};

// The finished bake's error figure (before post, on the map as the stages left it): the walk's noise and the
// ray stages' own, on every valid texel's bins and on the interior ones.
struct ErrorFigure {
  BinnedError whole, interior;
  nlohmann::json breakdown, interiorBreakdown;  // each part relative to the same signal
  std::vector<Lightmap> errorPages;             // with --error-map: each texel's standard error
};

struct BakeState {
  // The inputs and the preparation (bake_prepare.cpp).
  BakeOptions options;
  Scene scene;
  std::vector<Primitive> objectsOff;       // extras.irbake.mode "off": out of the bake, back in the result's scene
  AtlasResult atlas;
  std::unique_ptr<RayTracer> rayTracer;
  std::vector<TexelSamples> texels;
  VplSet vpls;
  VplSet sceneWalk;                        // the plan's walk at seed 0: the derived clamp's N and the importance
                                           // pilot read it, so both are settled once per scene
  BakePlan plan;                           // every automatic choice, settled once
  BakePrediction prediction;               // the preflight's time and memory, made before any work (report "prediction")
  VplImportanceStats importanceStats;
  EvaluatorDevices devices;                // the GL context, while the plan may choose GL
  std::unique_ptr<Evaluator> evaluator;    // the plan's, made once it is chosen (it keeps its own figures)
  std::unique_ptr<FootprintAlbedo> footprintAlbedo;  // hit albedo for the compensation and the gather (one for both)
  std::unique_ptr<BakeInputs> wholeInputs;           // every page and VPL: the sky and the gather read them
  std::unique_ptr<SurfaceFilterCache> surfaceFilters;  // each page's neighbour tests, made once for all filters
  LightReach lightReach;                   // each light's reach (lights/light_reach.h)
  std::unique_ptr<LightGrid> lightGrid;    // the lights near each point, for every stage's per-light loop
  double lightCutBound = 0.0;              // the cut's bound, relative to the map's mean (measureLightCut)
  LightTailStats lightTail;                // the left-out light sampled back (backendMaps)
  double lightTailNoise = 0.0;             // its noise, relative to the map's mean (measureLightCut)

  // The VPL blocks (walk_replicates.cpp, backend_maps.cpp).
  std::vector<std::vector<VplSet>> classVpls;  // per replicate of the walk, per interleave class
  std::vector<VplBlock> blocks;
  int pagesClass = -1;                   // the class classPages holds (blocks run class by class, so one
  std::vector<TexelSamples> classPages;  // class's texel copy at a time: 1/n² of the samples' memory)
  InterleaveStats interleaveStats;
  std::future<std::unique_ptr<ClampGather>> gather;  // traced while the GL backend bakes (GPU only)

  // The maps' direct light (backend_maps.cpp).
  std::vector<Lightmap> directMaps;     // the final gather's D: punctual lights and sky, exact
  std::vector<Lightmap> leftOutDirect;  // mixed lighting: the direct light of the lights not baked, in every
                                        // stage's map, taken out of what is written
  L1Pages directL1;                     // with --directional: D's L1 pages
  std::vector<Lightmap> cachedDirect;   // the punctual lights' pages, made once for the rounds

  // The error estimate (stages/error_estimate; error_figure.cpp): the walk as independent replicates, each a
  // whole estimate of the VPL light; the even ones form half A, the odd ones half B, and their spread is the
  // estimate.
  std::vector<VplSet> replicates;               // empty without an estimate
  ExactVplSums halfB;                           // the odd replicates' sum (the bake's sums hold them all)
  std::array<std::vector<Lightmap>, 2> halves;  // both halves mixed like the map (finish)
  float candidateBound = 0.0f;                  // the importance selection's bound, for every replicate
  double gatherNoiseRatio = 0.0;                // the final gather's noise over the mixed halves' (once)
  nlohmann::json rounds = nlohmann::json::array();  // the estimate after each round
  std::string stoppedBy;
  double roundSeconds = 0.0;                 // the last round of paths' blocks (the time cap's forecast)
  double stageRays = 1.0;                    // --target-error: the ray stages' rays over the plan's
  ClampCompensationOptions planCompensation;  // the plan's ray stages, before the target raised their rays
  FinalGatherOptions planGather;
  nlohmann::json stageNoise = nlohmann::json::object();          // a stage's own ray noise (RMS on bins, map units)
  nlohmann::json stageNoiseInterior = nlohmann::json::object();  // the same on interior bins (BinTexels)
  bool skyNoiseMeasured = false;
  std::vector<Lightmap> skyShift;  // under the final gather: the sky traced with another seed less the bake's
  ErrorFigure figure;                                             // the last one measured

  // Wall clock and the process's CPU time per stage (report "timings": seconds, cpuSeconds).
  nlohmann::json seconds = nlohmann::json::object();
  nlohmann::json cpuSeconds = nlohmann::json::object();
  nlohmann::json backendParts = nlohmann::json::object();  // the backend stage's split (timings.backendParts)
  Stopwatch total;
};

// Each stage records its wall and CPU time under its name.
template <class Stage>
void timed(BakeState& s, const char* name, Stage&& stage) {
  Stopwatch watch;
  stage();
  s.seconds[name] = s.seconds.value(name, 0.0) + watch.seconds();
  s.cpuSeconds[name] = s.cpuSeconds.value(name, 0.0) + watch.cpuSeconds();
}
// A part of the backend stage (inside its timed call): the GL context, the blocks' plan, the evaluator
// calls, the maps (the punctual lights' "direct" call, their shadow edges and the classes' mix).
template <class Part>
void part(BakeState& s, const char* name, Part&& work) {
  Stopwatch watch;
  work();
  s.backendParts[name] = s.backendParts.value(name, 0.0) + watch.seconds();
}

// What every runner reads (bake_state.cpp).
ProgressCallback withProgress(const BakeState& s, ProgressCallback cb);
BakeInputs inputs(const BakeState& s, const std::vector<TexelSamples>& pages, const VplSet& set,
                  const VplEvalOptions& e, ProgressCallback progress = {});
// What the stages after the evaluators read and where they write.
StageContext stageContext(BakeState& s, nlohmann::json& report);
// Whether the bake estimates its error (a VPL backend with VPL light), and whether it aims at a target.
bool estimating(const BakeState& s);
bool targeting(const BakeState& s);
// RGB triples per texel in the exact sums: the map, and the three L1 pages with --directional.
int coefficients(const BakeState& s);
// Zero sums for every texel a backend can return valid (GL and Embree keep the samples' valid flags).
ExactVplSums zeroSums(const BakeState& s);
// The texel samples of an interleave class as pages of their own (interleave 1: the pages themselves).
const std::vector<TexelSamples>& pagesOf(BakeState& s, int vplClass);

// The preparation (bake_prepare.cpp): atlas, ray tracer, texel samples, the plan and its evaluator, the
// walk and its importance selection, the clamp, the replicates, the VPL blocks.
void prepare(BakeState& s);

// The walk's replicates and the blocks (walk_replicates.cpp).
WalkOptions replicateWalk(const BakeState& s, size_t i);
void startReplicates(BakeState& s);
// One more round: a replicate for each half, its classes and blocks.
void addRound(BakeState& s);
// Replicate r's interleave classes and their fixed blocks.
void appendBlocks(BakeState& s, size_t r);

// The evaluator's calls and the maps made of them (backend_maps.cpp).
void evaluateBlock(BakeState& s, size_t index, ExactVplSums& sums, ProgressCallback progress);
std::vector<Lightmap> directStage(BakeState& s, L1Pages* l1);
// The map from the VPL sums (moved in: freed page by page as they are rounded), with the sky's light.
void mapsFromSums(BakeState& s, ExactVplSums sums, BakeResult& r, nlohmann::json& report);

// The error estimate's rounds and figure (error_figure.cpp).
double roundEstimate(BakeState& s, const ExactVplSums& sums);
std::array<std::vector<Lightmap>, 2> mixedHalves(const BakeState& s, const ExactVplSums& sums);
// The stages that trace rays of their own, on r's maps (and L1 pages): the clamp compensation and the final
// gather; when estimating, each run a second time with another seed, then the figure (into s.figure).
void rayStages(BakeState& s, BakeResult& r, nlohmann::json& report, bool estimate);
// The sky stage's own ray noise, from its pages as the bake traced them (error_figure.cpp).
void skyRayNoise(BakeState& s, const std::vector<Lightmap>& sky);
void reportFigure(const BakeState& s, nlohmann::json& report);
// light_cut_figure.cpp: the light the cut lights' fade leaves out, bounded at a subset of the texels against the
// finished map, into report["lightCull"] and s.lightCutBound.
void measureLightCut(BakeState& s, const std::vector<Lightmap>& maps, nlohmann::json& report);
nlohmann::json roundEntry(const BakeState& s);
void raiseStageRays(BakeState& s, double factor);
std::string percent(double x);
std::string shortNumber(double x);

}  // namespace irbake
