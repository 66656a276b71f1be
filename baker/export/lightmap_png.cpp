#include "export/lightmap_png.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/image_codec.h"

namespace irbake {

namespace {

bool covered(const Lightmap& map, size_t i) { return map.valid.size() != map.texels.size() || map.valid[i] != 0; }

float rangeOf(const Lightmap& map, double percentile) {
  std::vector<float> peaks;
  peaks.reserve(map.texels.size());
  for (size_t i = 0; i < map.texels.size(); ++i)
    if (covered(map, i)) {
      const glm::vec3 t = map.texels[i];
      const float m = std::max(t.x, std::max(t.y, t.z));
      if (m > 0.0f) peaks.push_back(m);
    }
  if (peaks.empty()) return 1.0f;
  const double q = std::clamp(percentile, 0.0, 100.0) / 100.0;
  const double rank = std::ceil(q * double(peaks.size())) - 1.0;  // nearest-rank percentile
  const size_t k = std::min(peaks.size() - 1, static_cast<size_t>(std::max(0.0, rank)));
  std::nth_element(peaks.begin(), peaks.begin() + static_cast<long>(k), peaks.end());
  return peaks[k] > 0.0f ? peaks[k] : 1.0f;
}

// The value a client reads back from the 8-bit code of normalised value x.
float roundTrip(float x, bool srgb) {
  x = std::clamp(x, 0.0f, 1.0f);
  const float code = std::round((srgb ? linearToSrgb(x) : x) * 255.0f) / 255.0f;
  return srgb ? srgbToLinear(code) : code;
}

double percentileOf(std::vector<double>& v, double p) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p / 100.0 * double(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

}  // namespace

LightmapPng encodeLightmapPng(const Lightmap& map, const LightmapPngOptions& options) {
  LightmapPng p;
  p.srgb = options.srgb;
  p.intensity = rangeOf(map, options.percentile);
  p.texture.name = "lightmap_" + std::to_string(map.page);
  p.texture.width = map.width;
  p.texture.height = map.height;
  p.texture.wrapS = p.texture.wrapT = WrapMode::ClampToEdge;
  p.texture.texels.resize(map.texels.size());
  for (size_t i = 0; i < map.texels.size(); ++i)
    p.texture.texels[i] = glm::vec4(glm::clamp(map.texels[i] / p.intensity, glm::vec3(0.0f), glm::vec3(1.0f)), 1.0f);
  p.png = encodePng(p.texture, p.srgb);
  return p;
}

LightmapPngError measureLightmapPng(const Lightmap& map, const LightmapPngOptions& options) {
  const float range = rangeOf(map, options.percentile);
  size_t texels = 0, zeros = 0, clipped = 0;
  std::vector<double> rel;
  for (size_t i = 0; i < map.texels.size(); ++i) {
    if (!covered(map, i)) continue;
    const glm::vec3 t = map.texels[i];
    bool anyPositive = false, zero = false, clip = false;
    for (int c = 0; c < 3; ++c) {
      if (!(t[c] > 0.0f)) continue;
      anyPositive = true;
      const float decoded = roundTrip(t[c] / range, options.srgb) * range;
      if (decoded == 0.0f) zero = true;
      if (t[c] > range) clip = true;
      rel.push_back(std::abs(double(decoded) - double(t[c])) / double(t[c]));
    }
    if (!anyPositive) continue;
    ++texels;
    zeros += zero;
    clipped += clip;
  }
  LightmapPngError e;
  if (texels == 0) return e;
  e.zeroFraction = double(zeros) / double(texels);
  e.clippedFraction = double(clipped) / double(texels);
  e.relErrorP90 = percentileOf(rel, 90.0);
  e.relErrorP50 = percentileOf(rel, 50.0);
  return e;
}

}  // namespace irbake
