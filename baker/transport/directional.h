// Directional light maps: the L1 spherical-harmonic part of the irradiance, stored so that the
// L0 page is exactly today's map. Formulas and sources: docs/units.md "Directional maps".
//
// Light arriving at x from direction ω with irradiance E (measured facing ω) gives, for a normal n,
//   E(n) = E · max(0, n·ω).
// Its SH projection up to band 1 (Ramamoorthi & Hanrahan 2001, Â0 = π, Â1 = 2π/3) is
//   E_SH(n) = E/4 + (E/2) n·ω,
// whose band-1 part is linear in n with the vector (E/2) ω. The sum over every source, g = Σ E_i ω_i, is the
// irradiance vector (Arvo 1994): twice the band-1 gradient. For every source above the horizon of n the
// clamped cosine is linear and E(n) = g·n exactly (E_SH's 1/4 + 1/2 slope is only a least-squares fit over
// the whole sphere). A surface texel only receives light from above its geometric normal n_g, so
//   map (L0)  = g·n_g / π                   (today's map: irradiance / π at n_g)
//   L1 pages  = t = (g − (g·n_g) n_g) / π   (the tangential part, world space, per colour channel)
// and the irradiance for any normal n (a normal map's) is reconstructed as
//   E(n) / π ≈ max(0, L0 · (n_g·n) + t·n)          (= max(0, g·n) / π)
// The error is only the clamp that a single linear term cannot show: sources below n's horizon,
//   |E_rec(n) − E(n)| ≤ Σ_i E_i · max(0, −ω_i·n) ≤ (Σ_i E_i) · |n − n_g|   (per channel, / π in map units),
// the L1 truncation bound tested in directional_test.cpp. A uniform sky over an open plane has t = 0.
//
// Storage: three pages per light-map page, L1x, L1y, L1z: page k holds, per texel, the k-th world
// component of t for R, G and B. L0 stays the map (`Lightmap`), untouched.
#pragma once
#include <array>

#include <glm/glm.hpp>

namespace irbake {

// t (or g) of one texel: axis k holds the k-th world component for R, G and B (the L1x/L1y/L1z pages).
using L1Vectors = std::array<glm::vec3, 3>;

// Adds one source to the irradiance vector g (in map units, / π): mapValue = E · (n_g·ω) / π, what the
// source adds to today's map at the geometric normal, cosReceiver = n_g·ω > 0, toSource = ω (unit).
inline void addIrradianceVector(L1Vectors& g, const glm::vec3& mapValue, const glm::vec3& toSource, float cosReceiver) {
  if (!(cosReceiver > 0.0f)) return;
  const glm::vec3 e = mapValue / cosReceiver;  // E / π facing the source
  for (int k = 0; k < 3; ++k) g[k] += e * toSource[k];
}

// The tangential part of g for the normal n (unit): what the L1 pages store.
inline L1Vectors tangentialPart(const L1Vectors& g, const glm::vec3& n) {
  L1Vectors t = g;
  for (int c = 0; c < 3; ++c) {
    const glm::vec3 v(g[0][c], g[1][c], g[2][c]);
    const glm::vec3 tc = v - glm::dot(v, n) * n;
    for (int k = 0; k < 3; ++k) t[k][c] = tc[k];
  }
  return t;
}

// The map value (irradiance / π, per channel) for a normal n from L0 (the map), the L1 pages t and the
// geometric normal ng the map was baked for: max(0, L0 (ng·n) + t·n). Never negative.
inline glm::vec3 reconstructDirectional(const glm::vec3& l0, const L1Vectors& t, const glm::vec3& ng,
                                        const glm::vec3& n) {
  const glm::vec3 linear = l0 * glm::dot(ng, n) + t[0] * n.x + t[1] * n.y + t[2] * n.z;
  return glm::max(linear, glm::vec3(0.0f));
}

// The same source's SH irradiance coefficients (band 0, band 1 in world xyz order (the real SH y, z, x order
// rearranged), for one channel: E_lm = Â_l · E · Y_lm(ω) with Â0 = π, Â1 = 2π/3. E_SH(n) = Σ E_lm Y_lm(n).
struct ShL1 {
  float l0 = 0.0f;
  glm::vec3 l1{0.0f};  // coefficients of Y_1(x), Y_1(y), Y_1(z)
};
inline ShL1 shIrradiance(float e, const glm::vec3& toSource) {
  constexpr float kPi = 3.14159265358979f;
  const float y0 = 0.282094792f, y1 = 0.488602512f;  // 1/(2√π), √(3/(4π))
  return {kPi * e * y0, (2.0f * kPi / 3.0f) * e * y1 * toSource};
}
inline float evalShIrradiance(const ShL1& sh, const glm::vec3& n) {
  const float y0 = 0.282094792f, y1 = 0.488602512f;
  return sh.l0 * y0 + y1 * glm::dot(sh.l1, n);
}

}  // namespace irbake
