// Shadow masks (mixed lighting): for each light in shadowmask mode, its baked visibility 0..1 per texel, in one
// of the four channels of a mask page beside each light-map page. The runtime shades such a light's direct
// light itself, times the mask. Texels a shadow edge crosses get the lit share of their own square (S×S
// shadow rays, as stages/shadow_edges). Lights share a channel only where their influences never meet at a
// texel: the overlap graph (lights that both reach some texel) is coloured with four colours.
#pragma once
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

constexpr int kShadowMaskChannels = 4;

struct ShadowMaskOptions {
  int subSamples = 8;                 // S: S×S shadow rays over each texel the mask's edge crosses (≤ 1: centre only)
  float jump = 0.1f;                  // an edge: the visibility differs from a valid 8-neighbour's by more
  float influenceThreshold = 1e-3f;   // a point or spot light reaches a texel while its map value at normal
                                      // incidence, I/(π d²), is at least this (and within its range and cone)
};

// Whether light reaches x at all: directional lights everywhere; point and spot lights within the nearer of
// their range and the distance where I/(π d²) falls to threshold, spot lights inside their outer cone.
bool lightInfluences(const Light& light, const glm::vec3& x, float threshold);

// The shadow-mask lights' channels.
struct ShadowMaskChannels {
  std::vector<int> channel;        // per scene light: 0..3, or -1 (no mask, or none left for it)
  std::vector<size_t> fellBack;    // lights asked for a mask that got no channel (they bake as indirect)
  int used() const;                // channels holding a light (0 when none)
  // [{"light": name, "channel": c}, ...] and the lights that fell back.
  nlohmann::json toJson(const Scene& scene) const;
};

// Colours the overlap graph of the lights with wants[i] (two lights overlap where both reach one valid texel)
// with at most four channels, brightest light first; a light no channel is free for falls back. With `grid`
// each sample tests only the lights near it (lights/light_reach.h).
ShadowMaskChannels assignShadowMaskChannels(const Scene& scene, const std::vector<TexelSamples>& texels,
                                            const std::vector<uint8_t>& wants, const ShadowMaskOptions& options,
                                            const LightGrid* grid = nullptr);

// Per map page, two pages: channels 0–2 in rgb, channel 3 in alpha (all three components); a texel no
// channel's light reaches holds 1 (nothing shadows it).
struct ShadowMaskPages {
  std::vector<Lightmap> rgb;
  std::vector<Lightmap> alpha;
  bool empty() const { return rgb.empty(); }
};

struct ShadowMaskStats {
  int channels = 0;           // channels in use
  size_t texels = 0;          // texel × light visibilities traced at the centre
  size_t edgeTexels = 0;      // of those, refined over their square
  size_t subPoints = 0;       // sub-points traced on those
  double seconds = 0.0;
  nlohmann::json toJson() const;
};

ShadowMaskPages bakeShadowMask(const BakeInputs& in, const ShadowMaskChannels& channels,
                               const ShadowMaskOptions& options, ShadowMaskStats* stats = nullptr);

}  // namespace irbake
