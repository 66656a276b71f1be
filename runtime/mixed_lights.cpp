#include "mixed_lights.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <epoxy/gl.h>

#include "common/error.h"

namespace irbake::view {

namespace {

// A mask page: half float RGBA (the 8-bit values exactly), bilinear, no mipmaps (a coarser level would mix
// in the padding between charts), clamped at the page edge, as the light map is.
GLuint uploadMask(int width, int height, const void* rgba) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, width, height, 0, GL_RGBA, GL_FLOAT, rgba);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

}  // namespace

glm::vec3 runtimeLightIrradiance(const Light& light, const glm::vec3& p, const glm::vec3& n) {
  if (light.type == LightType::Directional)
    return light.color * light.intensity * std::max(0.0f, glm::dot(n, -light.direction));
  const glm::vec3 d = light.position - p;
  const float r2 = std::max(glm::dot(d, d), 1e-20f), r = std::sqrt(r2);
  if (light.rangeWindow(r) == 0.0f) return glm::vec3(0.0f);
  const glm::vec3 l = d / r;
  return light.intensityToward(-l) * (std::max(0.0f, glm::dot(n, l)) / r2);
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
    masks_[m.shadowMaskTexture] = uploadMask(t.width, t.height, t.texels.data());
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
    white_ = uploadMask(1, 1, &one);
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
    const float type = l.type == LightType::Point ? 0.0f : l.type == LightType::Spot ? 1.0f : 2.0f;
    const glm::vec3 I = l.color * l.intensity;
    const float cosOuter = std::cos(l.outerConeAngle), cosInner = std::cos(l.innerConeAngle);
    glUniform4f(at("uMixedPosition", i), l.position.x, l.position.y, l.position.z, type);
    glUniform4f(at("uMixedDirection", i), l.direction.x, l.direction.y, l.direction.z, l.range);
    glUniform3f(at("uMixedIntensity", i), I.x, I.y, I.z);
    glUniform2f(at("uMixedCone", i), cosOuter, 1.0f / std::max(0.001f, cosInner - cosOuter));
    glUniform1i(at("uMixedChannel", i), lights_[i].maskChannel);
  }
}

}  // namespace irbake::view
