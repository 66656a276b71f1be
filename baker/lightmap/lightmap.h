// A baked page: irradiance/π (linear RGB) per texel; a white Lambertian surface shows this value.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace irbake {

struct Lightmap {
  int page = 0;
  int width = 0, height = 0;
  std::vector<glm::vec3> texels;  // irradiance / π, row y = 0 at v = 0
  std::vector<uint8_t> valid;     // 1 where computed from valid samples; others are filled by post
  size_t size() const { return static_cast<size_t>(width) * height; }
};

// Directional maps (transport/directional.h): the L1x, L1y, L1z pages, one Lightmap per page each (axis k
// holds the k-th world component of the tangential irradiance vector t, per colour channel, / π).
using L1Pages = std::array<std::vector<Lightmap>, 3>;

}  // namespace irbake
