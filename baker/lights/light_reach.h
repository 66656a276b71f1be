// How far each light reaches, and the lights near a point: every stage's per-light loop asks this lookup instead
// of visiting every light of the scene (docs/units.md, "Light reach").
//   - A light with a range reaches its range (its light is zero at and beyond it).
//   - A point, spot or IES light without range reaches where its map value at normal incidence, I/(π d²), falls
//     to `fraction` × the scene's reference: the brighter of what the lights at infinity and the sky give a
//     surface facing them, and the median over the positional lights of what each gives at the distance of its
//     nearest neighbour light. Its light fades out smoothly over the last quarter of that reach (`Light::cutoff`),
//     so the cut draws no ring. A light whose reach covers the whole scene is never cut.
//   - Lights at infinity reach everywhere.
// A uniform grid over the scene holds, per cell, the lights whose reach sphere meets the cell, in index order.
#pragma once
#include <atomic>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

struct LightCullOptions {
  float fraction = 0.01f;  // a light without range is cut where its light falls to this share of the reference;
                           // 0: no culling (every stage visits every light, no light is cut)
};

// Each light's reach, settled once per bake.
struct LightReach {
  float reference = 0.0f;       // map value (E/π, W/m² / π) the cut is relative to; 0: none known, nothing cut
  float threshold = 0.0f;       // fraction × reference
  std::vector<float> reach;     // per light: the radius of its influence (infinity: everywhere)
  std::vector<uint8_t> cut;     // per light: 1 where the threshold set the reach (Light::cutoff fades it out)
  size_t cutLights() const;
};

// The largest radiant intensity of a positional light per unit of colour (W/sr): its intensity, times an IES
// profile's largest candela; ≥ 0. The reach weighs it by the colour's brightest channel, the light tail by its mean.
float peakIntensity(const Light& light);

// The reach of every light of `scene` whose geometry lies in `bounds`.
LightReach settleLightReach(const Scene& scene, const Bounds3& bounds, const LightCullOptions& options);

// Sets Light::cutoff of the lights the threshold cut (the fade every direct term applies).
void applyLightCutoffs(Scene& scene, const LightReach& reach);

// The lights of one lookup, in index order: `ids[0..count)`, or every light 0..count-1 when ids is null.
struct LightSpan {
  const uint32_t* ids = nullptr;
  uint32_t count = 0;
  struct Iterator {
    const uint32_t* ids;
    uint32_t k;
    uint32_t operator*() const { return ids ? ids[k] : k; }
    Iterator& operator++() { ++k; return *this; }
    bool operator!=(const Iterator& o) const { return k != o.k; }
  };
  Iterator begin() const { return {ids, 0}; }
  Iterator end() const { return {ids, count}; }
  uint32_t size() const { return count; }
};

// The lights' reach spheres in a uniform grid over `bounds`, built once per bake.
class LightGrid {
 public:
  // Every light in every cell (no culling).
  explicit LightGrid(size_t lights);
  LightGrid(const Scene& scene, const LightReach& reach, const Bounds3& bounds);

  // The lights whose reach may include x (every light for a point outside the grid's bounds).
  LightSpan near(const glm::vec3& x) const;
  // The lights whose reach sphere meets the box [lo, hi], in index order.
  std::vector<uint32_t> touching(const glm::vec3& lo, const glm::vec3& hi) const;
  // Whether light i's reach sphere meets the box [lo, hi].
  bool touches(size_t i, const glm::vec3& lo, const glm::vec3& hi) const;
  size_t lights() const { return all_.size(); }
  bool culls() const { return culls_; }
  // Lookups answered so far (near and touching).
  size_t lookups() const { return lookups_.load(std::memory_order_relaxed); }

 private:
  size_t cellOf(const glm::ivec3& c) const { return (size_t(c.z) * dims_.y + c.y) * dims_.x + c.x; }

  bool culls_ = false;
  glm::vec3 lo_{0.0f}, cell_{1.0f};
  glm::ivec3 dims_{1, 1, 1};
  std::vector<glm::vec4> spheres_;     // per light: centre, radius (infinity: everywhere)
  std::vector<uint32_t> all_;          // 0..n-1
  std::vector<uint32_t> offsets_;      // per cell: its first entry in ids_ (cells + 1)
  std::vector<uint32_t> ids_;
  mutable std::atomic<size_t> lookups_{0};
};

// Whether every light's reach covers all of `bounds` (then a grid culls nothing).
bool reachesEverywhere(const Scene& scene, const LightReach& reach, const Bounds3& bounds);

}  // namespace irbake
