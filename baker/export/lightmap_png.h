// The 8-bit PNG of MOZ_lightmap: map value (irradiance/π, linear) = decode(PNG) × intensity.
// decode is the sRGB transfer curve when `srgb` (the default: its small-value slope keeps shadows that a
// linear 8-bit code rounds to 0), identity otherwise. The range (intensity) is a high percentile of the
// covered texels' largest channel, so one hot texel beside the light does not compress everything else.
// docs/export.md has the measurements behind the defaults.
#pragma once
#include <cstdint>
#include <vector>

#include "lightmap/lightmap.h"
#include "scene/scene.h"

namespace irbake {

struct LightmapPngOptions {
  bool srgb = true;          // sRGB-encode the normalised value (decode with the sRGB curve)
  double percentile = 99.9;  // intensity = this percentile of the covered texels' largest channel (100: the maximum)
};

struct LightmapPng {
  Texture texture;           // normalised values in [0,1] (linear; encodePng applies the sRGB curve when srgb)
  float intensity = 1.0f;    // MOZ_lightmap intensity
  bool srgb = true;
  std::vector<uint8_t> png;  // the encoded file
};

LightmapPng encodeLightmapPng(const Lightmap& map, const LightmapPngOptions& options = {});

// What an 8-bit encoding loses, over the covered (valid) texels with a positive value.
struct LightmapPngError {
  double zeroFraction = 0.0;  // fraction of covered texels with a channel > 0 that decodes to exactly 0
  double relErrorP90 = 0.0;   // 90th percentile of |decoded − value| / value over covered channels > 0
  double relErrorP50 = 0.0;   // median of the same
  double clippedFraction = 0.0;  // fraction of covered texels with a channel above the range (clipped)
};

// Quantises `map` as encodeLightmapPng would (decoding the 8-bit codes) and measures the error.
LightmapPngError measureLightmapPng(const Lightmap& map, const LightmapPngOptions& options = {});

}  // namespace irbake
