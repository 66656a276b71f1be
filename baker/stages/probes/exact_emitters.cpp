#include "stages/probes/exact_emitters.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "sampling/sampling.h"

namespace irbake {
namespace {

constexpr uint64_t kEmitterVisibilityStream = 0x9f;  // the visibility samples' lattice rotations
constexpr double kGoldenRatio = 1.6180339887498949;

glm::vec3 vertex(const Primitive& prim, uint32_t t, int k) { return prim.positions[prim.indices[3 * t + k]]; }

// Planar (within 0.1% of the extent, all triangles on one side) or small (diagonal ≤ half a spacing).
bool planarOrSmall(const Primitive& prim, float spacing) {
  Bounds3 box;
  glm::vec3 normal(0.0f), anchor(0.0f);
  float largest = 0.0f;
  for (uint32_t t = 0; t < prim.triangleCount(); ++t) {
    const glm::vec3 a = vertex(prim, t, 0), n = glm::cross(vertex(prim, t, 1) - a, vertex(prim, t, 2) - a);
    for (int k = 0; k < 3; ++k) box.extend(vertex(prim, t, k));
    if (glm::length(n) > largest) largest = glm::length(n), normal = n / largest, anchor = a;
  }
  if (!box.valid() || !(largest > 0.0f)) return false;
  const float extent = box.diagonal();
  if (extent <= 0.5f * spacing) return true;
  for (uint32_t t = 0; t < prim.triangleCount(); ++t) {
    const glm::vec3 a = vertex(prim, t, 0), n = glm::cross(vertex(prim, t, 1) - a, vertex(prim, t, 2) - a);
    if (glm::dot(n, normal) < 0.0f) return false;
    for (int k = 0; k < 3; ++k)
      if (std::abs(glm::dot(vertex(prim, t, k) - anchor, normal)) > 1e-3f * extent) return false;
  }
  return true;
}

}  // namespace

ExactEmitters chooseExactEmitters(const Scene& scene, float spacing, int maxTriangles) {
  ExactEmitters out;
  out.exactPrimitive.assign(scene.primitives.size(), 0);
  struct Candidate {
    uint32_t primitive;
    double power;
  };
  std::vector<Candidate> candidates;
  for (uint32_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    if (prim.material < 0 || prim.material >= static_cast<int>(scene.materials.size())) continue;
    const Material& m = scene.materials[prim.material];
    if (!m.isEmissive() || m.emissiveTexture >= 0 || prim.triangleCount() == 0) continue;
    if (static_cast<int>(prim.triangleCount()) > maxTriangles || !planarOrSmall(prim, spacing)) continue;
    double area = 0.0;
    for (uint32_t t = 0; t < prim.triangleCount(); ++t)
      area += 0.5 * glm::length(glm::cross(vertex(prim, t, 1) - vertex(prim, t, 0), vertex(prim, t, 2) - vertex(prim, t, 0)));
    const glm::vec3 Le = m.emission();
    const double power = area * (Le.x + Le.y + Le.z) / 3.0;
    if (power > 0.0) candidates.push_back({p, power});
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.power > b.power; });
  int used = 0;
  for (const Candidate& c : candidates) {
    const Primitive& prim = scene.primitives[c.primitive];
    const int n = static_cast<int>(prim.triangleCount());
    if (used + n > maxTriangles) continue;
    used += n;
    ProbeEmitter e;
    for (uint32_t t = 0; t < prim.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) e.positions.push_back(vertex(prim, t, k));
    e.radiance = scene.materials[prim.material].emission() / static_cast<float>(kPi);
    out.emitters.push_back(std::move(e));
    out.primitives.push_back(c.primitive);
    out.exactPrimitive[c.primitive] = 1;
  }
  return out;
}

size_t bakeEmitterVisibility(const BakeInputs& in, const ExactEmitters& exact, int samples, uint32_t seed,
                             LightProbeGrid& grid) {
  grid.emitters = exact.emitters;
  const size_t n = grid.size();
  const RayTracer& rt = in.rayTracer;
  const int M = std::max(1, samples);
  std::atomic<size_t> traced{0};
  for (ProbeEmitter& e : grid.emitters) {
    e.visibility.assign(n, 0.0f);
    const size_t triangles = e.positions.size() / 3;
    std::vector<double> cumulative(triangles);
    for (size_t t = 0; t < triangles; ++t) {
      const glm::vec3* x = &e.positions[3 * t];
      cumulative[t] = (t ? cumulative[t - 1] : 0.0) + 0.5 * glm::length(glm::cross(x[1] - x[0], x[2] - x[0]));
    }
    const double total = triangles ? cumulative.back() : 0.0;
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      if (!grid.valid[i] || !(total > 0.0)) return;
      Rng rng(hashSeed(seed, kEmitterVisibilityStream, i));
      const double r1 = rng.uniform(), r2 = rng.uniform();
      const glm::vec3 p = grid.position(i);
      double seen = 0.0, all = 0.0;
      size_t count = 0;
      for (int j = 0; j < M; ++j) {
        double u = (j + 0.5) / M + r1, v = j / kGoldenRatio + r2;
        u = (u - std::floor(u)) * total, v -= std::floor(v);
        const size_t t = std::min<size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin(), triangles - 1);
        const double below = t ? cumulative[t - 1] : 0.0;
        const double residual = std::clamp((u - below) / std::max(cumulative[t] - below, 1e-30), 0.0, 1.0);
        const glm::vec3* x = &e.positions[3 * t];
        const glm::vec2 b = uniformTriangle(residual, v);
        const glm::vec3 y = x[0] * (1.0f - b.x - b.y) + x[1] * b.x + x[2] * b.y;
        const glm::vec3 front = glm::normalize(glm::cross(x[1] - x[0], x[2] - x[0]));
        const glm::vec3 d = y - p;
        const float r2 = glm::dot(d, d);
        if (!(r2 > 0.0f)) continue;
        const float r = std::sqrt(r2);
        const float cosY = -glm::dot(front, d / r);
        if (!(cosY > 0.0f)) continue;
        const double w = cosY / r2;
        all += w;
        ++count;
        const float tmax = r - 2.0f * rt.epsilon();
        if (tmax > 0.0f && rt.occluded(p, d / r, 0.0f, tmax)) continue;
        double pass = 1.0;
        if (rt.hasTransmission() && tmax > 0.0f) {
          const glm::vec3 c = rt.transmittance(p, d / r, 0.0f, tmax);
          pass = (c.x + c.y + c.z) / 3.0;
        }
        seen += w * pass;
      }
      const double share = all > 0.0 ? seen / all : 1.0;
      e.visibility[i] = static_cast<float>(std::round(std::clamp(share, 0.0, 1.0) * 255.0) / 255.0);
      traced += count;
    });
  }
  return traced;
}

}  // namespace irbake
