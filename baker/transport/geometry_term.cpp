#include "transport/geometry_term.h"
#include "scene/triangle_area.h"

namespace irbake {

PunctualContribution punctualDirect(const Light& light, const glm::vec3& x, const glm::vec3& nx) {
  return lightKind(light.type).direct(light, x, nx);
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
