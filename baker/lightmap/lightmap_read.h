// Reading a baked map at a ray hit: which page the hit surface's light map is on, where on it, and the value
// there. Shared by the stages that gather from the map (stages/compensation, stages/gather).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/parallel_for.h>

#include "lightmap/lightmap.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"

namespace irbake {

// Light-map page number → index of its texel page (= its map, in the same order); −1 where none.
inline std::vector<int32_t> mapIndexOfPages(const std::vector<TexelSamples>& texels) {
  std::vector<int32_t> mapOfPage;
  for (size_t i = 0; i < texels.size(); ++i) {
    int page = texels[i].page;
    if (page < 0) continue;
    if (static_cast<size_t>(page) >= mapOfPage.size()) mapOfPage.resize(page + 1, -1);
    mapOfPage[page] = static_cast<int32_t>(i);
  }
  return mapOfPage;
}

// Where a hit lands on the maps: map index (−1: the surface has no light map) and continuous texel
// coordinates (u·W − ½, v·H − ½).
struct MapPoint {
  int map = -1;
  glm::vec2 texel{0.0f};
};

inline MapPoint mapPointOf(const Scene& scene, const std::vector<int32_t>& mapOfPage,
                           const std::vector<TexelSamples>& texels, const RayHit& hit) {
  MapPoint point;
  const Primitive& prim = scene.primitives[hit.primitive];
  const int page = prim.lightmap.page;
  if (page < 0 || static_cast<size_t>(page) >= mapOfPage.size() || mapOfPage[page] < 0 ||
      prim.uv1.size() != prim.positions.size())
    return point;
  const uint32_t* idx = &prim.indices[3 * static_cast<size_t>(hit.triangle)];
  const float b1 = hit.barycentric.x, b2 = hit.barycentric.y;
  const glm::vec2 uv = (1.0f - b1 - b2) * prim.uv1[idx[0]] + b1 * prim.uv1[idx[1]] + b2 * prim.uv1[idx[2]];
  const TexelSamples& m = texels[mapOfPage[page]];
  point.map = mapOfPage[page];
  point.texel = glm::vec2(uv.x * m.width - 0.5f, uv.y * m.height - 0.5f);
  return point;
}

// Bilinear read over the valid texels of a width × height page, at(x, y, v) saying whether texel (x, y) is
// valid and putting its value in v; the nearest valid texel of the 3×3 neighbourhood when none of the four is
// valid (chart borders); 0 when none at all. Shared by both map forms below.
template <class ValidValue>
glm::vec3 readBilinearOverValid(int width, int height, glm::vec2 t, ValidValue&& at) {
  const int x0 = static_cast<int>(std::floor(t.x)), y0 = static_cast<int>(std::floor(t.y));
  const float fx = t.x - x0, fy = t.y - y0;
  glm::vec3 sum(0.0f), v(0.0f);
  float weight = 0.0f;
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const int x = x0 + dx, y = y0 + dy;
      if (x < 0 || y < 0 || x >= width || y >= height || !at(x, y, v)) continue;
      const float w = (dx ? fx : 1.0f - fx) * (dy ? fy : 1.0f - fy) + 1e-6f;
      sum += w * v;
      weight += w;
    }
  if (weight > 0.0f) return sum / weight;
  const int cx = static_cast<int>(std::lround(t.x)), cy = static_cast<int>(std::lround(t.y));
  float best = 1e30f;
  glm::vec3 nearest(0.0f);
  for (int y = cy - 1; y <= cy + 1; ++y)
    for (int x = cx - 1; x <= cx + 1; ++x) {
      if (x < 0 || y < 0 || x >= width || y >= height || !at(x, y, v)) continue;
      const float d = (x - t.x) * (x - t.x) + (y - t.y) * (y - t.y);
      if (d < best) best = d, nearest = v;
    }
  return nearest;
}

// Bilinear read of irradiance/π over the valid texels of a map (values: one per texel of m, e.g. m.texels).
inline glm::vec3 readLightmap(const Lightmap& m, const std::vector<glm::vec3>& value, glm::vec2 t) {
  return readBilinearOverValid(m.width, m.height, t, [&](int x, int y, glm::vec3& v) {
    const size_t i = static_cast<size_t>(y) * m.width + x;
    if (!m.valid[i]) return false;
    v = value[i];
    return true;
  });
}

// A page's map packed for the gathers' random reads (tens of millions of hits, each a bilinear footprint at an
// unpredictable place): every texel one 32-bit word, RGB with 9-bit mantissas and a shared 5-bit exponent
// (EXT_texture_shared_exponent's RGB9E5, relative to a power-of-two scale per page), in 4×4-texel tiles of 64
// bytes. A footprint then touches one or two cache lines instead of four (two rows of floats, two of validity
// bytes), and a level's page of millions of texels shrinks to a quarter, inside the last-level cache. The largest
// channel keeps a relative precision of 2^-9 (rounded to nearest); a channel 2^k times smaller loses k more bits,
// well below the noise of the gathers that read it. Invalid texels hold a sentinel no value encodes to.
// read() returns what readLightmap returns over the decoded values.
class PackedLightmap {
 public:
  PackedLightmap() = default;
  PackedLightmap(const PackedLightmap&) = delete;  // a copy's words would lose the tile alignment
  PackedLightmap& operator=(const PackedLightmap&) = delete;
  PackedLightmap(PackedLightmap&&) noexcept = default;
  PackedLightmap& operator=(PackedLightmap&&) noexcept = default;
  // value(i): the value of texel i (y·width + x), read at valid texels only.
  template <class ValueOfTexel, class = std::enable_if_t<std::is_invocable_v<ValueOfTexel, size_t>>>
  PackedLightmap(const Lightmap& m, ValueOfTexel&& value) : width_(m.width), height_(m.height) {
    tilesX_ = (width_ + 3) / 4;
    const int tilesY = (height_ + 3) / 4;
    words_.assign(static_cast<size_t>(tilesX_) * tilesY * 16 + 16, kInvalid);
    offset_ = (64 - reinterpret_cast<uintptr_t>(words_.data()) % 64) % 64 / sizeof(uint32_t);
    float peak = 0.0f;
    for (size_t i = 0; i < m.size(); ++i)
      if (m.valid[i]) {
        const glm::vec3 v = value(i);
        peak = std::max({peak, v.x, v.y, v.z});
      }
    // Scale: the page's peak maps below 2^14 (exponent ≤ 29 of 31: the sentinel stays out of reach).
    int e = 0;
    if (peak > 0.0f && std::isfinite(peak)) std::frexp(peak, &e);
    const int shift = 14 - e;  // value · 2^shift < 2^14
    for (int x = 0; x < 32; ++x) unit_[x] = std::ldexp(1.0f, x - kBias - kMantissaBits - shift);
    tbb::parallel_for(0, height_, [&](int y) {
      for (int x = 0; x < width_; ++x) {
        const size_t i = static_cast<size_t>(y) * width_ + x;
        if (m.valid[i]) words_[index(x, y)] = encode(value(i), shift);
      }
    });
  }
  PackedLightmap(const Lightmap& m, const std::vector<glm::vec3>& values)
      : PackedLightmap(m, [&](size_t i) { return values[i]; }) {}
  bool valid(int x, int y) const { return word(x, y) != kInvalid; }
  glm::vec3 at(int x, int y) const { return decode(word(x, y)); }  // x, y inside; a valid texel

  glm::vec3 read(glm::vec2 t) const {
    return readBilinearOverValid(width_, height_, t, [&](int x, int y, glm::vec3& v) {
      const uint32_t w = word(x, y);
      if (w == kInvalid) return false;
      v = decode(w);
      return true;
    });
  }

 private:
  static constexpr uint32_t kInvalid = 0xffffffffu;
  static constexpr int kMantissaBits = 9, kBias = 15;
  size_t index(int x, int y) const {
    return offset_ + (static_cast<size_t>(y >> 2) * tilesX_ + (x >> 2)) * 16 + ((y & 3) << 2) + (x & 3);
  }
  uint32_t word(int x, int y) const { return words_[index(x, y)]; }
  glm::vec3 decode(uint32_t w) const {
    const float u = unit_[w >> 27];
    return glm::vec3(static_cast<float>(w & 511u) * u, static_cast<float>((w >> 9) & 511u) * u,
                     static_cast<float>((w >> 18) & 511u) * u);
  }
  // RGB9E5 of v · 2^shift (negative and non-finite channels as 0).
  static uint32_t encode(glm::vec3 v, int shift) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      const float x = v[k];
      c[k] = (std::isfinite(x) && x > 0.0f) ? std::ldexp(x, shift) : 0.0f;
    }
    const float peak = std::max({c[0], c[1], c[2]});
    if (!(peak > 0.0f)) return 0u;
    int e = 0;
    std::frexp(peak, &e);  // peak in [2^(e-1), 2^e)
    int exponent = std::max(e, -kBias + 1) + kBias;  // stored exponent: unit 2^(exponent - kBias - 9)
    float unit = std::ldexp(1.0f, exponent - kBias - kMantissaBits);
    if (std::lround(peak / unit) > 511) unit *= 2.0f, ++exponent;  // rounding carried into the next power
    uint32_t w = static_cast<uint32_t>(exponent) << 27;
    for (int k = 0; k < 3; ++k)
      w |= static_cast<uint32_t>(std::min<long>(511, std::lround(c[k] / unit))) << (9 * k);
    return w;
  }
  int width_ = 0, height_ = 0, tilesX_ = 0;
  size_t offset_ = 0;  // words_ + offset_ is 64-byte aligned: each tile one cache line
  std::vector<uint32_t> words_;
  float unit_[32] = {};  // value of one mantissa step per stored exponent, the page's scale included
};

// Every map packed (see PackedLightmap) with the values values[p] (one per texel of maps[p]).
inline std::vector<PackedLightmap> packLightmaps(const std::vector<Lightmap>& maps,
                                                 const std::vector<std::vector<glm::vec3>>& values) {
  std::vector<PackedLightmap> packed;
  packed.reserve(maps.size());
  for (size_t p = 0; p < maps.size(); ++p) packed.emplace_back(maps[p], values[p]);
  return packed;
}

}  // namespace irbake
