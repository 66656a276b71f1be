// The preflight: the bake predicted from the scene and the options alone, without unwrapping or tracing
// anything: the atlas estimate, the plan (what needs the bake itself marked "settled at bake"), the cost
// model's time and memory, and the warnings the bake would give. `irbake plan` prints it; the bake writes
// its prediction into report.json and refuses up front one over --max-memory.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas_estimate.h"
#include "pipeline/bake_options.h"
#include "pipeline/bake_plan.h"
#include "pipeline/cost_model.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"

namespace irbake {

struct BakePrediction {
  AtlasEstimate atlas;
  BakePlan plan;                       // settled as far as the scene and options allow
  CostInputs inputs;
  CostPrediction cost;
  std::vector<std::string> warnings;   // what the bake would warn
  // {"atlas", "plan", "inputs", "prediction", "warnings"}
  nlohmann::json toJson() const;
};

// The choice a bake settles from what it has made (texels, the walk, the GL context), shown by the plan as this.
inline const char* kSettledAtBake = "settled at bake";

// Predicts the bake of `scene` (lights added) with `options` on `cores` cores. Logs nothing; throws Error(Usage)
// where the bake would refuse the options before tracing (light modes, the probe budget). Its rays are weighed by
// the ray pilot over a tracer of its own, or, with weighRays false, left at the reference scene's cost (the bake
// weighs them once it has built its tracer; the memory does not depend on them).
BakePrediction predictBake(const Scene& scene, const BakeOptions& options, double cores, bool weighRays = true);

// The ray pilot over `rt` (the scene's tracer) sets the prediction's cost per ray, and its time anew.
void weighRays(BakePrediction& prediction, const Scene& scene, const RayTracer& rt);

// The cores a bake uses here: TBB's limit (--threads sets it).
double bakeCores();

// Throws Error(Usage) naming the scene when the predicted peak memory is over maxMemoryGB (GB of 10^9
// bytes; 0: no limit).
void checkMemoryLimit(const BakePrediction& prediction, double maxMemoryGB, const std::string& scenePath);

}  // namespace irbake
