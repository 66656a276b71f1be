#include "mixed_lights.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <epoxy/gl.h>

#include "common/error.h"
#include "lights/light_kind.h"
#include "view_renderer.h"

namespace irbake::view {

glm::vec3 runtimeLightIrradiance(const Light& light, const glm::vec3& p, const glm::vec3& n) {
  const LightKind& kind = lightKind(light.type);
  const glm::vec3 d = kind.toward(light, p);
  if (kind.atInfinity()) return light.color * light.intensity * std::max(0.0f, glm::dot(n, d));
  const float r2 = std::max(glm::dot(d, d), 1e-20f), r = std::sqrt(r2);
  const float window = light.rangeWindow(r);
  if (window == 0.0f) return glm::vec3(0.0f);
  const glm::vec3 l = d / r;
  return kind.intensityToward(light, -l) * (std::max(0.0f, glm::dot(n, l)) / r2 * window);
}

MixedLights::MixedLights(const ViewerScene& v) : scene_(v), lights_(v.scene.runtimeLights) {
  const std::string where = v.scene.sourcePath.empty() ? std::string("scene") : v.scene.sourcePath;
  if (lights_.size() > static_cast<size_t>(kMaxMixedLights))
    throw Error(ErrorCode::InvalidData, where,
                std::to_string(lights_.size()) + " lights in indirect or shadowmask mode: irview shades at most " +
                    std::to_string(kMaxMixedLights));
  for (const Material& m : v.scene.materials) {
    if (m.shadowMaskTexture < 0 || masks_.count(m.shadowMaskTexture)) continue;
    const Texture& t = v.scene.textures.at(static_cast<size_t>(m.shadowMaskTexture));
    if (t.width <= 0 || t.height <= 0 || t.texels.size() != static_cast<size_t>(t.width) * t.height)
      throw Error(ErrorCode::InvalidData, where,
                  "material '" + m.name + "': IRBAKE_shadowmask image '" + t.name + "' could not be decoded");
    masks_[m.shadowMaskTexture] = uploadLightmap(t.width, t.height, GL_RGBA, t.texels.data());
  }
}

MixedLights::~MixedLights() {
  for (auto& [index, tex] : masks_) glDeleteTextures(1, &tex);
  if (white_) glDeleteTextures(1, &white_);
}

unsigned MixedLights::maskTexture(int material) {
  const Material& m = scene_.scene.materials.at(static_cast<size_t>(material));
  auto it = masks_.find(m.shadowMaskTexture);
  if (it != masks_.end()) return it->second;
  if (!white_) {
    const glm::vec4 one(1.0f);
    white_ = uploadLightmap(1, 1, GL_RGBA, &one);
  }
  return white_;
}

void MixedLights::setUniforms(unsigned program, int unit) const {
  const auto at = [program](const char* name, size_t i) {
    return glGetUniformLocation(program, (std::string(name) + "[" + std::to_string(i) + "]").c_str());
  };
  glUniform1i(glGetUniformLocation(program, "uMixedCount"), static_cast<GLint>(lights_.size()));
  glUniform1i(glGetUniformLocation(program, "uShadowMask"), unit);
  for (size_t i = 0; i < lights_.size(); ++i) {
    const Light& l = lights_[i].light;
    const ShaderLight s = lightKind(l.type).shaderLight(l);
    const float type = static_cast<float>(s.code);
    glUniform4f(at("uMixedPosition", i), l.position.x, l.position.y, l.position.z, type);
    glUniform4f(at("uMixedDirection", i), l.direction.x, l.direction.y, l.direction.z, l.range);
    glUniform3f(at("uMixedIntensity", i), s.intensity.x, s.intensity.y, s.intensity.z);
    glUniform2f(at("uMixedCone", i), s.cosOuter, s.spotScale);
    glUniform1i(at("uMixedChannel", i), lights_[i].maskChannel);
  }
}

}  // namespace irbake::view
