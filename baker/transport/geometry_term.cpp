#include "transport/geometry_term.h"
#include "scene/triangle_area.h"

namespace irbake {

PunctualContribution punctualDirect(const Light& light, const glm::vec3& x, const glm::vec3& nx) {
  return lightKind(light.type).direct(light, x, nx);
}

size_t litVplCount(const VplSet& vpls) {
  size_t n = 0;
  for (const Vpl& v : vpls.vpls)
    if (v.power.x > 0.0f || v.power.y > 0.0f || v.power.z > 0.0f) ++n;
  return n;
}

float clampBoundForCount(const Scene& scene, double vplCount, double vplsPerMean) {
  double area = 0.0;
  for (const Primitive& p : scene.primitives)
    for (size_t t = 0; t < p.triangleCount(); ++t) area += triangleArea(p, t);
  if (!(vplCount > 0.0) || area <= 0.0) return 0.0f;
  return static_cast<float>(kPi * vplCount / (vplsPerMean * area));
}

float deriveClampBound(const Scene& scene, const VplSet& vpls, double vplsPerMean) {
  return clampBoundForCount(scene, static_cast<double>(litVplCount(vpls)), vplsPerMean);
}

}  // namespace irbake
