#include "evaluators/gl/gl_resources.h"

#include <algorithm>
#include <utility>

namespace irbake {

namespace {

// 30-bit Morton code of a point in the unit cube: spatially close triangles get close codes.
uint32_t morton3(glm::vec3 u) {
  auto spread = [](uint32_t v) {
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
  };
  const glm::uvec3 q = glm::uvec3(glm::clamp(u, glm::vec3(0.0f), glm::vec3(1.0f)) * 1023.0f);
  return (spread(q.x) << 2) | (spread(q.y) << 1) | spread(q.z);
}

}  // namespace

// See-through primitives (MASK holes, BLEND, transmission) are drawn into shadow maps of their own: a
// lookup that finds one in front of the receiver cannot be answered by depth alone, and its texel is
// resolved with rays (contact texels), which model them.
bool seeThrough(const Scene& scene, const Primitive& prim) {
  const Material& m = scene.materials[prim.material];
  return m.alphaMode == AlphaMode::Mask || m.isTransmissive();
}

// The scene's opaque primitives (or, with seeThroughOnly, the see-through ones) as one vertex/index buffer.
void uploadGeometry(const Scene& scene, int clusterTriangles, GpuGeometry& g, bool seeThroughOnly) {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  for (const Primitive& prim : scene.primitives) {
    if (seeThrough(scene, prim) != seeThroughOnly) continue;
    const uint32_t base = static_cast<uint32_t>(positions.size());
    positions.insert(positions.end(), prim.positions.begin(), prim.positions.end());
    for (uint32_t i : prim.indices) indices.push_back(base + i);
  }
  // Triangles in Morton order of their centroids, so each culling cluster is spatially compact
  // (consecutive triangles of a long strip would give clusters spanning a whole wall).
  const size_t triangleCount = indices.size() / 3;
  const Bounds3 b = scene.bounds();
  const glm::vec3 inv = 1.0f / glm::max(b.extent(), glm::vec3(1e-12f));
  std::vector<std::pair<uint32_t, uint32_t>> order(triangleCount);
  for (size_t t = 0; t < triangleCount; ++t) {
    const glm::vec3 c = (positions[indices[3 * t]] + positions[indices[3 * t + 1]] + positions[indices[3 * t + 2]]) / 3.0f;
    order[t] = {morton3((c - b.min) * inv), static_cast<uint32_t>(t)};
  }
  std::sort(order.begin(), order.end());
  std::vector<uint32_t> sorted(indices.size());
  for (size_t t = 0; t < triangleCount; ++t)
    for (int k = 0; k < 3; ++k) sorted[3 * t + k] = indices[3 * order[t].second + k];
  indices.swap(sorted);
  appendClusters(positions, indices, 0, triangleCount, clusterTriangles, g.clusters);
  g.triangles = indices.size() / 3;
  glCreateVertexArrays(1, &g.vao);
  glCreateBuffers(1, &g.vbo);
  glCreateBuffers(1, &g.ibo);
  glNamedBufferStorage(g.vbo, std::max<size_t>(1, positions.size()) * sizeof(glm::vec3),
                       positions.empty() ? nullptr : positions.data(), 0);
  glNamedBufferStorage(g.ibo, std::max<size_t>(1, indices.size()) * sizeof(uint32_t),
                       indices.empty() ? nullptr : indices.data(), 0);
  glVertexArrayVertexBuffer(g.vao, 0, g.vbo, 0, sizeof(glm::vec3));
  glVertexArrayElementBuffer(g.vao, g.ibo);
  glEnableVertexArrayAttrib(g.vao, 0);
  glVertexArrayAttribFormat(g.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(g.vao, 0, 0);
}

}  // namespace irbake
