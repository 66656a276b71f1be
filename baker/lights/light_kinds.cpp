// The registry of light kinds, indexed by LightType, and what every kind answers the same way.
#include <algorithm>
#include <cmath>

#include "lights/light_kind.h"

namespace irbake {

// One per kind, each in its own file.
const LightKind& pointLightKind();
const LightKind& spotLightKind();
const LightKind& directionalLightKind();
const LightKind& iesLightKind();

const LightKind& lightKind(LightType type) {
  static const LightKind* const kinds[] = {
      &pointLightKind(),        // LightType::Point
      &spotLightKind(),         // LightType::Spot
      &directionalLightKind(),  // LightType::Directional
      &iesLightKind(),          // LightType::Ies
  };
  return *kinds[static_cast<size_t>(type)];
}

ShaderLight LightKind::shaderLight(const Light& light) const {
  ShaderLight s;
  s.code = shaderCode();
  s.intensity = light.color * light.intensity;
  const float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
  s.cosOuter = cosOuter;
  s.spotScale = 1.0f / std::max(0.001f, cosInner - cosOuter);
  return s;
}

PunctualContribution LightKind::atNormalIncidence(const Light& light, const glm::vec3& p) const {
  glm::vec3 w = toward(light, p);
  if (atInfinity()) w = glm::normalize(w);
  if (!(glm::dot(w, w) > 0.0f)) return {};
  return direct(light, p, glm::normalize(w));
}

}  // namespace irbake
