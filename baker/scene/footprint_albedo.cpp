#include "scene/footprint_albedo.h"

#include <algorithm>
#include <cmath>

namespace irbake {

Texture downsampleTexture(const Texture& tex) {
  Texture out;
  out.name = tex.name;
  out.wrapS = tex.wrapS;
  out.wrapT = tex.wrapT;
  out.gltfImage = tex.gltfImage;
  out.width = std::max(1, tex.width / 2);
  out.height = std::max(1, tex.height / 2);
  out.texels.assign(static_cast<size_t>(out.width) * out.height, glm::vec4(0.0f));
  if (tex.width <= 0 || tex.height <= 0 || tex.texels.empty()) return out;
  for (int y = 0; y < out.height; ++y) {
    // Source rows whose centres fall in destination row y: [y·H/h, (y+1)·H/h).
    const int y0 = static_cast<int>(static_cast<int64_t>(y) * tex.height / out.height);
    const int y1 = static_cast<int>(static_cast<int64_t>(y + 1) * tex.height / out.height);
    for (int x = 0; x < out.width; ++x) {
      const int x0 = static_cast<int>(static_cast<int64_t>(x) * tex.width / out.width);
      const int x1 = static_cast<int>(static_cast<int64_t>(x + 1) * tex.width / out.width);
      glm::dvec4 sum(0.0);
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx) sum += glm::dvec4(tex.texels[static_cast<size_t>(sy) * tex.width + sx]);
      out.texels[static_cast<size_t>(y) * out.width + x] = glm::vec4(sum / static_cast<double>((y1 - y0) * (x1 - x0)));
    }
  }
  return out;
}

namespace {

glm::vec2 interpolateUv(const std::vector<glm::vec2>& uv, const Primitive& p, uint32_t tri, glm::vec2 b) {
  if (uv.size() != p.positions.size()) return glm::vec2(0.0f);
  const uint32_t* idx = &p.indices[3 * static_cast<size_t>(tri)];
  return uv[idx[0]] * (1.0f - b.x - b.y) + uv[idx[1]] * b.x + uv[idx[2]] * b.y;
}

double uvArea(const std::vector<glm::vec2>& uv, const uint32_t* idx) {
  const glm::dvec2 a(uv[idx[0]]), b(uv[idx[1]]), c(uv[idx[2]]);
  return 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

}  // namespace

FootprintAlbedo::FootprintAlbedo(const Scene& scene) : scene_(scene) {
  coarser_.resize(scene.textures.size());
  std::vector<uint8_t> used(scene.textures.size(), 0);
  for (const Material& m : scene.materials)
    if (m.baseColorTexture >= 0 && static_cast<size_t>(m.baseColorTexture) < used.size()) used[m.baseColorTexture] = 1;
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    if (!used[t]) continue;
    const Texture* from = &scene.textures[t];
    while (from->width > 1 || from->height > 1) {
      coarser_[t].push_back(downsampleTexture(*from));
      from = &coarser_[t].back();
    }
  }
  level_.resize(scene.primitives.size());
  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    level_[p].assign(prim.triangleCount(), 0);
    const Material& m = scene.materials[prim.material];
    if (m.baseColorTexture < 0 || prim.lightmap.page < 0) continue;
    const std::vector<glm::vec2>& uvTex = m.baseColorTexCoord == 1 ? prim.uv1 : prim.uv0;
    if (uvTex.size() != prim.positions.size() || prim.uv1.size() != prim.positions.size()) continue;
    const Texture& tex = scene.textures[m.baseColorTexture];
    const int maxLevel = static_cast<int>(coarser_[m.baseColorTexture].size());
    const double texTexels = static_cast<double>(tex.width) * tex.height;
    const double mapTexels = static_cast<double>(prim.lightmap.width) * prim.lightmap.height;
    for (size_t t = 0; t < prim.triangleCount(); ++t) {
      const uint32_t* idx = &prim.indices[3 * t];
      const double map = uvArea(prim.uv1, idx) * mapTexels;
      const double texture = uvArea(uvTex, idx) * m.baseColorUvTransform.areaScale() * texTexels;
      if (!(map > 0.0) || !(texture > 0.0)) continue;
      // Texture texels per map texel, along a side: level ⌊log2⌋ is the coarsest whose texel is at most a map texel.
      const double perMapTexel = std::sqrt(texture / map);
      const int lv = perMapTexel > 1.0 ? static_cast<int>(std::floor(std::log2(perMapTexel))) : 0;
      level_[p][t] = static_cast<uint8_t>(std::clamp(lv, 0, std::min(maxLevel, 255)));
    }
  }
}

glm::vec3 FootprintAlbedo::at(uint32_t primitive, uint32_t triangle, glm::vec2 barycentric) const {
  const Primitive& prim = scene_.primitives[primitive];
  const Material& m = scene_.materials[prim.material];
  glm::vec4 c = m.baseColorFactor;
  if (m.baseColorTexture >= 0) {
    const int lv = level_[primitive][triangle];
    const Texture& tex = lv == 0 ? scene_.textures[m.baseColorTexture] : coarser_[m.baseColorTexture][lv - 1];
    const glm::vec2 uv = interpolateUv(m.baseColorTexCoord == 1 ? prim.uv1 : prim.uv0, prim, triangle, barycentric);
    c *= sampleBilinear(tex, m.baseColorUvTransform.apply(uv));
  }
  return glm::vec3(c);
}

}  // namespace irbake
