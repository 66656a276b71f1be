// The report's description of a finished bake (report.json): scene, atlas, texels, VPLs, evaluator, clamp,
// post and the plan; the stages add their own objects as they run.
#pragma once
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "evaluators/evaluator.h"
#include "pipeline/bake_options.h"
#include "pipeline/bake_plan.h"
#include "post/post.h"
#include "scene/scene.h"
#include "stages/interleave/interleaved_sampling.h"
#include "texels/texel_samples.h"
#include "transport/vpl_importance.h"
#include "vpl/vpl.h"

namespace irbake {

struct BakeFacts {
  const Scene& scene;
  const AtlasResult& atlas;
  const std::vector<TexelSamples>& texels;
  const VplSet& vpls;
  const BakeOptions& options;
  const BakePlan& plan;
  const Evaluator& evaluator;  // adds its own objects (Evaluator::describe)
  const InterleaveStats& interleave;
  size_t vplBlocks = 0;
  const VplImportanceStats& importance;
  const PostStats& post;
};

void describeBake(const BakeFacts& facts, nlohmann::json& report);

}  // namespace irbake
