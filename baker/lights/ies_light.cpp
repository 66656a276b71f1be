// IES light (EXT_lights_ies): a point light whose intensity towards ω is candela(θ, φ) × multiplier × colour,
// with θ from the light's nadir (the node's −Z) and φ from its +X towards +Y (scene/ies_profile.h).
#include <algorithm>
#include <cmath>

#include "bake_interface.glsl"  // BAKE_LIGHT_IES
#include "common/base64.h"
#include "lights/positional_light.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

constexpr double kDegrees = 180.0 / kPi;

// The profile's angles (degrees) of a unit direction leaving the light.
void profileAngles(const Light& light, const glm::vec3& dir, double& theta, double& phi) {
  const glm::vec3 nadir = light.direction, x = light.profileAxisX, y = glm::cross(-nadir, x);
  const glm::dvec3 w(dir), n(nadir);
  theta = std::atan2(glm::length(glm::cross(w, n)), glm::dot(w, n)) * kDegrees;  // exact near the nadir, unlike acos
  phi = std::atan2(static_cast<double>(glm::dot(dir, y)), static_cast<double>(glm::dot(dir, x))) * kDegrees;
}

class IesLight final : public LightKind {
 public:
  const char* name() const override { return "ies"; }
  bool atInfinity() const override { return false; }
  bool aimed() const override { return true; }

  glm::vec3 intensityToward(const Light& light, const glm::vec3& dirFromLight) const override {
    if (!light.profile) return glm::vec3(0.0f);
    double theta, phi;
    profileAngles(light, dirFromLight, theta, phi);
    return light.color * light.intensity * static_cast<float>(light.profile->candelaAt(theta, phi));
  }
  glm::vec3 power(const Light& light) const override {
    return light.profile ? light.color * light.intensity * static_cast<float>(light.profile->integral()) : glm::vec3(0.0f);
  }
  glm::dvec3 walkPower(const Light& light, float) const override { return glm::dvec3(power(light)); }
  // A cell of the profile by its share of the power (u0), a direction uniform in solid angle inside it (u2, u3),
  // weighted by the intensity there against the cell's mean.
  double emit(const Light& light, const glm::vec3&, float, double u0, double, double u2, double u3,
              glm::vec3& origin, glm::vec3& dir) const override {
    origin = light.position;
    dir = light.direction;
    if (!light.profile || !(light.profile->integral() > 0.0)) return 0.0;
    const IesProfile& p = *light.profile;
    const size_t cells = p.cellCdf.size(), rows = p.vertical.size() - 1;
    const double target = std::clamp(u0, 0.0, 1.0) * p.cellCdf.back();
    size_t c = std::min<size_t>(std::upper_bound(p.cellCdf.begin(), p.cellCdf.end(), target) - p.cellCdf.begin(), cells - 1);
    while (c > 0 && !(p.cellIntegral(c / rows, c % rows) > 0.0)) --c;  // u0 = 1 past the last lit cell
    const size_t h = c / rows, v = c % rows;
    const double cos0 = std::cos(p.vertical[v] / kDegrees), cos1 = std::cos(p.vertical[v + 1] / kDegrees);
    const double cosTheta = cos0 + (cos1 - cos0) * u2;
    const double phi = (p.horizontal[h] + (p.horizontal[h + 1] - p.horizontal[h]) * u3) / kDegrees;
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const glm::vec3 x = light.profileAxisX, y = glm::cross(-light.direction, x);
    dir = glm::normalize(x * float(sinTheta * std::cos(phi)) + y * float(sinTheta * std::sin(phi)) +
                         light.direction * float(cosTheta));
    const double solidAngle = (cos0 - cos1) * (p.horizontal[h + 1] - p.horizontal[h]) / kDegrees;
    const double candela = p.candelaAt(std::acos(std::clamp(cosTheta, -1.0, 1.0)) * kDegrees, phi * kDegrees);
    return candela * solidAngle / p.cellIntegral(h, v);
  }

  glm::vec3 toward(const Light& light, const glm::vec3& x) const override { return light.position - x; }
  PunctualContribution direct(const Light& light, const glm::vec3& x, const glm::vec3& nx) const override {
    return positionalDirect(light, x, nx, [this](const Light& l, const glm::vec3& w) { return intensityToward(l, w); });
  }
  bool influences(const Light& light, const glm::vec3& x, float threshold) const override {
    const glm::vec3 d = x - light.position;
    return light.profile && withinReach(light, glm::dot(d, d), threshold, static_cast<float>(light.profile->maxCandela));
  }

  // The profile object of EXT_lights_ies' root "lights": the file as a data URI.
  void describeGltf(const Light& light, nlohmann::json& gltfLight) const override {
    if (!light.profile) return;
    gltfLight["uri"] = "data:application/x-ies-lm-63;base64," + base64Encode(light.profile->text);
  }
  ShadowProjection shadowProjection(const Light&, float) const override { return ShadowProjection::Cube; }
  int shaderCode() const override { return BAKE_LIGHT_IES; }
};

}  // namespace

const LightKind& iesLightKind() {
  static const IesLight kind;
  return kind;
}

}  // namespace irbake
