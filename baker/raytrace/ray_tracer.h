// Embree 3 scene over the scene model: closest-hit and occlusion queries, scene-scaled offsets,
// textured albedo at hits. Alpha MASK cut-outs are holes. Thread-safe for queries.
#pragma once
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

struct RayHit {
  bool hit = false;
  float t = 0.0f;
  uint32_t primitive = 0, triangle = 0;
  glm::vec2 barycentric{0.0f};      // (u, v): p = (1-u-v) v0 + u v1 + v v2
  glm::vec3 position{0.0f};
  glm::vec3 geometricNormal{0.0f};  // unit, as wound (front face is counter-clockwise)
  glm::vec3 shadingNormal{0.0f};    // interpolated vertex normal, unit
  bool backFace = false;            // the ray hit the back of the triangle
};

// A shadow-ray segment: origin, unit direction, and the distance to test up to.
struct ShadowRay {
  glm::vec3 origin{0.0f};
  glm::vec3 dir{0.0f, 0.0f, 1.0f};
  float tmax = 0.0f;
};

class RayTracer {
 public:
  explicit RayTracer(const Scene& scene);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  RayHit intersect(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const;
  // Closest hits of n rays from one origin (tmin 0, tmax ∞) in packets of 8 (rtcIntersect8; single rays where
  // this Embree build has no native 8-wide packets): hits[i] as intersect(origin, dirs[i], 0, ∞) gives it.
  // HitDetail::Surface leaves position and shadingNormal unset (the final gather reads the map and the
  // material at the hit's triangle and barycentrics only, for tens of millions of hits).
  enum class HitDetail { Full, Surface };
  // Traversal::Robust: Embree's robust mode (RTC_SCENE_FLAG_ROBUST), as every other query here: a ray through an
  // edge or a corner shared by two triangles never slips between them. Traversal::Fast: a second BVH over the
  // same geometries without it, faster on the gather's rays, where a ray aimed exactly through a shared
  // edge may slip (RayTracer.FastTraversalHitsWhereRobustDoesOffExactEdges: 5 of 4096 such rays, none of a grid
  // that passes beside the edges). For the final gather's tens of millions of cosine rays from jittered samples,
  // each one of a texel's 16 and filtered over 49 texels; not for leak tests or visibility.
  enum class Traversal { Robust, Fast };
  void intersectPackets(const glm::vec3& origin, const glm::vec3* dirs, size_t n, RayHit* hits,
                        HitDetail detail = HitDetail::Full, Traversal traversal = Traversal::Robust) const;
  // Opaque occlusion: see-through surfaces (Material::isTransmissive) are skipped, MASK holes too.
  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const;
  // The product of the see-through surfaces' transmittances along a ray that occluded() found clear
  // (RGB; 1 in scenes without see-through materials).
  glm::vec3 transmittance(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const;
  bool hasTransmission() const { return hasTransmission_; }
  // Mutual visibility of two surface points, offset along their normals by epsilon().
  bool visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) const;
  // The shadow ray visible() traces; false when the points are closer than epsilon() (always visible).
  bool visibilityRay(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb, ShadowRay& ray) const;
  // Occlusion of n rays in packets of 8 (rtcOccluded8); occluded[i] = 1 when ray i is blocked.
  void occludedPackets(const ShadowRay* rays, size_t n, uint8_t* occluded) const;
  // A surface point of triangle (primitive, triangle) moved epsilon() towards the triangle's centroid:
  // points on edges and corners (quasi-random samples hit vertices exactly) then lie strictly inside
  // their face, so a normal offset never lands on a neighbouring face's plane (no leaks at corners).
  glm::vec3 insetPoint(uint32_t primitive, uint32_t triangle, const glm::vec3& p) const;
  // Ray origin for leaving that surface point on the side of n: insetPoint + epsilon() · n.
  glm::vec3 spawnPoint(uint32_t primitive, uint32_t triangle, const glm::vec3& p, const glm::vec3& n) const {
    return insetPoint(primitive, triangle, p) + n * epsilon_;
  }
  // Self-intersection offset scaled to the scene (relative to its bounding-box size).
  float epsilon() const { return epsilon_; }
  // Textured diffuse albedo (linear RGB) at a hit: baseColorFactor × baseColorTexture.
  glm::vec3 albedoAt(const RayHit& hit) const;
  const Scene& scene() const { return scene_; }

 private:
  // A hit's position, normals and side from Embree's ids and barycentrics.
  RayHit completeHit(const glm::vec3& dir, float t, uint32_t geomID, uint32_t primID, glm::vec2 uv,
                     HitDetail detail = HitDetail::Full) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Scene& scene_;
  float epsilon_ = 1e-4f;
  bool hasTransmission_ = false;
};

}  // namespace irbake
