#include "stages/shadow_mask/shadow_mask.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "common/progress.h"
#include "lights/light_kind.h"
#include "stages/shadow_edges/texel_square.h"

namespace irbake {

namespace {

float channelMax(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// Unit direction from x towards the light and the distance to it (infinite for a directional light).
void towardLight(const Light& light, const glm::vec3& x, glm::vec3& dir, float& distance) {
  const LightKind& kind = lightKind(light.type);
  const glm::vec3 d = kind.toward(light, x);
  if (kind.atInfinity()) {
    dir = d;
    distance = INFINITY;
    return;
  }
  distance = glm::length(d);
  dir = distance > 0.0f ? d / distance : glm::vec3(0.0f, 0.0f, 1.0f);
}

// 1 where nothing stands between origin and the light, 0 where something opaque does, the see-through
// surfaces' transmittance (channel mean) between.
float visibility(const RayTracer& rt, const Light& light, const glm::vec3& x, const glm::vec3& origin) {
  glm::vec3 dir;
  float distance;
  towardLight(light, x, dir, distance);
  const float tmax = std::isinf(distance) ? 1e30f : distance - rt.epsilon();
  if (!(tmax > 0.0f)) return 1.0f;
  if (rt.occluded(origin, dir, 0.0f, tmax)) return 0.0f;
  if (!rt.hasTransmission()) return 1.0f;
  const glm::vec3 tr = rt.transmittance(origin, dir, 0.0f, tmax);
  return (tr.x + tr.y + tr.z) / 3.0f;
}

// One light's visibility per texel at its samples (coverage-weighted); -1 where the light does not reach the
// texel or the texel is not valid.
std::vector<float> centreVisibility(const BakeInputs& in, const TexelSamples& ts, const Light& light, float threshold) {
  const RayTracer& rt = in.rayTracer;
  std::vector<float> vis(ts.layerSize(), -1.0f);
  const size_t layer = ts.layerSize();
  const int layers = ts.supersample * ts.supersample;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, layer, 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      if (!ts.valid[t]) continue;
      double sum = 0.0, weight = 0.0;
      for (int k = 0; k < layers; ++k) {
        const size_t s = static_cast<size_t>(k) * layer + t;
        const float w = ts.positionWeight[s].w;
        if (w <= 0.0f || ts.primitive[s] >= in.scene.primitives.size()) continue;
        const glm::vec3 x = rt.insetPoint(ts.primitive[s], ts.triangle[s], glm::vec3(ts.positionWeight[s]));
        if (!lightInfluences(light, x, threshold)) continue;
        sum += w * visibility(rt, light, x, x + glm::vec3(ts.normal[s]) * rt.epsilon());
        weight += w;
      }
      if (weight > 0.0) vis[t] = static_cast<float>(sum / weight);
    }
  });
  return vis;
}

// Texels a shadow edge crosses get the lit share of their own square (pages with one sample per texel only:
// supersampled ones already spread their samples over the square).
void refineEdges(const BakeInputs& in, const TexelSamples& ts, const Light& light, const ShadowMaskOptions& options,
                 std::vector<float>& vis, ShadowMaskStats& stats) {
  if (options.subSamples <= 1 || ts.supersample != 1) return;
  const std::vector<uint8_t> edge = edgeTexels(vis, ts.width, ts.height, options.jump);
  const SquareTriangles squares = squareTriangles(in.scene, ts, edge);
  std::atomic<size_t> edges{0}, points{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.layerSize(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      if (!edge[t]) continue;
      SquareMean mean;
      const bool sampled = averageOverTexelSquare(
          in, ts, t, options.subSamples, &squares,
          [&](const glm::vec3& xs, const glm::vec3&, const glm::vec3& origin, glm::vec3* values) {
            values[0] = glm::vec3(visibility(in.rayTracer, light, xs, origin));
            return values[0].x > 0.0f;
          },
          mean);
      points += static_cast<size_t>(mean.points);
      if (!sampled || mean.kept == 0) continue;
      vis[t] = static_cast<float>(mean.sum[0].x / mean.kept);
      ++edges;
    }
  });
  stats.edgeTexels += edges;
  stats.subPoints += points;
}

}  // namespace

bool lightInfluences(const Light& light, const glm::vec3& x, float threshold) {
  return lightKind(light.type).influences(light, x, threshold);
}

int ShadowMaskChannels::used() const {
  int n = 0;
  for (int c : channel) n = std::max(n, c + 1);
  return n;
}

nlohmann::json ShadowMaskChannels::toJson(const Scene& scene) const {
  nlohmann::json lights = nlohmann::json::array(), fell = nlohmann::json::array();
  for (size_t i = 0; i < channel.size(); ++i)
    if (channel[i] >= 0) lights.push_back({{"light", scene.lights[i].name}, {"index", i}, {"channel", channel[i]}});
  for (size_t i : fellBack) fell.push_back(scene.lights[i].name);
  return {{"channels", used()}, {"lights", lights}, {"fellBackToIndirect", fell}};
}

ShadowMaskChannels assignShadowMaskChannels(const Scene& scene, const std::vector<TexelSamples>& texels,
                                            const std::vector<uint8_t>& wants, const ShadowMaskOptions& options,
                                            const LightGrid* grid) {
  const size_t n = scene.lights.size();
  ShadowMaskChannels result;
  result.channel.assign(n, -1);
  std::vector<size_t> asked;
  for (size_t i = 0; i < n && i < wants.size(); ++i)
    if (wants[i]) asked.push_back(i);
  if (asked.empty()) return result;
  // Two lights overlap where both reach one valid texel sample.
  tbb::combinable<std::vector<uint8_t>> local([n] { return std::vector<uint8_t>(n * n, 0); });
  for (const TexelSamples& ts : texels)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.slotCount(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<uint8_t>& overlap = local.local();
      std::vector<size_t> reached;
      for (size_t s = r.begin(); s != r.end(); ++s) {
        if (ts.positionWeight[s].w <= 0.0f || !ts.valid[s % ts.layerSize()]) continue;
        reached.clear();
        const glm::vec3 x(ts.positionWeight[s]);
        const LightSpan near = grid ? grid->near(x) : LightSpan{nullptr, static_cast<uint32_t>(n)};
        for (uint32_t i : near)
          if (i < wants.size() && wants[i] && lightInfluences(scene.lights[i], x, options.influenceThreshold)) reached.push_back(i);
        for (size_t a : reached)
          for (size_t b : reached) overlap[a * n + b] = 1;
      }
    });
  std::vector<uint8_t> overlap(n * n, 0);
  local.combine_each([&](const std::vector<uint8_t>& o) {
    for (size_t k = 0; k < o.size(); ++k) overlap[k] |= o[k];
  });
  // Greedy colouring, brightest first (colour × intensity, then the scene's order): the lights that matter
  // most keep their masks when four channels do not suffice.
  std::stable_sort(asked.begin(), asked.end(), [&](size_t a, size_t b) {
    return channelMax(scene.lights[a].color) * scene.lights[a].intensity >
           channelMax(scene.lights[b].color) * scene.lights[b].intensity;
  });
  for (size_t i : asked) {
    bool taken[kShadowMaskChannels] = {};
    for (size_t j = 0; j < n; ++j)
      if (j != i && overlap[i * n + j] && result.channel[j] >= 0) taken[result.channel[j]] = true;
    const bool* free = std::find(taken, taken + kShadowMaskChannels, false);
    if (free == taken + kShadowMaskChannels) result.fellBack.push_back(i);
    else result.channel[i] = static_cast<int>(free - taken);
  }
  std::sort(result.fellBack.begin(), result.fellBack.end());
  return result;
}

nlohmann::json ShadowMaskStats::toJson() const {
  return {{"channels", channels}, {"texels", texels}, {"edgeTexels", edgeTexels}, {"subPoints", subPoints}};
}

ShadowMaskPages bakeShadowMask(const BakeInputs& in, const ShadowMaskChannels& channels,
                               const ShadowMaskOptions& options, ShadowMaskStats* stats) {
  Stopwatch watch;
  ShadowMaskStats st;
  ShadowMaskPages pages;
  st.channels = channels.used();
  if (st.channels == 0) return pages;
  for (const TexelSamples& ts : in.texels) {
    Lightmap rgb = blankLightmap(ts);
    rgb.valid = ts.valid;
    for (size_t t = 0; t < rgb.size(); ++t)
      if (ts.valid[t]) rgb.texels[t] = glm::vec3(1.0f);
    Lightmap alpha = rgb;
    for (size_t i = 0; i < channels.channel.size(); ++i) {
      const int c = channels.channel[i];
      if (c < 0) continue;
      const Light& light = in.scene.lights[i];
      std::vector<float> vis = centreVisibility(in, ts, light, options.influenceThreshold);
      refineEdges(in, ts, light, options, vis, st);
      for (size_t t = 0; t < vis.size(); ++t) {
        if (vis[t] < 0.0f) continue;  // not this light's texel: another light of the channel may own it
        ++st.texels;
        if (c < 3) rgb.texels[t][c] = vis[t];
        else alpha.texels[t] = glm::vec3(vis[t]);
      }
    }
    pages.rgb.push_back(std::move(rgb));
    if (st.channels > 3) pages.alpha.push_back(std::move(alpha));
  }
  st.seconds = watch.seconds();
  if (stats) *stats = st;
  return pages;
}

}  // namespace irbake
