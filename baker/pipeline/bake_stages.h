// The stages after the evaluators, in the order the bake runs them: shadow edges (on the punctual lights'
// map), sky, clamp compensation, final gather, directional pages, post. Each reads its options from the plan.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"
#include "lightmap/probe_grid.h"
#include "pipeline/bake_plan.h"
#include "post/post.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/shadow_mask/shadow_mask.h"

namespace irbake {

// What the stages share: the scene, every page and VPL (BakeInputs), the plan; each stage adds its wall and CPU
// time to `seconds` and `cpuSeconds` and its stats, as its own object, to `report`.
struct StageContext {
  const Scene& scene;
  const BakeInputs& inputs;
  BakePlan& plan;
  const ClampCompensationOptions& askedCompensation;  // as given (the plan records what auto chose)
  const ProgressCallback& progress;
  nlohmann::json& seconds;
  nlohmann::json& cpuSeconds;  // the process's CPU seconds per stage, beside `seconds`
  nlohmann::json& report;

  void timed(const char* name, const std::function<void()>& stage);
};

// Punctual lights' shadow edges area-averaged, on their map alone (l1: scaled with it); leftOut: the direct
// pages of the lights left out of the map (plan.leftOut), refined on the same edge texels; cutLight: the cut
// lights' left-out light per page and texel, unshadowed (refineShadowEdges).
void shadowEdgeStage(StageContext& ctx, std::vector<Lightmap>& maps, L1Pages* l1,
                     std::vector<Lightmap>* leftOut = nullptr, const CutLightPages* cutLight = nullptr);
// The sky's direct light, traced (every VPL evaluator; the reference integrator finds the sky itself).
// Under the final gather an environment map's light goes into its D (direct) as well. traced: the sky's own
// pages as added (the error estimate traces them again), or null.
void skyStage(StageContext& ctx, std::vector<Lightmap>& maps, std::vector<Lightmap>& direct,
              std::vector<Lightmap>* traced = nullptr);
// The clamp's lost near-field light gathered back from the map; traced: its rays traced beforehand (beside
// the GL evaluator), or null.
void compensationStage(StageContext& ctx, std::vector<Lightmap>& maps, L1Pages* l1,
                       std::unique_ptr<ClampGather> traced);
// Each texel's bounced light read from the finished map one bounce away; direct: D (and its L1 pages).
void finalGatherStage(StageContext& ctx, const std::vector<Lightmap>& direct, const L1Pages* directL1,
                      std::vector<Lightmap>& maps, L1Pages* l1);
// Mixed lighting: the left-out lights' direct light taken out of the finished map (never below 0), after
// every stage that reads the map one bounce away.
void leaveOutDirect(std::vector<Lightmap>& maps, const std::vector<Lightmap>& leftOut);
// The shadow-mask lights' visibility pages (empty when there are none).
ShadowMaskPages shadowMaskStage(StageContext& ctx);
// Dilation and seams on the shadow-mask pages, as on the map's.
void shadowMaskPostStage(StageContext& ctx, ShadowMaskPages& mask);
// The L1 pages' sky share, then post per axis.
void directionalStage(StageContext& ctx, L1Pages& axes);
// Dilation and seams on the map pages.
PostStats postStage(StageContext& ctx, std::vector<Lightmap>& maps);
// Irradiance probes read from the final maps (after post: the seam stitching moves valid texels, not only
// padding, and the probes must see the map the export writes); grid left empty when the plan has none.
void probeStage(StageContext& ctx, const std::vector<Lightmap>& maps, LightProbeGrid& grid);

}  // namespace irbake
