// Shadow-view geometry for the GL backend (CPU side, no GL calls): VPL frames, cube faces in the
// VPL's normal-aligned frame (only the faces its hemisphere sees, side faces scissored to the upper
// half), spot perspective and directional ortho views, and per-view culling of triangle clusters.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "texels/texel_samples.h"
#include "vpl/vpl.h"

namespace irbake {

// Distances derived from the scene size (docs/units.md, "Shadow maps: depth precision and bias").
struct ShadowScale {
  float nearPlane = 1e-5f;     // reversed-Z near plane (m)
  float constantBias = 1e-5f;  // constant depth bias (m)
  float originOffset = 1e-4f;  // VPL shadow origin pushed off its surface along the normal (m)
};

// Orthonormal frame; local +Z = normal. Cube faces are laid out in this frame.
struct VplFrame {
  glm::vec3 tangent, bitangent, normal;
};
VplFrame vplFrame(const glm::vec3& normal);

// One rendered shadow view: world → clip matrix (GL clip space with [0,1] depth), scissor
// rectangle (x, y, w, h) in texels, and world-space culling planes (a·p + d ≥ 0 inside).
struct ShadowView {
  glm::mat4 clip{1.0f};
  glm::ivec4 scissor{0};
  std::vector<glm::vec4> planes;
};

// Cube face `face` (GL order +X −X +Y −Y +Z −Z, in the frame's local axes) seen from origin, with
// reversed-Z infinite-far depth (window depth = near / axis distance). hemisphereOnly: drop the −Z
// face, scissor the side faces to the half with local z ≥ 0 (one texel margin) and cull below the plane.
std::optional<ShadowView> cubeFaceView(const glm::vec3& origin, const VplFrame& frame, int face, int size,
                                       float nearPlane, bool hemisphereOnly);

// The GL cube-map face and (s, t) a local direction looks up (OpenGL 4.5 table 8.19), for tests.
int cubeFaceOf(const glm::vec3& dir, glm::vec2& st);

// Spot light: one perspective view (reversed-Z) around its axis covering the outer cone.
// tanHalfFov: out, tangent of the half field of view.
ShadowView spotView(const glm::vec3& position, const glm::vec3& direction, float outerConeAngle, int size,
                    float nearPlane, float& tanHalfFov);

// Directional light: an orthographic box fitted to the scene bounds, depth 0 nearest the light.
// texelSize: out, world size of one texel (m); depthRange: out, metres per unit of window depth.
ShadowView directionalView(const glm::vec3& direction, const Bounds3& bounds, int size, float& texelSize,
                           float& depthRange);

// VPL cube face size from what the light map can show: a face texel's footprint 2r/F at the typical VPL →
// receiver distance r is held to `footprintPerTexel` texel spacings h, F = 2r / (footprintPerTexel·h), rounded
// up to a multiple of 32 and clamped to [minSize, maxSize]. At 1 the 2×2 filter blurs an edge about as much as
// the map does. r: the contribution-weighted median distance of sampled facing (VPL, valid texel) pairs;
// h: the pages' median texel spacing (one interleave class's pages: n times the full page's).
struct CubeFaceChoice {
  int size = 0;                // chosen face size (texels)
  float medianDistance = 0.0f; // r (m); 0 when no facing pair was found (size = maxSize)
  float texelSpacing = 0.0f;   // h (m); 0 when no page has a spacing (size = maxSize)
};
CubeFaceChoice chooseCubeFaceSize(const std::vector<Vpl>& vpls, const std::vector<TexelSamples>& pages,
                                  float clampBound, float footprintPerTexel, int minSize, int maxSize,
                                  int pairSamples = 4096);

// Consecutive triangles of one primitive in the global index buffer with their bounds.
struct TriangleCluster {
  size_t firstIndex = 0;  // into the index buffer
  size_t indexCount = 0;
  Bounds3 bounds;
};
void appendClusters(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices, size_t firstIndex,
                    size_t triangleCount, int clusterTriangles, std::vector<TriangleCluster>& clusters);

// Appends glMultiDrawElements ranges (counts, byte offsets) of the clusters inside the view,
// merging neighbours; adds the submitted triangle count to trianglesDrawn.
void cullClusters(const ShadowView& view, const std::vector<TriangleCluster>& clusters, std::vector<int>& counts,
                  std::vector<const void*>& offsets, size_t& trianglesDrawn);

}  // namespace irbake
