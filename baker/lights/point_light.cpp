// Point light: intensity I (W/sr) the same in every direction, E = I cosθ / r².
#include "bake_interface.glsl"  // BAKE_LIGHT_POINT
#include "lights/positional_light.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

class PointLight final : public LightKind {
 public:
  const char* name() const override { return "point"; }
  bool atInfinity() const override { return false; }
  bool aimed() const override { return false; }

  glm::vec3 intensityToward(const Light& light, const glm::vec3&) const override {
    return light.color * light.intensity;
  }
  glm::vec3 power(const Light& light) const override { return 4.0f * kPiF * (light.color * light.intensity); }
  glm::dvec3 walkPower(const Light& light, float) const override { return glm::dvec3(power(light)); }
  double emit(const Light& light, const glm::vec3&, float, double, double, double u2, double u3, glm::vec3& origin,
              glm::vec3& dir) const override {
    origin = light.position;
    dir = uniformSphere(u2, u3);
    return 1.0;
  }

  glm::vec3 toward(const Light& light, const glm::vec3& x) const override { return light.position - x; }
  PunctualContribution direct(const Light& light, const glm::vec3& x, const glm::vec3& nx) const override {
    return positionalDirect(light, x, nx, [this](const Light& l, const glm::vec3& w) { return intensityToward(l, w); });
  }
  bool influences(const Light& light, const glm::vec3& x, float threshold) const override {
    const glm::vec3 d = x - light.position;
    return withinReach(light, glm::dot(d, d), threshold);
  }

  void describeGltf(const Light&, nlohmann::json& gltfLight) const override { gltfLight["type"] = "point"; }
  ShadowProjection shadowProjection(const Light&, float) const override { return ShadowProjection::Cube; }
  int shaderCode() const override { return BAKE_LIGHT_POINT; }
};

}  // namespace

const LightKind& pointLightKind() {
  static const PointLight kind;
  return kind;
}

}  // namespace irbake
