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
  s.lightTailNoise = 0.0;
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
  // Per texel: what the cut took with no shadow (a bound) and with each light's shadow ray (what it took).
  std::vector<double> bound(picked.size(), 0.0), taken(picked.size(), 0.0), kept(picked.size(), 0.0);
  const RayTracer& rt = *s.rayTracer;
  tbb::parallel_for(size_t(0), picked.size(), [&](size_t k) {
    const auto [p, t] = picked[k];
    const glm::vec3 x(s.texels[p].positionWeight[t]), n(s.texels[p].normal[t]);
    for (const auto& [faded, whole] : cut) {
      const PunctualContribution w = punctualDirect(whole, x, n);
      const double d = channelMean(w.mapValue - punctualDirect(*faded, x, n).mapValue);
      if (!(d > 0.0)) continue;
      bound[k] += d;
      if (!rt.occluded(x + n * rt.epsilon(), w.toLight, 0.0f, w.distance - rt.epsilon())) taken[k] += d;
    }
    kept[k] = channelMean(maps[p].texels[t]);
  });
  auto rmsOverMean = [&](const std::vector<double>& v) {
    double squares = 0.0, mean = 0.0;
    for (size_t k = 0; k < v.size(); ++k) squares += v[k] * v[k], mean += kept[k];
    return mean > 0.0 ? std::sqrt(squares / double(v.size())) / (mean / double(v.size())) : 0.0;
  };
  const double takenRelative = rmsOverMean(taken);
  j["cutBound"] = {{"relative", takenRelative}, {"unshadowedRelative", rmsOverMean(bound)}, {"texels", picked.size()},
                   {"covers", "the light the cut lights' fade took at the texels (relative: with their shadow rays; "
                              "unshadowedRelative: without, a bound), RMS over the texels over the map's mean"}};
  // Sampled back (stages/light_tail), the cut leaves no bias, only the samples' noise: RMS over the texels of
  // the estimate's standard deviation, over the map's mean (before the post's filters, which only lower it).
  if (s.lightTail.texels > 0) {
    double mean = 0.0;
    for (double k : kept) mean += k;
    mean /= double(std::max<size_t>(1, kept.size()));
    s.lightTailNoise = mean > 0.0 ? std::sqrt(s.lightTail.variance / double(s.lightTail.texels)) / mean : 0.0;
    j["tailNoise"] = {{"relative", s.lightTailNoise},
                      {"covers", "the sampled-back left-out light's noise, RMS over the texels over the map's mean"}};
  } else {
    s.lightCutBound = takenRelative;
  }
}

}  // namespace irbake
