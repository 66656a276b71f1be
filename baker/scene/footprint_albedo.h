// The base colour at a ray hit read at the size of one light-map texel there, for the stages that multiply it
// by the baked map at the hit (the final gather reads the map bilinearly, so finer albedo detail than a map texel
// averages out anyway).
//
// Each base-colour texture gets a box-filtered mip chain; each triangle the level whose texel is no larger than a
// light-map texel on it (from the two UV sets' areas). The gather's hits then read small levels that stay in
// cache instead of missing it in full-size ones, and each read is the texture's mean over the footprint rather
// than one point of it.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

// Texture level k + 1 of `tex`: half its size (at least 1), each texel the exact mean of the texels of level k
// whose centres fall in it (odd sizes included), with tex's wrap modes.
Texture downsampleTexture(const Texture& tex);

class FootprintAlbedo {
 public:
  // Levels from each primitive's LightmapRef (its page's size in texels) and lightmap UVs. A triangle without a
  // page, without lightmap UVs or with a degenerate UV triangle reads level 0 (the texture itself).
  explicit FootprintAlbedo(const Scene& scene);
  // The base colour's rgb at barycentric (u, v) of the triangle, as Scene::baseColorAt with the texture read at
  // the triangle's level.
  glm::vec3 at(uint32_t primitive, uint32_t triangle, glm::vec2 barycentric) const;
  // The level triangle t of primitive p reads (0: the texture itself); 0 for untextured materials.
  int level(uint32_t primitive, uint32_t triangle) const { return level_[primitive][triangle]; }

 private:
  const Scene& scene_;
  std::vector<std::vector<Texture>> coarser_;  // per scene texture: levels 1, 2, … down to 1×1
  std::vector<std::vector<uint8_t>> level_;    // per primitive, per triangle
};

}  // namespace irbake
