#include "scene/scene.h"
#include "scene/triangle_area.h"

#include <algorithm>
#include <cmath>

#include "common/maths.h"

namespace irbake {

const char* toString(LightMode mode) {
  switch (mode) {
    case LightMode::Baked: return "baked";
    case LightMode::Indirect: return "indirect";
    case LightMode::ShadowMask: return "shadowmask";
  }
  return "baked";
}

bool parseLightMode(const std::string& text, LightMode& mode) {
  for (LightMode m : {LightMode::Baked, LightMode::Indirect, LightMode::ShadowMask})
    if (text == toString(m)) {
      mode = m;
      return true;
    }
  return false;
}

const char* toString(ObjectMode mode) {
  switch (mode) {
    case ObjectMode::Baked: return "baked";
    case ObjectMode::ShadowOnly: return "shadow-only";
    case ObjectMode::Probes: return "probes";
    case ObjectMode::Off: return "off";
  }
  return "baked";
}

bool parseObjectMode(const std::string& text, ObjectMode& mode) {
  for (ObjectMode m : {ObjectMode::Baked, ObjectMode::ShadowOnly, ObjectMode::Probes, ObjectMode::Off})
    if (text == toString(m)) {
      mode = m;
      return true;
    }
  return false;
}

namespace {

float wrapCoord(float t, WrapMode mode) {
  switch (mode) {
    case WrapMode::Repeat: return t - std::floor(t);
    case WrapMode::ClampToEdge: return std::clamp(t, 0.0f, 1.0f);
    case WrapMode::MirroredRepeat: {
      float f = t - 2.0f * std::floor(t * 0.5f);  // [0,2)
      return f > 1.0f ? 2.0f - f : f;
    }
  }
  return t;
}

int wrapIndex(int i, int n, WrapMode mode) {
  switch (mode) {
    case WrapMode::Repeat: return ((i % n) + n) % n;
    case WrapMode::ClampToEdge: return std::clamp(i, 0, n - 1);
    case WrapMode::MirroredRepeat: {
      int period = 2 * n;
      int m = ((i % period) + period) % period;
      return m < n ? m : period - 1 - m;
    }
  }
  return 0;
}

glm::vec2 interpolate(const std::vector<glm::vec2>& uv, const Primitive& p, uint32_t tri, glm::vec2 b) {
  if (uv.empty()) return glm::vec2(0.0f);
  const uint32_t* idx = &p.indices[3 * tri];
  return uv[idx[0]] * (1.0f - b.x - b.y) + uv[idx[1]] * b.x + uv[idx[2]] * b.y;
}
}  // namespace

glm::vec4 sampleBilinear(const Texture& tex, glm::vec2 uv) {
  if (tex.width <= 0 || tex.height <= 0 || tex.texels.empty()) return glm::vec4(1.0f);
  // Texel centres at (i + 0.5) / width.
  float x = wrapCoord(uv.x, tex.wrapS) * tex.width - 0.5f;
  float y = wrapCoord(uv.y, tex.wrapT) * tex.height - 0.5f;
  int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  float fx = x - x0, fy = y - y0;
  int xa = wrapIndex(x0, tex.width, tex.wrapS), xb = wrapIndex(x0 + 1, tex.width, tex.wrapS);
  int ya = wrapIndex(y0, tex.height, tex.wrapT), yb = wrapIndex(y0 + 1, tex.height, tex.wrapT);
  auto at = [&](int xi, int yi) { return tex.texels[static_cast<size_t>(yi) * tex.width + xi]; };
  return (at(xa, ya) * (1.0f - fx) + at(xb, ya) * fx) * (1.0f - fy) + (at(xa, yb) * (1.0f - fx) + at(xb, yb) * fx) * fy;
}

Bounds3 Scene::bounds() const {
  Bounds3 b;
  for (const auto& p : primitives)
    for (const auto& v : p.positions) b.extend(v);
  return b;
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const auto& p : primitives) n += p.triangleCount();
  return n;
}

glm::vec3 Scene::emitterPower() const {
  glm::dvec3 total(0.0);
  for (const auto& p : primitives) {
    const Material& m = materials[p.material];
    if (!m.isEmissive()) continue;
    for (uint32_t t = 0; t < p.triangleCount(); ++t) {
      const double area = triangleArea(p, t);
      glm::vec3 Le = emissionAt(p, t, glm::vec2(1.0f / 3.0f));  // texture at the centroid
      total += glm::dvec3(Le) * (kPiF * area);
    }
  }
  return glm::vec3(total);
}

bool Scene::hasEmissiveSurface() const {
  for (const auto& p : primitives)
    if (materials[p.material].isEmissive()) return true;
  return false;
}

bool Scene::hasLightOrEmitter() const { return !lights.empty() || environment.present() || hasEmissiveSurface(); }

glm::vec2 UvTransform::apply(glm::vec2 uv) const {
  if (!present) return uv;
  const float c = std::cos(rotation), s = std::sin(rotation);
  const glm::vec2 p = scale * uv;
  return offset + glm::vec2(c * p.x + s * p.y, -s * p.x + c * p.y);
}

glm::mat3 UvTransform::matrix() const {
  const float c = std::cos(rotation), s = std::sin(rotation);
  // Columns: the images of u, of v, and the offset.
  return glm::mat3(glm::vec3(c * scale.x, -s * scale.x, 0.0f), glm::vec3(s * scale.y, c * scale.y, 0.0f),
                   glm::vec3(offset, 1.0f));
}

glm::vec4 Scene::baseColorAt(const Primitive& prim, uint32_t triangle, glm::vec2 b) const {
  const Material& m = materials[prim.material];
  glm::vec4 c = m.baseColorFactor;
  if (m.baseColorTexture >= 0) {
    const auto& uv = m.baseColorTexCoord == 1 ? prim.uv1 : prim.uv0;
    c *= sampleBilinear(textures[m.baseColorTexture], m.baseColorUvTransform.apply(interpolate(uv, prim, triangle, b)));
  }
  return c;
}

glm::vec3 Scene::emissionAt(const Primitive& prim, uint32_t triangle, glm::vec2 b) const {
  const Material& m = materials[prim.material];
  glm::vec3 e = m.emission();
  if (m.emissiveTexture >= 0 && m.isEmissive()) {
    const auto& uv = m.emissiveTexCoord == 1 ? prim.uv1 : prim.uv0;
    e *= glm::vec3(sampleBilinear(textures[m.emissiveTexture], m.emissiveUvTransform.apply(interpolate(uv, prim, triangle, b))));
  }
  return e;
}

}  // namespace irbake

namespace irbake {

SurfaceTransmission Scene::transmissionAt(const Primitive& prim, uint32_t triangle, glm::vec2 barycentric) const {
  SurfaceTransmission t;
  const Material& m = materials[prim.material];
  if (!m.isTransmissive()) return t;
  const glm::vec4 c = baseColorAt(prim, triangle, barycentric);
  t.fraction = m.alphaMode == AlphaMode::Blend ? std::clamp(1.0f - c.a, 0.0f, 1.0f) : 0.0f;
  if (m.transmission > 0.0f) t.fraction = std::max(t.fraction, m.transmission);
  t.tint = glm::vec3(c);
  return t;
}

}  // namespace irbake
