#include "scene/light_additions.h"

#include <cmath>

#include "common/error.h"
#include "scene/environment.h"

namespace irbake {

Light directionalLight(const glm::vec3& direction, float irradiance, const std::string& name) {
  const float len = glm::length(direction);
  if (!(len > 0.0f) || !std::isfinite(len)) throw Error(ErrorCode::Usage, "", "--sun needs a non-zero direction");
  if (!(irradiance > 0.0f) || !std::isfinite(irradiance))
    throw Error(ErrorCode::Usage, "", "--sun needs a positive irradiance");
  Light sun;
  sun.name = name;
  sun.type = LightType::Directional;
  sun.direction = direction / len;
  sun.intensity = irradiance;
  return sun;
}

void addLights(Scene& scene, const LightAdditions& additions) {
  if (additions.sky && !additions.environment.empty())
    throw Error(ErrorCode::Usage, "", "--sky and --env exclude each other");
  if (additions.sun) scene.lights.push_back(*additions.sun);
  if (additions.sky) scene.environment = Environment::uniform(*additions.sky);
  if (!additions.environment.empty())
    scene.environment =
        loadEnvironment(additions.environment, additions.environmentIntensity, additions.environmentRotation);
}

}  // namespace irbake
