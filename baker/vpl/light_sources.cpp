#include "vpl/light_sources.h"
#include "scene/triangle_area.h"

#include <algorithm>
#include <cmath>

#include "common/maths.h"
#include "lights/light_kind.h"

namespace irbake {

double LightSources::areaPdf(uint32_t primitive, uint32_t triangle) const {
  if (primitive >= firstSlot.size() || firstSlot[primitive] < 0) return 0.0;
  size_t slot = static_cast<size_t>(firstSlot[primitive]) + triangle;
  if (slot >= triangles.size() || triangles[slot].area <= 0.0f) return 0.0;
  return areaOnly.pdf(slot) / triangles[slot].area;
}

LightSources collectLightSources(const Scene& scene) {
  LightSources out;
  Bounds3 b = scene.bounds();
  out.sceneCentre = b.valid() ? 0.5f * (b.min + b.max) : glm::vec3(0.0f);
  out.sceneRadius = b.valid() ? std::max(0.5f * b.diagonal(), 1e-6f) * 1.001f : 1.0f;
  out.firstSlot.assign(scene.primitives.size(), -1);
  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    if (!scene.materials[prim.material].isEmissive()) continue;
    out.firstSlot[p] = static_cast<int64_t>(out.triangles.size());
    for (uint32_t t = 0; t < prim.triangleCount(); ++t) {
      const glm::vec3& a = prim.positions[prim.indices[3 * t]];
      const glm::vec3& c1 = prim.positions[prim.indices[3 * t + 1]];
      const glm::vec3& c2 = prim.positions[prim.indices[3 * t + 2]];
      glm::vec3 n = glm::cross(c1 - a, c2 - a);
      float len = glm::length(n);
      EmitterTriangle e;
      e.primitive = static_cast<uint32_t>(p);
      e.triangle = t;
      e.area = 0.5f * len;
      e.normal = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
      e.power = glm::dvec3(scene.emissionAt(prim, t, glm::vec2(1.0f / 3.0f))) * (kPi * e.area);
      out.triangles.push_back(e);
    }
  }
  std::vector<double> weights, areaWeights;
  for (const auto& e : out.triangles) {
    weights.push_back(channelMean(e.power));
    out.totalPower += e.power;
  }
  areaWeights = weights;
  for (const Light& l : scene.lights) {
    glm::dvec3 power = lightKind(l.type).walkPower(l, out.sceneRadius);
    out.lightPower.push_back(power);
    weights.push_back(channelMean(power));
    out.totalPower += power;
  }
  if (scene.environment.present()) {
    out.skyPower = scene.environment.integral() * (kPi * out.sceneRadius * out.sceneRadius);
    out.hasSky = channelMean(out.skyPower) > 0.0;
    if (out.hasSky) {
      weights.push_back(channelMean(out.skyPower));
      out.totalPower += out.skyPower;
    }
  }
  if (!weights.empty()) out.all = AliasTable(weights);
  out.startWeights = std::move(weights);
  if (!areaWeights.empty()) out.areaOnly = AliasTable(areaWeights);
  return out;
}

double meanReflectivity(const Scene& scene) {
  static const glm::vec2 kPoints[4] = {{1.0f / 3, 1.0f / 3}, {1.0f / 6, 1.0f / 6}, {2.0f / 3, 1.0f / 6}, {1.0f / 6, 2.0f / 3}};
  double weighted = 0.0, area = 0.0;
  for (const Primitive& prim : scene.primitives) {
    for (uint32_t t = 0; t < prim.triangleCount(); ++t) {
      const double A = triangleArea(prim, t);
      double rho = 0.0;
      for (const glm::vec2& p : kPoints) {
        glm::vec3 a(scene.baseColorAt(prim, t, p));
        rho += std::max(a.x, std::max(a.y, a.z));
      }
      weighted += A * rho / 4.0;
      area += A;
    }
  }
  if (area <= 0.0) return 0.0;
  return std::clamp(weighted / area, 0.0, 0.999);
}

}  // namespace irbake
