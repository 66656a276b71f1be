#include "testing/backend_stage.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "stages/interleave/interleaved_sampling.h"

namespace irbake::testing {
namespace {

// The punctual lights alone (the bake's directEval), or blank pages whose valid flags are the samples'.
std::vector<Lightmap> directMaps(const BakeInputs& in, const Evaluator& evaluator, int& calls) {
  std::vector<Lightmap> maps;
  if (in.eval.includeDirect && !in.scene.lights.empty()) {
    const VplSet none;
    BakeInputs direct{in.scene, in.rayTracer, in.texels, none, in.eval, {}};
    direct.eval.includeVpls = false;
    direct.eval.biasCompensation = false;
    maps = evaluator.evaluate(direct);
    ++calls;
  } else {
    for (const TexelSamples& ts : in.texels) maps.push_back(blankLightmap(ts));
  }
  for (size_t p = 0; p < maps.size() && p < in.texels.size(); ++p)
    if (maps[p].valid.size() != maps[p].size()) maps[p].valid = in.texels[p].valid;
  return maps;
}

}  // namespace

std::vector<Lightmap> bakeBackendStage(const BakeInputs& in, int n, const Evaluator& evaluator, int* backendCalls) {
  n = std::max(1, n);
  int calls = 0;
  std::vector<Lightmap> maps = directMaps(in, evaluator, calls);
  if (in.eval.includeVpls && !in.vpls.vpls.empty()) {
    std::vector<std::vector<glm::vec3>> vplPart(in.texels.size());
    std::vector<std::vector<uint8_t>> vplValid(in.texels.size());
    for (size_t p = 0; p < in.texels.size(); ++p) {
      vplPart[p].assign(in.texels[p].layerSize(), glm::vec3(0.0f));
      vplValid[p].assign(in.texels[p].layerSize(), 0);
    }
    const std::vector<VplSet> subsets = classVplSubsets(in.vpls, n);
    for (size_t c = 0; c < subsets.size(); ++c) {
      if (subsets[c].vpls.empty()) continue;  // the bake makes no block of an empty class
      const int cx = static_cast<int>(c) % n, cy = static_cast<int>(c) / n;
      const std::vector<TexelSamples> pages = n > 1 ? interleaveClass(in.texels, n, cx, cy) : in.texels;
      BakeInputs part{in.scene, in.rayTracer, pages, subsets[c], in.eval, {}};
      part.eval.includeDirect = false;
      part.eval.biasCompensation = false;
      const std::vector<Lightmap> classMaps = evaluator.evaluate(part);
      ++calls;
      // Class texel (x, y) is texel (n·x + cx, n·y + cy) of its page; only the texels the backend found valid count.
      for (size_t p = 0; p < classMaps.size() && p < in.texels.size(); ++p) {
        const Lightmap& m = classMaps[p];
        for (int y = 0; y < m.height; ++y)
          for (int x = 0; x < m.width; ++x) {
            const size_t ct = static_cast<size_t>(y) * m.width + x;
            if (ct >= m.valid.size() || !m.valid[ct]) continue;
            const size_t t = static_cast<size_t>(n * y + cy) * in.texels[p].width + (n * x + cx);
            vplPart[p][t] += m.texels[ct];
            vplValid[p][t] = 1;
          }
      }
    }
    for (size_t p = 0; p < maps.size() && p < in.texels.size(); ++p)
      addMixedClasses(in.texels[p], n, {&vplPart[p]}, vplValid[p], {&maps[p]}, in.surfaceFilters);
  }
  if (backendCalls) *backendCalls = calls;
  return maps;
}

}  // namespace irbake::testing
