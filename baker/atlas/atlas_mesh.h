// Stage 1 of the atlas: one primitive as a welded half-edge mesh (OpenMesh), flattened into the
// per-face adjacency the later stages walk. Seams (hard normals) and non-manifold splits are marked here.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake::atlas {

constexpr uint32_t kNone = 0xffffffffu;

struct MeshOptions {
  double weldTolerance = 1e-6;     // weld distance relative to the bounding-box diagonal; faces thinner
                                   // than it (area < tolerance × diagonal × longest edge) are degenerate
  double hardNormalDegrees = 1.0;  // corner normals further apart than this make the edge a seam
};

// Faces keep the primitive's triangle order. faceVertex ids index vertexPos (welded, then split
// where OpenMesh refused a non-manifold face). Degenerate faces take no part in adjacency.
struct AtlasMesh {
  std::vector<std::array<uint32_t, 3>> faceVertex;     // welded vertex per corner
  std::vector<std::array<uint32_t, 3>> faceNeighbour;  // face across edge (corner k -> k+1), kNone if none
  std::vector<uint8_t> seamEdge;                        // bit k: edge k is a hard edge (never crossed)
  std::vector<uint8_t> degenerate;                      // 1: zero area or repeated corners
  std::vector<glm::dvec3> vertexPos;
  std::vector<glm::dvec3> faceNormal;                   // unit (zero for degenerate faces)
  std::vector<double> faceArea;
  double meanEdge = 0.0;       // mean edge length of the non-degenerate faces
  double diagonal = 0.0;       // bounding-box diagonal
  size_t degenerateFaces = 0;
  size_t nonManifoldFaces = 0;  // faces whose corners were duplicated so OpenMesh accepted them
  size_t faceCount() const { return faceVertex.size(); }
};

AtlasMesh buildAtlasMesh(const Primitive& prim, const MeshOptions& options = {});

}  // namespace irbake::atlas
