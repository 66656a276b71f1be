// A triangle's area (world space: the loader has applied the node transforms), the one formula every stage
// that weighs surfaces by area uses (emitter power, the clamp's mean, the final gather's emitter share).
#pragma once
#include <cstddef>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

inline double triangleArea(const Primitive& p, size_t triangle) {
  const glm::vec3& a = p.positions[p.indices[3 * triangle]];
  const glm::vec3& b = p.positions[p.indices[3 * triangle + 1]];
  const glm::vec3& c = p.positions[p.indices[3 * triangle + 2]];
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

}  // namespace irbake
