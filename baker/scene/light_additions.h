// Light a bake adds to its scene: a sun, a uniform sky or an environment map (irbake bake --sun, --sky,
// --env), settled and checked when the options are read, added once the scene is loaded.
#pragma once
#include <filesystem>
#include <optional>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

struct LightAdditions {
  std::optional<Light> sun;            // a directional light (directionalLight)
  std::optional<glm::vec3> sky;        // a uniform sky's radiance, W/(m² sr); excludes environment
  std::filesystem::path environment;   // an equirectangular map (.exr/.hdr, +Y up); empty: none
  float environmentIntensity = 1.0f;   // scales the map
  float environmentRotation = 0.0f;    // turns the map about +Y (degrees)
};

// A directional light travelling along direction (any non-zero length) with irradiance W/m² (> 0).
// Throws Error(Usage) otherwise.
Light directionalLight(const glm::vec3& direction, float irradiance, const std::string& name = "sun (command line)");

// Adds the sun, and the sky or the environment map (read here: Error(Io | InvalidData) naming the file).
void addLights(Scene& scene, const LightAdditions& additions);

}  // namespace irbake
