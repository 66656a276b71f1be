// The report's description of a bake: what was baked and how, each stage's stats as its own object.
#include "pipeline/bake_report.h"

#include <algorithm>


namespace irbake {

void describeBake(const BakeFacts& f, nlohmann::json& report) {
  size_t texelCount = 0, covered = 0, valid = 0;
  for (const auto& t : f.texels) {
    texelCount += t.layerSize();
    for (auto c : t.covered) covered += c != 0;
    for (auto v : t.valid) valid += v != 0;
  }
  report["backendChoice"] = {{"asked", toString(f.options.backend)},
                             {"used", toString(f.plan.backend)},
                             {"reason", f.plan.choices.at("backend").reason}};
  report["compensationOverlapped"] = f.plan.overlapCompensation;
  report["backend"] = toString(f.plan.backend);
  if (f.plan.backend != BackendKind::Reference) {
    report["interleave"] = f.interleave.toJson();
    report["interleave"]["vplBlocks"] = f.vplBlocks;
    report["interleave"]["vplsPerBlock"] = f.options.vplBlock;
  }
  const glm::dvec3 emitted(f.scene.emitterPower());
  report["scene"] = {{"source", f.scene.sourcePath},
                     {"triangles", f.scene.triangleCount()},
                     {"primitives", f.scene.primitives.size()},
                     {"lights", f.scene.lights.size()},
                     {"emitterPower", nlohmann::json::array({emitted.x, emitted.y, emitted.z})}};
  if (f.scene.stats.gpuInstances > 0)
    report["scene"]["gpuInstancing"] = {{"nodes", f.scene.stats.gpuInstancedNodes},
                                        {"instances", f.scene.stats.gpuInstances},
                                        {"export", "EXT_mesh_gpu_instancing dropped: each instance written as a node of its own, with its own light-map region"}};
  if (!f.scene.stats.decodedExtensions.empty()) report["scene"]["decodedExtensions"] = f.scene.stats.decodedExtensions;
  report["atlas"] = f.atlas.toJson();
  report["texels"] = {{"total", texelCount}, {"covered", covered}, {"valid", valid},
                      {"supersample", std::max(1, f.options.texels.supersample)},
                      {"leakControl", f.options.texels.leakControl}};
  report["vpls"] = f.vpls.toJson();
  report["vpls"]["paths"] = f.plan.walk.paths;
  report["vpls"]["walkFactor"] = f.plan.walk.walkFactor;  // paths × walkFactor walked, resampled to `count`
  report["vpls"]["seed"] = f.options.walk.seed;
  if (f.plan.importanceFactor > 1.0 || f.importance.evenness > 0.0) report["vplImportance"] = f.importance.toJson();
  report["eval"] = {{"clampBound", f.plan.eval.clampBound},
                    {"clampVplsPerMean", f.plan.clampK},
                    {"clampDerived", f.plan.clampDerived},
                    {"biasCompensation", f.plan.eval.biasCompensation}};
  report["post"] = f.post.toJson();
  report["plan"] = f.plan.toJson();
  f.evaluator.describe(report);
}

}  // namespace irbake
