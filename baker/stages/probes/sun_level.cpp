#include "stages/probes/sun_level.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "stages/probes/light_visibility_fit.h"
#include "transport/geometry_term.h"

namespace irbake {
namespace {

// The lattice over the whole grid: S(n − 1) + 1 points per axis (1 along a one-probe axis), point (x, y, z)
// at origin + spacing (x, y, z) / S.
struct FineLattice {
  glm::ivec3 dims{1};
  int S = 1;
  size_t size() const { return static_cast<size_t>(dims.x) * dims.y * dims.z; }
  size_t index(int x, int y, int z) const {
    return static_cast<size_t>(x) + static_cast<size_t>(dims.x) * (static_cast<size_t>(y) + static_cast<size_t>(dims.y) * z);
  }
};

// The blend of the probes' visibilities at the lattice point `t` (cell fraction) of the cell at `base`: valid
// probes only, weights renormalised, as the clients blend; -1 when no corner is valid.
float blendVisibility(const LightProbeGrid& g, const std::vector<float>& v, const glm::ivec3& base, const glm::vec3& t) {
  float sum = 0.0f, weight = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const glm::ivec3 d(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const glm::ivec3 q = base + d;
    if (q.x >= g.counts.x || q.y >= g.counts.y || q.z >= g.counts.z) continue;
    float w = 1.0f;
    for (int a = 0; a < 3; ++a) w *= d[a] ? t[a] : 1.0f - t[a];
    const size_t idx = g.index(q.x, q.y, q.z);
    if (!(w > 0.0f) || !g.valid[idx]) continue;
    sum += w * v[idx];
    weight += w;
  }
  return weight > 0.0f ? sum / weight : -1.0f;
}

}  // namespace

int strongestDirectionalLight(const std::vector<Light>& lights) {
  int best = -1;
  double strongest = 0.0;
  for (size_t l = 0; l < lights.size(); ++l) {
    if (lights[l].type != LightType::Directional || !(glm::dot(lights[l].direction, lights[l].direction) > 0.0f)) continue;
    const glm::vec3 toward = -glm::normalize(lights[l].direction);
    const double e = channelMean(punctualDirect(lights[l], glm::vec3(0.0f), toward).mapValue);
    if (e > strongest) strongest = e, best = static_cast<int>(l);
  }
  return best;
}

ProbeSunLevel bakeSunLevel(const BakeInputs& in, const LightProbeGrid& g, size_t light, const std::vector<float>& visibility,
                           const SunLevelOptions& options, SunLevelStats* stats) {
  ProbeSunLevel out;
  const int S = options.subdivisions;
  if (S <= 0 || light >= in.scene.lights.size() || visibility.size() != g.size()) return out;
  const Light& sun = in.scene.lights[light];
  const glm::vec3 toward = -glm::normalize(sun.direction);
  out.direction = -toward;
  out.subdivisions = S;
  out.visibility = visibility;
  const PunctualContribution c = punctualDirect(sun, glm::vec3(0.0f), toward);
  shAddDirectional(out.sh, toward, c.mapValue);

  FineLattice lattice;
  lattice.S = S;
  for (int a = 0; a < 3; ++a) lattice.dims[a] = g.counts[a] > 1 ? S * (g.counts[a] - 1) + 1 : 1;
  std::vector<uint8_t> lit(lattice.size(), 0);
  tbb::parallel_for(size_t(0), lattice.size(), [&](size_t i) {
    const glm::vec3 q(static_cast<float>(i % lattice.dims.x), static_cast<float>(i / lattice.dims.x % lattice.dims.y),
                      static_cast<float>(i / (static_cast<size_t>(lattice.dims.x) * lattice.dims.y)));
    lit[i] = punctualVisibility(in, sun, g.origin + g.spacing * q / static_cast<float>(S)) >= 0.5f;
  });

  const glm::ivec3 cellCounts = glm::max(g.counts - 1, glm::ivec3(1));
  const size_t cellTotal = static_cast<size_t>(cellCounts.x) * cellCounts.y * cellCounts.z;
  std::vector<uint8_t> refine(cellTotal, 0);
  tbb::parallel_for(size_t(0), cellTotal, [&](size_t c) {
    const glm::ivec3 base(static_cast<int>(c % cellCounts.x), static_cast<int>(c / cellCounts.x % cellCounts.y),
                          static_cast<int>(c / (static_cast<size_t>(cellCounts.x) * cellCounts.y)));
    for (int d = 0; d <= S; ++d)
      for (int b = 0; b <= S; ++b)
        for (int a = 0; a <= S; ++a) {
          const glm::ivec3 o(a, b, d);
          glm::vec3 t;
          glm::ivec3 q;
          for (int k = 0; k < 3; ++k) {
            t[k] = g.counts[k] > 1 ? static_cast<float>(o[k]) / S : 0.0f;
            q[k] = g.counts[k] > 1 ? base[k] * S + o[k] : 0;
          }
          const float blend = blendVisibility(g, visibility, base, t);
          if (blend < 0.0f) return;  // no valid probe: nothing a client would correct
          if (std::abs(static_cast<float>(lit[lattice.index(q.x, q.y, q.z)]) - blend) > options.tolerance) refine[c] = 1;
        }
  });

  const int W = out.wordsPerCell(), s1 = S + 1;
  for (size_t c = 0; c < cellTotal; ++c) {
    if (!refine[c]) continue;
    const glm::ivec3 base(static_cast<int>(c % cellCounts.x), static_cast<int>(c / cellCounts.x % cellCounts.y),
                          static_cast<int>(c / (static_cast<size_t>(cellCounts.x) * cellCounts.y)));
    out.cells.push_back(static_cast<uint32_t>(g.index(base.x, base.y, base.z)));
    out.fine.resize(out.fine.size() + W, 0u);
    uint32_t* words = &out.fine[out.fine.size() - W];
    for (int d = 0; d <= S; ++d)
      for (int b = 0; b <= S; ++b)
        for (int a = 0; a <= S; ++a) {
          const glm::ivec3 o(a, b, d);
          glm::ivec3 q;
          for (int k = 0; k < 3; ++k) q[k] = g.counts[k] > 1 ? base[k] * S + o[k] : 0;
          const int n = a + s1 * (b + s1 * d);
          if (lit[lattice.index(q.x, q.y, q.z)]) words[n / 32] |= 1u << (n % 32);
        }
  }
  if (stats) {
    stats->cells = out.cells.size();
    stats->rays = lattice.size();
  }
  return out;
}

}  // namespace irbake
