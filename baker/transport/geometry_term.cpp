#include "transport/geometry_term.h"
#include "scene/triangle_area.h"

#include <cmath>
#include <limits>

namespace irbake {

PunctualContribution punctualDirect(const Light& light, const glm::vec3& x, const glm::vec3& nx) {
  PunctualContribution c;
  if (light.type == LightType::Directional) {
    glm::vec3 l = -glm::normalize(light.direction);
    float cosX = glm::dot(nx, l);
    if (cosX <= 0.0f) return c;
    c.toLight = l;
    c.distance = std::numeric_limits<float>::infinity();
    c.mapValue = light.color * light.intensity * (cosX / kPiF);
    return c;
  }
  glm::vec3 d = light.position - x;
  float r2 = glm::dot(d, d);
  if (!(r2 > 0.0f)) return c;
  float r = std::sqrt(r2);
  glm::vec3 l = d / r;
  float cosX = glm::dot(nx, l);
  if (cosX <= 0.0f || light.rangeWindow(r) == 0.0f) return c;
  c.toLight = l;
  c.distance = r;
  c.mapValue = light.intensityToward(-l) * (cosX / (r2 * kPiF));
  return c;
}

float deriveClampBound(const Scene& scene, const VplSet& vpls, double vplsPerMean) {
  size_t n = 0;
  for (const Vpl& v : vpls.vpls)
    if (v.power.x > 0.0f || v.power.y > 0.0f || v.power.z > 0.0f) ++n;
  double area = 0.0;
  for (const Primitive& p : scene.primitives)
    for (size_t t = 0; t < p.triangleCount(); ++t) area += triangleArea(p, t);
  if (n == 0 || area <= 0.0) return 0.0f;
  return static_cast<float>(kPi * static_cast<double>(n) / (vplsPerMean * area));
}

}  // namespace irbake
