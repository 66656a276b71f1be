// Small compressed glTF files made by our own code with meshoptimizer's and Draco's encoders: the
// loader's tests and the fuzz seed corpus (tests/fuzz/make_seed_corpus.cpp) use them. Depends on
// nlohmann/json, glm and the two libraries only, so that the fuzz project can build it alone.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace irbake::testing {

// A GLB's JSON and BIN chunk, kept apart so that a test can break either before packing.
struct GlbParts {
  nlohmann::json json;
  std::vector<uint8_t> bin;
};

// One triangle-list mesh on node 0 of scene 0, lit by a point light above it. Meshopt: POSITION
// (ATTRIBUTES, stride 12) and the indices (TRIANGLES, stride 4) are compressed views of buffer 0, backed
// by buffer 1, a fallback buffer without data; bufferView 0 holds the indices, 1 the positions.
GlbParts meshoptParts(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices);
// Draco: the primitive's POSITION (accessor 1, Draco attribute id 0) and indices (accessor 0) are decoded
// from the Draco stream in bufferView 0; the accessors have no views of their own.
GlbParts dracoParts(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices);
// The GLB container of `parts`.
std::vector<uint8_t> glbBytes(const GlbParts& parts);

}  // namespace irbake::testing
