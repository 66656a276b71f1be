// irview's mixed lighting (docs/viewer.md, "Mixed lights"): the lights an irbake export leaves to the client
// (Scene::runtimeLights: indirect and shadowmask modes) are shaded in real time on every light-mapped
// surface, radiance += baseColor/π × E_direct × visibility, where visibility is the light's channel of the
// material's IRBAKE_shadowmask page (the 8-bit linear PNG) and 1 for an indirect light (no baked visibility:
// unshadowed). Needs a current GL context; the shader side is shaders/view_mixed_lights.glsl.
#pragma once
#include <map>
#include <vector>

#include <glm/glm.hpp>

#include "viewer_scene.h"

namespace irbake::view {

// Lights one draw shades at most (the shader's uniform arrays).
constexpr int kMaxMixedLights = 16;

// The direct irradiance (W/m², RGB) of a runtime light at point p with unit normal n, unshadowed: what the
// shader computes before the mask (KHR_lights_punctual units; spot falloff as the spot kind's intensityToward).
glm::vec3 runtimeLightIrradiance(const Light& light, const glm::vec3& p, const glm::vec3& n);

class MixedLights {
 public:
  // Uploads each material's mask page. Throws Error(InvalidData) naming the scene for more than
  // kMaxMixedLights runtime lights, or a mask page that is not width × height RGBA texels.
  explicit MixedLights(const ViewerScene& v);
  ~MixedLights();
  MixedLights(const MixedLights&) = delete;
  MixedLights& operator=(const MixedLights&) = delete;

  size_t count() const { return lights_.size(); }
  // A light-mapped primitive shades the runtime lights (static surfaces: the ones the bake mapped).
  bool shades(bool hasLightmap) const { return hasLightmap && !lights_.empty(); }
  // The material's mask texture, or a white one (visibility 1) when it has none.
  unsigned maskTexture(int material);
  // Sets the lights' uniforms and uShadowMask = texture unit `unit` on the bound program.
  void setUniforms(unsigned program, int unit) const;

 private:
  const ViewerScene& scene_;
  std::vector<RuntimeLight> lights_;
  std::map<int, unsigned> masks_;  // Scene::textures index → GL texture
  unsigned white_ = 0;
};

}  // namespace irbake::view
