// The maths both VPL backends evaluate identically (Embree here, GLSL in shaders/ for the GL backend).
// Keep these formulas small: they are ported line by line.
//
// Convention: a lightmap texel stores irradiance / π (DEVELOPERS.md), so a white Lambertian surface
// shows exactly the stored value.
//
// VPL (cosine emitter of power Φ at y, normal n_y) at a receiver x with normal n_x, ω = (y − x) / r:
//   G(x, y)   = max(0, n_x·ω) · max(0, −n_y·ω) / r²                        [1/m²]
//   Gc        = min(G, B)            (B = clamp bound; B = 0 means no clamp)
//   E         = Φ / π · Gc · V(x, y)                                         [W/m²]
//   map value = E / π = Φ · Gc · V / π²
//
// Punctual lights (exact; no VPL at bounce 0), d = light position − x, r = |d|, l = d / r:
//   point/spot:   E = I(−l) · max(0, n_x·l) / r² · window(r) · V   (I(−l): the kind's intensityToward, spot falloff)
//   directional:  E = I · max(0, −n_x·dir) · V                     (shadow ray towards −dir, to infinity)
//   map value = E / π
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "common/maths.h"
#include "lights/light_kind.h"
#include "scene/scene.h"
#include "vpl/vpl.h"

namespace irbake {

// Unclamped geometry term G between a receiver (x, nx) and a VPL (y, ny); 0 when either faces away.
inline float vplGeometryTerm(const glm::vec3& x, const glm::vec3& nx, const glm::vec3& y, const glm::vec3& ny) {
  glm::vec3 d = y - x;
  float r2 = glm::dot(d, d);
  if (!(r2 > 0.0f)) return 0.0f;
  float invR = 1.0f / std::sqrt(r2);
  float cosX = glm::dot(nx, d) * invR, cosY = -glm::dot(ny, d) * invR;
  if (cosX <= 0.0f || cosY <= 0.0f) return 0.0f;
  return cosX * cosY / r2;
}

// min(G, bound); bound 0 = no clamp.
inline float clampGeometryTerm(float g, float bound) { return bound > 0.0f ? glm::min(g, bound) : g; }

// Map value (irradiance / π) that a visible VPL of power Φ gives through the (clamped) geometry term.
inline glm::vec3 vplMapValue(const glm::vec3& power, float geometryTerm) { return power * (geometryTerm * kInvPi2F); }

// A punctual light at a receiver, before the shadow test: its kind's direct term (lights/light_kind.h).
PunctualContribution punctualDirect(const Light& light, const glm::vec3& x, const glm::vec3& nx);

// How far the shadow ray toward c's light runs from ε off the receiver (at most 0: the light is that close; a
// light at infinity: 1e30).
inline float shadowRayLength(const PunctualContribution& c, float eps) {
  return std::isinf(c.distance) ? 1e30f : c.distance - eps;
}

// The clamp bound B (1/m²) derived from the scene and the VPL set:
//   B = π · N / (k · A),  N = VPLs with non-zero power, A = total one-sided surface area, k = 16.
// Why: each VPL stands for the light of A/N of the surface, so the mean irradiance the set represents is
// about N Φ_v / A, while one VPL at distance r (both cosines 1) gives Φ_v / (π r²) and clamped at most
// Φ_v B / π = (1/k) · Φ_v N / A. So no single VPL adds more than 1/k of that mean: a texel's value rests
// on at least ~k VPLs, which keeps splotches below the noise. Equivalently the clamp radius is
// r_c = sqrt(k A / (π N)) ≈ 2.3 VPL spacings. The energy removed inside r_c (corners, contacts) is what
// bias compensation recovers. Returns 0 (no clamp) without VPLs.
constexpr double kClampVplsPerMean = 16.0;  // k above
float deriveClampBound(const Scene& scene, const VplSet& vpls, double vplsPerMean = kClampVplsPerMean);
// The same bound for N = vplCount (0: no clamp): a count settled apart from the VPLs evaluated.
float clampBoundForCount(const Scene& scene, double vplCount, double vplsPerMean = kClampVplsPerMean);
// The VPLs with non-zero power: the N of deriveClampBound.
size_t litVplCount(const VplSet& vpls);

}  // namespace irbake
