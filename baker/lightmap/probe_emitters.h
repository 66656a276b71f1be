// Emitters the probes leave out and the clients shade exactly (docs/export.md, "IRBAKE_light_probes", `emitters`):
// a small uniform emitter near an object changes faster over its surface than L2 can follow, so its direct light
// is Lambert's polygon formula at each surface point (lightmap/polygon_irradiance.h) times its visibility, blended
// from the probes as the coefficients are; its light bounced off other surfaces stays in the coefficients.
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace irbake {

struct ProbeEmitter {
  std::vector<glm::vec3> positions;  // world-space triangle list (3 per triangle, counter-clockwise front)
  glm::vec3 radiance{0.0f};          // Le/π: the coefficients' units (E/π = radiance · Σ polygon factors)
  std::vector<float> visibility;     // per probe: the share of the emitter's unoccluded light that arrives, [0, 1]
};

}  // namespace irbake
