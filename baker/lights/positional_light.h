// What the lights with a position (point, spot, IES) share: the inverse-square direct term and the reach.
#pragma once
#include <algorithm>
#include <cmath>

#include "common/maths.h"
#include "lights/light_kind.h"

namespace irbake {

// E = I(−l) · max(0, n_x·l) / r² · window(r), as irradiance / π, window(r) glTF's range (Light::rangeWindow);
// intensityToward(light, dirFromLight) is the kind's. The bake's cut of a light without range (Light::cutoff)
// fades it out as well.
template <typename IntensityToward>
PunctualContribution positionalDirect(const Light& light, const glm::vec3& x, const glm::vec3& nx,
                                      IntensityToward intensityToward) {
  PunctualContribution c;
  glm::vec3 d = light.position - x;
  float r2 = glm::dot(d, d);
  if (!(r2 > 0.0f)) return c;
  // Past the range or the cut both windows are 0: most of a grid cell's lights are, and need no root.
  const float reach = light.range > 0.0f && light.cutoff > 0.0f ? std::min(light.range, light.cutoff)
                                                                : std::max(light.range, light.cutoff);
  if (reach > 0.0f && !(r2 < reach * reach)) return c;
  float r = std::sqrt(r2);
  glm::vec3 l = d / r;
  float cosX = glm::dot(nx, l);
  const float window = light.rangeWindow(r) * light.cutoffWindow(r);
  if (cosX <= 0.0f || window == 0.0f) return c;
  c.toLight = l;
  c.distance = r;
  c.mapValue = intensityToward(light, -l) * (cosX / (r2 * kPiF)) * window;
  return c;
}

// Whether a point at squared distance r2 from the light lies within the distance where the peak intensity falls to
// `threshold` (W/m² facing the light; 0: no such limit) and within the range.
// `peakScale` scales the intensity to the light's peak (an IES profile's largest candela).
inline bool withinReach(const Light& light, float r2, float threshold, float peakScale = 1.0f) {
  const float peak = std::max(light.color.x, std::max(light.color.y, light.color.z)) * light.intensity *
                     peakScale;  // W/sr
  if (!(peak > 0.0f)) return false;
  float reach2 = threshold > 0.0f ? peak / (3.14159265f * threshold) : INFINITY;
  if (light.range > 0.0f) reach2 = std::min(reach2, light.range * light.range);
  if (light.cutoff > 0.0f) reach2 = std::min(reach2, light.cutoff * light.cutoff);
  return !(r2 > reach2);
}

}  // namespace irbake
