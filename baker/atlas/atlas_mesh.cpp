#include "atlas/atlas_mesh.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

namespace irbake::atlas {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

struct CellHash {
  size_t operator()(const std::array<int64_t, 3>& c) const {
    return size_t(c[0] * 73856093) ^ size_t(c[1] * 19349663) ^ size_t(c[2] * 83492791);
  }
};

// Welds the primitive's positions on a grid of `cell`: appends one position per occupied cell to
// vertexPos and returns the welded vertex of every input vertex. The cell map (~60 bytes per vertex)
// is gone before the half-edge structure is built, the atlas stage's peak (docs/validation.md, "Memory").
std::vector<uint32_t> weldPositions(const Primitive& prim, double cell, std::vector<glm::dvec3>& vertexPos) {
  std::vector<uint32_t> weldOf(prim.positions.size());
  std::unordered_map<std::array<int64_t, 3>, uint32_t, CellHash> cells;
  for (size_t i = 0; i < prim.positions.size(); ++i) {
    const glm::dvec3 p(prim.positions[i]);
    const std::array<int64_t, 3> key{int64_t(std::llround(p.x / cell)), int64_t(std::llround(p.y / cell)),
                                     int64_t(std::llround(p.z / cell))};
    auto [it, added] = cells.try_emplace(key, uint32_t(vertexPos.size()));
    if (added) vertexPos.push_back(p);
    weldOf[i] = it->second;
  }
  return weldOf;
}

}  // namespace

AtlasMesh buildAtlasMesh(const Primitive& prim, const MeshOptions& options) {
  AtlasMesh mesh;
  const size_t faces = prim.triangleCount();
  Bounds3 bounds;
  for (const glm::vec3& p : prim.positions) bounds.extend(p);
  mesh.diagonal = bounds.diagonal();

  // Weld by position on a grid relative to the mesh size, so the result does not depend on units.
  std::vector<uint32_t> weldOf = weldPositions(prim, std::max(mesh.diagonal * options.weldTolerance, 1e-30), mesh.vertexPos);

  mesh.faceVertex.resize(faces);
  mesh.faceNeighbour.assign(faces, {kNone, kNone, kNone});
  mesh.seamEdge.assign(faces, 0);
  mesh.degenerate.assign(faces, 0);
  mesh.faceNormal.assign(faces, glm::dvec3(0.0));
  mesh.faceArea.assign(faces, 0.0);

  double edgeSum = 0.0;
  size_t edgeCount = 0;
  for (size_t f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) mesh.faceVertex[f][k] = weldOf[prim.indices[3 * f + k]];
    const auto& v = mesh.faceVertex[f];
    const glm::dvec3 &a = mesh.vertexPos[v[0]], &b = mesh.vertexPos[v[1]], &c = mesh.vertexPos[v[2]];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    mesh.faceArea[f] = 0.5 * glm::length(n);
    if (v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) {
      edgeSum += glm::length(b - a) + glm::length(c - b) + glm::length(a - c);
      edgeCount += 3;
    }
  }
  mesh.meanEdge = edgeCount ? edgeSum / double(edgeCount) : 0.0;
  std::vector<uint32_t>().swap(weldOf);
  for (size_t f = 0; f < faces; ++f) {
    const auto& v = mesh.faceVertex[f];
    const bool repeated = v[0] == v[1] || v[1] == v[2] || v[0] == v[2];
    const glm::dvec3 &a = mesh.vertexPos[v[0]], &b = mesh.vertexPos[v[1]], &c = mesh.vertexPos[v[2]];
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    // Thinner than the weld tolerance: such a face has no surface to give texels to.
    if (repeated || !(mesh.faceArea[f] > options.weldTolerance * mesh.diagonal * longest)) {
      mesh.degenerate[f] = 1;
      ++mesh.degenerateFaces;
      continue;
    }
    mesh.faceNormal[f] = glm::normalize(glm::cross(b - a, c - a));
  }

  // The half-edge structure: OpenMesh refuses faces that would make an edge or vertex non-manifold;
  // such a face gets its own copies of its corners (it becomes an island) so no face is lost.
  OmMesh om;
  // Edges: V + F − χ by Euler's formula, so V + F is enough for any union of discs and spheres (an
  // open grid has V + F − 1; faces·3/2, the closed-mesh count, was short there and the edge array
  // doubled while full). Never more than 3F.
  om.reserve(mesh.vertexPos.size(), std::min(mesh.vertexPos.size() + faces, 3 * faces), faces);
  for (const glm::dvec3& p : mesh.vertexPos) om.add_vertex(OmMesh::Point(float(p.x), float(p.y), float(p.z)));
  std::vector<uint32_t> faceOfOm;
  faceOfOm.reserve(faces);
  // Refused faces are handled here; OpenMesh's message about each is noise. Switched off once for the
  // process: meshes are built on several threads, and toggling the shared stream per mesh would race.
  static const bool quiet = (omerr().disable(), true);
  (void)quiet;
  for (size_t f = 0; f < faces; ++f) {
    if (mesh.degenerate[f]) continue;
    auto& v = mesh.faceVertex[f];
    OmMesh::FaceHandle fh = om.add_face(OmMesh::VertexHandle(int(v[0])), OmMesh::VertexHandle(int(v[1])),
                                        OmMesh::VertexHandle(int(v[2])));
    if (!fh.is_valid()) {
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 p = mesh.vertexPos[v[k]];
        v[k] = uint32_t(mesh.vertexPos.size());
        mesh.vertexPos.push_back(p);
        om.add_vertex(OmMesh::Point(float(p.x), float(p.y), float(p.z)));
      }
      fh = om.add_face(OmMesh::VertexHandle(int(v[0])), OmMesh::VertexHandle(int(v[1])),
                       OmMesh::VertexHandle(int(v[2])));
      ++mesh.nonManifoldFaces;
    }
    if (size_t(fh.idx()) != faceOfOm.size()) faceOfOm.resize(size_t(fh.idx()));
    faceOfOm.push_back(uint32_t(f));
  }

  // Normal breaks are seams only when authored: flat normals the loader computed break at every edge.
  const bool hasNormals = prim.normals.size() == prim.positions.size() && !prim.normalsComputed;
  const double hardCos = std::cos(glm::radians(options.hardNormalDegrees));
  for (size_t f = 0; f < faces; ++f) {
    if (mesh.degenerate[f]) continue;
    const auto& v = mesh.faceVertex[f];
    for (int k = 0; k < 3; ++k) {
      const auto heh = om.find_halfedge(OmMesh::VertexHandle(int(v[k])), OmMesh::VertexHandle(int(v[(k + 1) % 3])));
      if (!heh.is_valid()) continue;
      const auto opp = om.opposite_halfedge_handle(heh);
      const auto ofh = om.face_handle(opp);
      if (!ofh.is_valid()) continue;
      const uint32_t g = faceOfOm[size_t(ofh.idx())];
      mesh.faceNeighbour[f][k] = g;
      if (!hasNormals) continue;
      // Hard edge: the two faces' corners at either end of the edge carry different normals.
      for (int e = 0; e < 2; ++e) {
        const uint32_t wv = v[(k + e) % 3];
        const glm::vec3 nf = prim.normals[prim.indices[3 * f + (k + e) % 3]];
        for (int j = 0; j < 3; ++j) {
          if (mesh.faceVertex[g][j] != wv) continue;
          const glm::vec3 ng = prim.normals[prim.indices[3 * g + j]];
          if (double(glm::dot(nf, ng)) < hardCos * double(glm::length(nf) * glm::length(ng))) mesh.seamEdge[f] |= uint8_t(1u << k);
        }
      }
    }
  }
  return mesh;
}

}  // namespace irbake::atlas
