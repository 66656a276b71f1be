// Irradiance probes on a regular grid: each probe holds the light arriving at a point as L2 spherical
// harmonics (9 RGB coefficients), in the map's units, in three.js's SphericalHarmonics3 / LightProbe convention
// (docs/export.md, "IRBAKE_light_probes"):
//   c_k = (1/π) ∫ L(ω) Y_k(ω) dω,  k = 0..8, world axes of the glTF (+Y up), Y_k three.js's real basis
//   Y_0 = 0.282095; Y_1..3 = 0.488603 (y, z, x); Y_4 = 1.092548 xy, Y_5 = 1.092548 yz,
//   Y_6 = 0.315392 (3z² − 1), Y_7 = 1.092548 xz, Y_8 = 0.546274 (x² − y²)
// so that SphericalHarmonics3.getIrradianceAt(n) (the shader's shGetIrradianceAt: Σ Â_l c_k Y_k(n), Â = π,
// 2π/3, π/4) gives E(n)/π: the value a light-map texel facing n would hold there.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "lightmap/probe_emitters.h"

namespace irbake {

constexpr int kShCoefficients = 9;
// The smallest spacing a bake writes (--probes, the automatic spacing's floor) and a reader accepts.
constexpr float kMinProbeSpacing = 0.01f;
using ShCoefficients = std::array<glm::vec3, kShCoefficients>;

// three.js's real SH basis at unit direction d.
inline std::array<float, kShCoefficients> shBasis(const glm::vec3& d) {
  const float x = d.x, y = d.y, z = d.z;
  return {0.282095f,          0.488603f * y,      0.488603f * z,
          0.488603f * x,      1.092548f * x * y,  1.092548f * y * z,
          0.315392f * (3.0f * z * z - 1.0f),      1.092548f * x * z, 0.546274f * (x * x - y * y)};
}

// Σ Â_l c_k Y_k(n) as three.js's getIrradianceAt writes it: E(n)/π for coefficients in map units.
inline glm::vec3 shIrradiance(const ShCoefficients& c, const glm::vec3& n) {
  const float x = n.x, y = n.y, z = n.z;
  glm::vec3 r = c[0] * 0.886227f;
  r += c[1] * (2.0f * 0.511664f * y) + c[2] * (2.0f * 0.511664f * z) + c[3] * (2.0f * 0.511664f * x);
  r += c[4] * (2.0f * 0.429043f * x * y) + c[5] * (2.0f * 0.429043f * y * z);
  r += c[6] * (0.743125f * z * z - 0.247708f) + c[7] * (2.0f * 0.429043f * x * z);
  r += c[8] * (0.429043f * (x * x - y * y));
  return r;
}

// The mean of E(n)/π over every direction n: the L0 term alone (0.886227 · c_0).
inline glm::vec3 shAverage(const ShCoefficients& c) { return c[0] * 0.886227f; }

// Adds a light of map value `value` (E/π at normal incidence) from direction d: c_k += value · Y_k(d).
inline void shAddDirectional(ShCoefficients& c, const glm::vec3& d, const glm::vec3& value) {
  const auto y = shBasis(d);
  for (int k = 0; k < kShCoefficients; ++k) c[k] += value * y[k];
}

// The strongest directional light's visibility on a finer lattice in the cells its shadow crosses (docs/export.md,
// "IRBAKE_light_probes", `sun`). A blend of probes a spacing apart smears a sun's shadow edge over the cell; a
// point p of a refined cell instead takes its probes' blend plus (v_fine(p) − Σ w_i v_i) · sh: v_fine the
// trilinear interpolation of the cell's (S+1)³ lattice of binary visibilities, v_i the visibility probe i's
// coefficients carry, w_i the blend's own weights.
struct ProbeSunLevel {
  glm::vec3 direction{0.0f};      // the light's travel direction (world, unit)
  glm::vec3 irradiance{0.0f};     // its map value (E/π facing it) at visibility 1: the clients shade it exactly
  ShCoefficients sh{};            // its SH at visibility 1, map units (what a probe that fully sees it got)
  std::vector<float> visibility;  // per probe: the visibility its coefficients carry, in [0, 1]
  std::vector<uint32_t> cells;    // refined cells, ascending: the linear index i + nx (j + ny k) of the base probe
  int subdivisions = 0;           // S per axis (0: no sun level)
  std::vector<uint32_t> fine;     // bits: cell c's point (a, b, d), 0..S each, is bit a + (S+1)(b + (S+1) d) of
                                  // the words [c W, (c + 1) W), W = wordsPerCell(), bit n of a word = 1 << n

  bool present() const { return subdivisions > 0; }
  int pointsPerCell() const { return (subdivisions + 1) * (subdivisions + 1) * (subdivisions + 1); }
  int wordsPerCell() const { return (pointsPerCell() + 31) / 32; }
  bool bit(size_t cell, int a, int b, int d) const {
    const int s1 = subdivisions + 1, n = a + s1 * (b + s1 * d);
    return (fine[cell * wordsPerCell() + n / 32] >> (n % 32)) & 1u;
  }
  // v_fine at the cell-local fraction t ∈ [0, 1]³ of the cell whose base probe is `base`; -1 when that cell
  // is not refined.
  float fineVisibility(size_t base, const glm::vec3& t) const {
    if (!present()) return -1.0f;
    const auto it = std::lower_bound(cells.begin(), cells.end(), static_cast<uint32_t>(base));
    if (it == cells.end() || *it != base) return -1.0f;
    const size_t cell = static_cast<size_t>(it - cells.begin());
    const float S = static_cast<float>(subdivisions);
    glm::ivec3 lo;
    glm::vec3 f;
    for (int a = 0; a < 3; ++a) {
      const float x = std::clamp(t[a], 0.0f, 1.0f) * S;
      lo[a] = std::min(static_cast<int>(std::floor(x)), subdivisions - 1);
      f[a] = x - static_cast<float>(lo[a]);
    }
    float v = 0.0f;
    for (int k = 0; k < 8; ++k) {
      const glm::ivec3 d(k & 1, (k >> 1) & 1, (k >> 2) & 1);
      float w = 1.0f;
      for (int a = 0; a < 3; ++a) w *= d[a] ? f[a] : 1.0f - f[a];
      if (w > 0.0f && bit(cell, lo.x + d.x, lo.y + d.y, lo.z + d.z)) v += w;
    }
    return v;
  }
};

struct LightProbeGrid {
  glm::vec3 origin{0.0f};        // position of probe (0, 0, 0), metres, world space
  float spacing = 0.0f;          // between neighbours along each axis
  glm::ivec3 counts{0};          // probes along x, y, z; probe (i, j, k) is index i + nx (j + ny k)
  std::vector<ShCoefficients> coefficients;  // one per probe (map units: see above)
  std::vector<glm::vec3> offsets;            // where each probe was baked, relative to its grid point
  std::vector<uint8_t> valid;                // 0: inside geometry or behind a wall, left out of interpolation
  ProbeSunLevel sun;                         // optional: the sun's visibility refined where its shadow crosses
  std::vector<ProbeEmitter> emitters;        // optional: emitters shaded exactly, not in the coefficients

  size_t size() const { return static_cast<size_t>(counts.x) * counts.y * counts.z; }
  size_t index(int i, int j, int k) const {
    return static_cast<size_t>(i) + static_cast<size_t>(counts.x) * (static_cast<size_t>(j) + static_cast<size_t>(counts.y) * k);
  }
  glm::ivec3 cell(size_t index) const {  // (i, j, k) of a probe index
    return glm::ivec3(static_cast<int>(index % counts.x), static_cast<int>(index / counts.x % counts.y),
                      static_cast<int>(index / (static_cast<size_t>(counts.x) * counts.y)));
  }
  glm::vec3 gridPoint(int i, int j, int k) const { return origin + spacing * glm::vec3(i, j, k); }
  glm::vec3 position(size_t index) const {
    const glm::ivec3 c = cell(index);
    return gridPoint(c.x, c.y, c.z) + (index < offsets.size() ? offsets[index] : glm::vec3(0.0f));
  }
};

// What interpolation found at a point: the blended coefficients and the weight they carried.
struct ProbeBlend {
  ShCoefficients coefficients{};
  int probes = 0;       // valid, visible probes blended
  float weight = 0.0f;  // their summed trilinear weight (0: none; coefficients then 0)
  float sunVisibility = 0.0f;  // the sun level's visibility v(p) the coefficients carry (0 without a sun level)
  std::array<std::pair<size_t, float>, 8> corners{};  // the blended probes and their weights (renormalised)
};

// The trilinear blend's probes around p (the cell clamped to the grid): corner(index, weight) for each of
// the 8 with a positive weight, a one-probe axis's single layer once. Returns the cell's base corner; `fraction`,
// when given, receives p's position in the cell (0..1 per axis, 0 along a one-probe axis).
template <class Corner>
glm::ivec3 forEachBlendCorner(const LightProbeGrid& g, const glm::vec3& p, Corner&& corner, glm::vec3* fraction = nullptr) {
  const glm::vec3 f = (p - g.origin) / g.spacing;
  glm::ivec3 base;
  glm::vec3 t;
  for (int a = 0; a < 3; ++a) {
    const float hi = static_cast<float>(g.counts[a] - 1);
    const float c = std::clamp(f[a], 0.0f, hi);
    base[a] = std::min(static_cast<int>(std::floor(c)), std::max(0, g.counts[a] - 2));
    t[a] = g.counts[a] > 1 ? c - static_cast<float>(base[a]) : 0.0f;
  }
  if (fraction) *fraction = t;
  for (int k = 0; k < 8; ++k) {
    const glm::ivec3 d(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const glm::ivec3 q = glm::min(base + d, g.counts - 1);
    if (glm::any(glm::notEqual(base + d, q))) continue;
    float w = 1.0f;
    for (int a = 0; a < 3; ++a) w *= d[a] ? t[a] : 1.0f - t[a];
    if (w > 0.0f) corner(g.index(q.x, q.y, q.z), w);
  }
  return base;
}

// Trilinear over the 8 probes around p (clamped to the grid), each weighted by its validity and, when
// `visible` is given, by whether p sees the probe's baked position (a wall between them: weight 0, so light
// never crosses it). Where none of the 8 counts, the nearest valid visible probe of the 4×4×4 around p. In a
// cell of the sun level, the blend's sun is replaced by the fine lattice's (ProbeSunLevel); `sunVisibility` is
// then the lattice's, elsewhere the blend of the probes' (or the nearest probe's).
inline ProbeBlend interpolateProbes(const LightProbeGrid& g, const glm::vec3& p,
                                    const std::function<bool(const glm::vec3&, const glm::vec3&)>& visible = {}) {
  ProbeBlend out;
  if (g.size() == 0 || !(g.spacing > 0.0f)) return out;
  auto use = [&](size_t idx) { return g.valid[idx] && (!visible || visible(p, g.position(idx))); };
  const bool sun = g.sun.present() && g.sun.visibility.size() == g.size();
  float sunBlend = 0.0f;
  glm::vec3 t(0.0f);
  const glm::ivec3 base = forEachBlendCorner(g, p, [&](size_t idx, float w) {
    if (!use(idx)) return;
    for (int k = 0; k < kShCoefficients; ++k) out.coefficients[k] += w * g.coefficients[idx][k];
    if (sun) sunBlend += w * g.sun.visibility[idx];
    out.weight += w;
    out.corners[out.probes++] = {idx, w};
  }, &t);
  if (out.weight > 0.0f) {
    for (auto& c : out.coefficients) c /= out.weight;
    for (int c = 0; c < out.probes; ++c) out.corners[c].second /= out.weight;
    const float fine = sun ? g.sun.fineVisibility(g.index(base.x, base.y, base.z), t) : -1.0f;
    if (fine >= 0.0f)
      for (int k = 0; k < kShCoefficients; ++k) out.coefficients[k] += (fine - sunBlend / out.weight) * g.sun.sh[k];
    if (sun) out.sunVisibility = fine >= 0.0f ? fine : sunBlend / out.weight;
    return out;
  }
  float best = 1e30f;
  size_t nearest = g.size();
  for (int k = base.z - 1; k <= base.z + 2; ++k)
    for (int j = base.y - 1; j <= base.y + 2; ++j)
      for (int i = base.x - 1; i <= base.x + 2; ++i) {
        if (i < 0 || j < 0 || k < 0 || i >= g.counts.x || j >= g.counts.y || k >= g.counts.z) continue;
        const size_t idx = g.index(i, j, k);
        const glm::vec3 d = g.position(idx) - p;
        if (glm::dot(d, d) < best && use(idx)) best = glm::dot(d, d), nearest = idx;
      }
  if (nearest == g.size()) return out;
  out.coefficients = g.coefficients[nearest];
  out.corners[0] = {nearest, 1.0f};
  out.probes = 1;
  out.weight = 1.0f;
  if (sun) out.sunVisibility = g.sun.visibility[nearest];
  return out;
}

// What a white Lambert surface with unit normal n shows (E(n)/π) under coefficients c that carry the sun level's
// light at visibility v: the rest of the light through L2, clamped at 0 against its ringing, plus the sun as an
// exact clamped cosine, v · irradiance · max(0, n·(−direction)). L2 alone rings on a delta: facing the sun it
// reads 17/16 of it, at 90° from it 3/32 of it. Without a sun level: max(0, shIrradiance(c, n)). `clampSh` false
// leaves the L2 term unclamped (`irbake probe`, whose values the bench fits).
inline glm::vec3 shadeProbeLambert(const ShCoefficients& c, float v, const ProbeSunLevel& sun, const glm::vec3& n,
                                   bool clampSh = true) {
  auto clamped = [&](const glm::vec3& e) { return clampSh ? glm::max(e, glm::vec3(0.0f)) : e; };
  if (!sun.present()) return clamped(shIrradiance(c, n));
  ShCoefficients rest = c;
  for (int k = 0; k < kShCoefficients; ++k) rest[k] -= v * sun.sh[k];
  return clamped(shIrradiance(rest, n)) + v * sun.irradiance * std::max(0.0f, -glm::dot(n, sun.direction));
}

}  // namespace irbake
