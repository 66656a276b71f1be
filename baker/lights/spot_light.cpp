// Spot light: a point light within a cone, with glTF's recommended smooth falloff: t² with t linear in cosθ
// between the outer and the inner cone angle, 1 inside the inner cone.
#include "bake_interface.glsl"  // BAKE_LIGHT_SPOT
#include "lights/positional_light.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

// Direction from a spot light distributed like its intensity t(cosθ)², so every path carries the same power.
glm::vec3 spotDirection(const Light& l, double u, double v) {
  double cosO = std::cos(l.outerConeAngle), cosI = std::cos(l.innerConeAngle);
  double band = std::max(0.0, cosI - cosO);
  if (band < 0.001) {  // matches intensityToward's minimum band
    band = 0.001;
    cosI = cosO + band;
  }
  double massBand = band / 3.0, massInner = std::max(0.0, 1.0 - cosI);
  double c;
  if (u * (massBand + massInner) < massBand) {
    double s = u * (massBand + massInner) / massBand;  // CDF ∝ x³ over the band
    c = cosO + band * std::cbrt(s);
  } else {
    double s = (u * (massBand + massInner) - massBand) / std::max(massInner, 1e-300);
    c = cosI + (1.0 - cosI) * std::min(s, 1.0);
  }
  c = std::clamp(c, -1.0, 1.0);
  double sn = std::sqrt(std::max(0.0, 1.0 - c * c)), phi = 2.0 * kPi * v;
  glm::vec3 t, b, d = glm::normalize(l.direction);
  orthonormalBasis(d, t, b);
  return glm::normalize(t * float(sn * std::cos(phi)) + b * float(sn * std::sin(phi)) + d * float(c));
}

class SpotLight final : public LightKind {
 public:
  const char* name() const override { return "spot"; }
  bool atInfinity() const override { return false; }
  bool aimed() const override { return true; }

  glm::vec3 intensityToward(const Light& light, const glm::vec3& dirFromLight) const override {
    glm::vec3 I = light.color * light.intensity;
    float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
    float scale = 1.0f / std::max(0.001f, cosInner - cosOuter);
    float t = std::clamp((glm::dot(light.direction, dirFromLight) - cosOuter) * scale, 0.0f, 1.0f);
    return I * (t * t);
  }
  // ∫ over the cone of t(cosθ)² dω with t linear in cosθ: full inside the inner cone, (cosI − cosO)/3 of the band
  // between the cones (exact when cosI − cosO ≥ 0.001).
  glm::vec3 power(const Light& light) const override {
    double cosO = std::cos(light.outerConeAngle), cosI = std::cos(light.innerConeAngle);
    double band = std::max(0.0, cosI - cosO);
    double solid = 2.0 * kPi * ((1.0 - cosI) + band / 3.0);
    return static_cast<float>(solid) * (light.color * light.intensity);
  }
  glm::dvec3 walkPower(const Light& light, float) const override { return glm::dvec3(power(light)); }
  double emit(const Light& light, const glm::vec3&, float, double, double, double u2, double u3, glm::vec3& origin,
              glm::vec3& dir) const override {
    origin = light.position;
    dir = spotDirection(light, u2, u3);
    return 1.0;
  }

  glm::vec3 toward(const Light& light, const glm::vec3& x) const override { return light.position - x; }
  PunctualContribution direct(const Light& light, const glm::vec3& x, const glm::vec3& nx) const override {
    return positionalDirect(light, x, nx, [this](const Light& l, const glm::vec3& w) { return intensityToward(l, w); });
  }
  bool influences(const Light& light, const glm::vec3& x, float threshold) const override {
    const glm::vec3 d = x - light.position;
    const float r2 = glm::dot(d, d);
    if (!withinReach(light, r2, threshold)) return false;
    if (r2 > 0.0f) return glm::dot(d, light.direction) >= std::cos(light.outerConeAngle) * std::sqrt(r2);
    return true;
  }

  void describeGltf(const Light& light, nlohmann::json& gltfLight) const override {
    gltfLight["type"] = "spot";
    gltfLight["spot"] = {{"innerConeAngle", light.innerConeAngle}, {"outerConeAngle", light.outerConeAngle}};
  }
  ShadowProjection shadowProjection(const Light& light, float maxPerspectiveAngle) const override {
    return light.outerConeAngle > maxPerspectiveAngle ? ShadowProjection::Cube : ShadowProjection::Perspective;
  }
  int shaderCode() const override { return BAKE_LIGHT_SPOT; }
};

}  // namespace

const LightKind& spotLightKind() {
  static const SpotLight kind;
  return kind;
}

}  // namespace irbake
