// The light the cut lights' fade leaves out (lights/light_reach.h), bounded against the finished map.
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "pipeline/bake_state.h"
#include "transport/geometry_term.h"

namespace irbake {

namespace {

// Texel samples the bound is measured at, at most: every k-th valid texel of every page.
constexpr size_t kBoundTexels = 8192;

// The cut lights as they would be without the cut.
std::vector<std::pair<const Light*, Light>> uncutLights(const Scene& scene) {
  std::vector<std::pair<const Light*, Light>> out;
  for (const Light& l : scene.lights)
    if (l.cutoff > 0.0f) {
      Light whole = l;
      whole.cutoff = 0.0f;
      out.emplace_back(&l, whole);
    }
  return out;
}

}  // namespace

void measureLightCut(BakeState& s, const std::vector<Lightmap>& maps, nlohmann::json& report) {
  s.lightCutBound = 0.0;
  if (!s.lightGrid || !s.lightGrid->culls()) return;
  const auto cut = uncutLights(s.scene);
  nlohmann::json& j = report["lightCull"];
  j = {{"fraction", s.options.lightCull.fraction}, {"reference", s.lightReach.reference},
       {"threshold", s.lightReach.threshold}, {"lights", s.scene.lights.size()}, {"cutLights", cut.size()},
       {"lookups", s.lightGrid->lookups()}};
  if (cut.empty()) return;
  // Each sampled texel's left-out light with no shadow (at least what the cut took from it) and its map value.
  size_t valid = 0;
  for (size_t p = 0; p < maps.size() && p < s.texels.size(); ++p)
    valid += static_cast<size_t>(std::count(maps[p].valid.begin(), maps[p].valid.end(), uint8_t(1)));
  const size_t stride = std::max<size_t>(1, valid / kBoundTexels);
  std::vector<std::pair<size_t, size_t>> picked;
  for (size_t p = 0, k = 0; p < maps.size() && p < s.texels.size(); ++p)
    for (size_t t = 0; t < maps[p].size() && t < maps[p].valid.size(); ++t)
      if (maps[p].valid[t] && s.texels[p].positionWeight[t].w > 0.0f && k++ % stride == 0) picked.emplace_back(p, t);
  std::vector<double> dropped(picked.size(), 0.0), kept(picked.size(), 0.0);
  tbb::parallel_for(size_t(0), picked.size(), [&](size_t k) {
    const auto [p, t] = picked[k];
    const glm::vec3 x(s.texels[p].positionWeight[t]), n(s.texels[p].normal[t]);
    glm::vec3 d(0.0f);
    for (const auto& [faded, whole] : cut) d += punctualDirect(whole, x, n).mapValue - punctualDirect(*faded, x, n).mapValue;
    dropped[k] = channelMean(glm::max(d, glm::vec3(0.0f)));
    kept[k] = channelMean(maps[p].texels[t]);
  });
  double sumSquares = 0.0, sumDropped = 0.0, sumKept = 0.0;
  for (size_t k = 0; k < picked.size(); ++k) {
    sumSquares += dropped[k] * dropped[k];
    sumDropped += dropped[k];
    sumKept += kept[k];
  }
  const double meanKept = picked.empty() ? 0.0 : sumKept / double(picked.size());
  if (meanKept > 0.0) s.lightCutBound = std::sqrt(sumSquares / double(picked.size())) / meanKept;
  j["cutBound"] = {{"relative", s.lightCutBound}, {"relativeMean", meanKept > 0.0 ? sumDropped / sumKept : 0.0},
                   {"texels", picked.size()},
                   {"covers", "the light the cut lights leave out with no shadow (at least what the cut took), RMS over "
                              "the texels over the map's mean"}};
}

}  // namespace irbake
