// png8: 8-bit RGBA PNG. MapRange::Percentile is MOZ_lightmap's image: value (irradiance/π, linear) =
// decode(PNG) × intensity, decode the sRGB curve when `srgb` (the default: its small-value slope keeps
// shadows that a linear 8-bit code rounds to 0), identity otherwise. The range (intensity) is a high
// percentile of the covered texels' largest channel, so one hot texel beside the light does not compress
// everything else; docs/export.md has the measurements behind the defaults. SignedMax is the L1 pages'
// (docs/export.md "IRBAKE_lightmap_directional"), Unit the shadow masks'.
#include <algorithm>
#include <cmath>
#include <string>

#include "export/map_encoding.h"
#include "scene/image_codec.h"

namespace irbake {

namespace {

bool covered(const Lightmap& map, size_t i) { return map.valid.size() != map.texels.size() || map.valid[i] != 0; }

float percentileRange(const Lightmap& map, double percentile) {
  std::vector<float> peaks;
  peaks.reserve(map.texels.size());
  for (size_t i = 0; i < map.texels.size(); ++i)
    if (covered(map, i)) {
      const glm::vec3 t = map.texels[i];
      const float m = std::max(t.x, std::max(t.y, t.z));
      if (m > 0.0f) peaks.push_back(m);
    }
  return rangeAtPercentile(peaks, percentile);
}

// The largest |value| over the valid texels (1 when all are 0 or it is not finite).
float signedRange(const Lightmap& page) {
  float largest = 0.0f;
  for (size_t i = 0; i < page.texels.size(); ++i) {
    if (i < page.valid.size() && !page.valid[i]) continue;
    const glm::vec3 a = glm::abs(page.texels[i]);
    largest = std::max(largest, std::max(a.x, std::max(a.y, a.z)));
  }
  return largest > 0.0f && std::isfinite(largest) ? largest : 1.0f;
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

class Png8Encoding final : public MapEncoding {
 public:
  MapEncodingKind kind() const override { return MapEncodingKind::Png8; }
  const char* name() const override { return "png8"; }
  const char* mimeType() const override { return "image/png"; }

  // One 8-bit step around the value's code, in value units (the decode of code ± ½).
  double tolerance(float value, const MapMetadata& md) const override {
    const float span = md.signedValues ? 2.0f : 1.0f;
    const float x = std::clamp(md.signedValues ? (value / md.intensity + 1.0f) * 0.5f : value / md.intensity, 0.0f, 1.0f);
    const float s = md.srgb ? linearToSrgb(x) : x;
    auto decode = [&](float c) { return md.srgb ? srgbToLinear(std::clamp(c, 0.0f, 1.0f)) : std::clamp(c, 0.0f, 1.0f); };
    return double(decode(s + 0.5f / 255.0f) - decode(s - 0.5f / 255.0f)) * span * md.intensity;
  }

  EncodedMap encode(const Lightmap& page, const MapEncodeOptions& options) const override {
    EncodedMap e;
    e.metadata.page = page.page;
    e.metadata.srgb = options.srgb;
    e.metadata.signedValues = options.range == MapRange::SignedMax;
    e.metadata.intensity = options.range == MapRange::Percentile ? percentileRange(page, options.percentile)
                           : options.range == MapRange::SignedMax ? signedRange(page)
                                                                  : 1.0f;
    Texture& t = e.stored;
    t.name = options.name.empty() ? "lightmap_" + std::to_string(page.page) : options.name;
    t.width = page.width;
    t.height = page.height;
    t.wrapS = t.wrapT = WrapMode::ClampToEdge;
    t.texels.resize(page.texels.size());
    const float intensity = e.metadata.intensity;
    for (size_t i = 0; i < page.texels.size(); ++i) {
      const glm::vec3 v = page.texels[i];
      const float a = options.alpha ? options.alpha->texels[i].x : 1.0f;
      if (options.range == MapRange::Percentile)
        t.texels[i] = glm::vec4(glm::clamp(v / intensity, glm::vec3(0.0f), glm::vec3(1.0f)), 1.0f);
      else if (options.range == MapRange::SignedMax)
        t.texels[i] = glm::vec4(glm::clamp((v / intensity + 1.0f) * 0.5f, 0.0f, 1.0f), 1.0f);
      else
        t.texels[i] = glm::clamp(glm::vec4(v, a), 0.0f, 1.0f);
    }
    e.bytes = encodePng(t, options.srgb);
    return e;
  }

  DecodedMap decode(const uint8_t* bytes, size_t size, const MapMetadata& md, const std::string& name) const override {
    return fromStored(decodeImageToTexture(bytes, size, md.srgb, name), md);
  }

  DecodedMap fromStored(const Texture& t, const MapMetadata& md) const override {
    return decodedFromTexture(t, md.page, [&md](glm::vec3 s) { return (md.signedValues ? 2.0f * s - 1.0f : s) * md.intensity; });
  }
};

}  // namespace

float rangeAtPercentile(std::vector<float>& peaks, double percentile) {
  if (peaks.empty()) return 1.0f;
  const double q = std::clamp(percentile, 0.0, 100.0) / 100.0;
  const double rank = std::ceil(q * double(peaks.size())) - 1.0;  // nearest-rank percentile
  const size_t k = std::min(peaks.size() - 1, static_cast<size_t>(std::max(0.0, rank)));
  std::nth_element(peaks.begin(), peaks.begin() + static_cast<long>(k), peaks.end());
  return peaks[k] > 0.0f ? peaks[k] : 1.0f;
}

const MapEncoding& png8MapEncoding() {
  static const Png8Encoding encoding;
  return encoding;
}

Png8Error measurePng8(const Lightmap& map, const MapEncodeOptions& options) {
  const float range = percentileRange(map, options.percentile);
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
  Png8Error e;
  if (texels == 0) return e;
  e.zeroFraction = double(zeros) / double(texels);
  e.clippedFraction = double(clipped) / double(texels);
  e.relErrorP90 = percentileOf(rel, 90.0);
  e.relErrorP50 = percentileOf(rel, 50.0);
  return e;
}

}  // namespace irbake
