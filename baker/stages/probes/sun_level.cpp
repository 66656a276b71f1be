#include "stages/probes/sun_level.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "lights/light_kind.h"
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

// The blend of the probes' visibilities at p exactly as the clients blend (valid probes only, weights
// renormalised); -1 when no corner is valid.
float blendVisibility(const LightProbeGrid& g, const std::vector<float>& v, const glm::vec3& p) {
  float sum = 0.0f, weight = 0.0f;
  forEachBlendCorner(g, p, [&](size_t idx, float w) {
    if (!g.valid[idx]) return;
    sum += w * v[idx];
    weight += w;
  });
  return weight > 0.0f ? sum / weight : -1.0f;
}

// Whether probe `base` is a cell's base corner: not the last along an axis of more than one probe.
bool isCellBase(const LightProbeGrid& g, const glm::ivec3& base) {
  for (int a = 0; a < 3; ++a)
    if (g.counts[a] > 1 && base[a] >= g.counts[a] - 1) return false;
  return true;
}

}  // namespace

int strongestDirectionalLight(const std::vector<Light>& lights) {
  int best = -1;
  double strongest = 0.0;
  for (size_t l = 0; l < lights.size(); ++l) {
    if (!lightKind(lights[l].type).atInfinity() || !(glm::dot(lights[l].direction, lights[l].direction) > 0.0f))
      continue;
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
  out.irradiance = c.mapValue;
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

  // Lattice point o (0..S per axis) of the cell whose base probe is `base`, in the whole grid's lattice.
  auto latticeIndex = [&](const glm::ivec3& base, const glm::ivec3& o) {
    glm::ivec3 q;
    for (int k = 0; k < 3; ++k) q[k] = g.counts[k] > 1 ? base[k] * S + o[k] : 0;
    return lattice.index(q.x, q.y, q.z);
  };
  // Refined cells, marked at their base probe (so ascending order is the probes' order).
  std::vector<uint8_t> refine(g.size(), 0);
  tbb::parallel_for(size_t(0), g.size(), [&](size_t c) {
    const glm::ivec3 base = g.cell(c);
    if (!isCellBase(g, base)) return;
    for (int d = 0; d <= S; ++d)
      for (int b = 0; b <= S; ++b)
        for (int a = 0; a <= S; ++a) {
          const glm::ivec3 o(a, b, d);
          const glm::vec3 p = g.gridPoint(base.x, base.y, base.z) + g.spacing * glm::vec3(o) / static_cast<float>(S);
          const float blend = blendVisibility(g, visibility, p);
          if (blend < 0.0f) return;  // no valid probe: nothing a client would correct
          if (std::abs(static_cast<float>(lit[latticeIndex(base, o)]) - blend) > options.tolerance) refine[c] = 1;
        }
  });

  const int W = out.wordsPerCell(), s1 = S + 1;
  for (size_t c = 0; c < g.size(); ++c) {
    if (!refine[c]) continue;
    const glm::ivec3 base = g.cell(c);
    out.cells.push_back(static_cast<uint32_t>(c));
    out.fine.resize(out.fine.size() + W, 0u);
    uint32_t* words = &out.fine[out.fine.size() - W];
    for (int d = 0; d <= S; ++d)
      for (int b = 0; b <= S; ++b)
        for (int a = 0; a <= S; ++a) {
          const int n = a + s1 * (b + s1 * d);
          if (lit[latticeIndex(base, glm::ivec3(a, b, d))]) words[n / 32] |= 1u << (n % 32);
        }
  }
  if (stats) {
    stats->cells = out.cells.size();
    stats->rays = lattice.size();
  }
  return out;
}

}  // namespace irbake
