// Directional light (the sun): irradiance I (W/m²) from one direction everywhere, E = I cosθ.
#include <cmath>
#include <limits>

#include "bake_interface.glsl"  // BAKE_LIGHT_DIRECTIONAL
#include "common/maths.h"
#include "lights/light_kind.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

class DirectionalLight final : public LightKind {
 public:
  const char* name() const override { return "directional"; }
  bool atInfinity() const override { return true; }
  bool aimed() const override { return true; }

  glm::vec3 intensityToward(const Light& light, const glm::vec3&) const override {
    return light.color * light.intensity;
  }
  glm::vec3 power(const Light&) const override { return glm::vec3(0.0f); }
  glm::dvec3 walkPower(const Light& light, float sceneRadius) const override {
    return glm::dvec3(light.color * light.intensity) * (kPi * sceneRadius * sceneRadius);
  }
  double emit(const Light& light, const glm::vec3& sceneCentre, float sceneRadius, double u0, double u1, double,
              double, glm::vec3& origin, glm::vec3& dir) const override {
    dir = glm::normalize(light.direction);
    glm::vec3 t, b;
    orthonormalBasis(dir, t, b);
    const double r = sceneRadius * std::sqrt(u0), phi = 2.0 * kPi * u1;
    origin = sceneCentre - dir * (1.01f * sceneRadius) + t * float(r * std::cos(phi)) + b * float(r * std::sin(phi));
    return 1.0;
  }

  glm::vec3 toward(const Light& light, const glm::vec3&) const override { return -light.direction; }
  PunctualContribution direct(const Light& light, const glm::vec3&, const glm::vec3& nx) const override {
    PunctualContribution c;
    glm::vec3 l = -glm::normalize(light.direction);
    float cosX = glm::dot(nx, l);
    if (cosX <= 0.0f) return c;
    c.toLight = l;
    c.distance = std::numeric_limits<float>::infinity();
    c.mapValue = light.color * light.intensity * (cosX / kPiF);
    return c;
  }
  bool influences(const Light&, const glm::vec3&, float) const override { return true; }

  void describeGltf(const Light&, nlohmann::json& gltfLight) const override { gltfLight["type"] = "directional"; }
  ShadowProjection shadowProjection(const Light&, float) const override { return ShadowProjection::Orthographic; }
  int shaderCode() const override { return BAKE_LIGHT_DIRECTIONAL; }
};

}  // namespace

const LightKind& directionalLightKind() {
  static const DirectionalLight kind;
  return kind;
}

}  // namespace irbake
