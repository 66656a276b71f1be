// The ray pilot: the same count of gather-like rays in the scene and in the reference scene, alternately timed.
#include "pipeline/ray_pilot.h"

#include <time.h>

#include <algorithm>
#include <limits>
#include <vector>

#include "raytrace/ray_tracer.h"
#include "sampling/sampling.h"
#include "scene/triangle_area.h"

namespace irbake {

namespace {

// This thread's CPU seconds: the rays are traced on this thread, so the machine's other work does not count.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Ray origins (offset off the surface) and their front normals: triangles area-weighted over the mapped ones,
// pointsPerTriangle points on each, traced one after the other as neighbouring texels are, so that their rays
// find the BVH's nodes in cache as the bake's rays do.
struct PilotPoints {
  std::vector<glm::vec3> origins, normals;
};

PilotPoints pilotPoints(const Scene& scene, const RayTracer& rt, const RayPilotOptions& o) {
  std::vector<double> cdf;
  std::vector<std::pair<uint32_t, uint32_t>> triangles;  // (primitive, triangle) of each cdf step
  double total = 0.0;
  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    if (!prim.getsLightmap()) continue;
    for (size_t t = 0; t < prim.triangleCount(); ++t) {
      const double a = triangleArea(prim, t);
      if (!(a > 0.0)) continue;
      total += a;
      cdf.push_back(total);
      triangles.emplace_back(uint32_t(p), uint32_t(t));
    }
  }
  PilotPoints points;
  if (cdf.empty()) return points;
  Rng rng(hashSeed(o.seed, 0x7069));
  size_t k = 0;
  for (int i = 0; i < o.points; ++i) {
    if (i % std::max(1, o.pointsPerTriangle) == 0)
      k = std::min(cdf.size() - 1, size_t(std::upper_bound(cdf.begin(), cdf.end(), rng.uniform() * total) - cdf.begin()));
    const auto [p, t] = triangles[k];
    const Primitive& prim = scene.primitives[p];
    const glm::vec3 a = prim.positions[prim.indices[3 * t]], b = prim.positions[prim.indices[3 * t + 1]],
                    c = prim.positions[prim.indices[3 * t + 2]];
    const glm::vec2 w = uniformTriangle(rng.uniform(), rng.uniform());
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    points.origins.push_back(rt.spawnPoint(p, t, a + w.x * (b - a) + w.y * (c - a), n));
    points.normals.push_back(n);
  }
  return points;
}

struct Round {
  double seconds = 0.0;
  long rays = 0, hits = 0;
};

// One round: raysPerPoint cosine rays from each point, 8 to a packet, as the final gather traces them.
Round traceRound(const RayTracer& rt, const PilotPoints& points, const RayPilotOptions& o) {
  Rng rng(hashSeed(o.seed, 0x7261));
  std::vector<glm::vec3> dirs(size_t(std::max(1, o.raysPerPoint)));
  std::vector<RayHit> hits(dirs.size());
  Round r;
  const double start = threadCpuSeconds();
  for (size_t i = 0; i < points.origins.size(); ++i) {
    CosineLattice lattice(points.normals[i], int(dirs.size()), rng.uniform(), rng.uniform());
    for (glm::vec3& d : dirs) d = lattice.next();
    rt.intersectPackets(points.origins[i], dirs.data(), dirs.size(), hits.data(), RayTracer::HitDetail::Surface,
                        RayTracer::Traversal::Fast);
    for (const RayHit& h : hits) r.hits += h.hit;
    r.rays += long(dirs.size());
  }
  r.seconds = threadCpuSeconds() - start;
  return r;
}

}  // namespace

double rayCostScale(double secondsPerRay, double referenceSecondsPerRay) {
  if (!(secondsPerRay > 0.0) || !(referenceSecondsPerRay > 0.0)) return 1.0;
  return secondsPerRay / referenceSecondsPerRay;
}

Scene rayPilotReferenceScene() {
  Scene s;
  s.materials.emplace_back();
  // A quad split into div x div pairs of triangles, counter-clockwise about e1 x e2.
  const auto quad = [&](glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int div) {
    Primitive p;
    const glm::vec3 n = glm::normalize(glm::cross(e1, e2));
    for (int j = 0; j <= div; ++j)
      for (int i = 0; i <= div; ++i) {
        p.positions.push_back(p0 + e1 * (float(i) / float(div)) + e2 * (float(j) / float(div)));
        p.normals.push_back(n);
      }
    for (int j = 0; j < div; ++j)
      for (int i = 0; i < div; ++i) {
        const uint32_t a = uint32_t(j * (div + 1) + i), b = a + 1, c = a + uint32_t(div) + 2, d = a + uint32_t(div) + 1;
        p.indices.insert(p.indices.end(), {a, b, c, a, c, d});
      }
    s.primitives.push_back(std::move(p));
  };
  quad(glm::vec3(-20, 0, -20), glm::vec3(0, 0, 40), glm::vec3(40, 0, 0), 1);
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 8; ++k) {
      const float h = 4.0f + float((i * 5 + k * 3) % 7) * 2.0f;  // 4 to 16 m
      const glm::vec3 lo(-18.5f + 5.0f * float(i), 0.0f, -18.5f + 5.0f * float(k)), X(3, 0, 0), Y(0, h, 0), Z(0, 0, 3);
      for (const auto& [p0, e1, e2] : {std::tuple{lo, Y, X}, {lo + Z, X, Y}, {lo, X, Z}, {lo + Y, Z, X}, {lo, Z, Y}, {lo + X, Y, Z}})
        quad(p0, e1, e2, 4);
    }
  return s;
}

RayPilot measureRayPilot(const Scene& scene, const RayTracer& rt, const RayPilotOptions& options) {
  RayPilot pilot;
  const PilotPoints points = pilotPoints(scene, rt, options);
  if (points.origins.empty()) return pilot;
  const Scene reference = rayPilotReferenceScene();
  const RayTracer referenceRt(reference);
  const PilotPoints referencePoints = pilotPoints(reference, referenceRt, options);
  // Each round pairs the scene's rays with the reference's, traced one after the other, so that what the
  // machine's load does to both cancels in their ratio; the median ratio over the rounds counts.
  double best = std::numeric_limits<double>::infinity(), referenceBest = best;
  std::vector<double> ratios;
  for (int round = 0; round < std::max(1, options.rounds); ++round) {
    const Round r = traceRound(rt, points, options), ref = traceRound(referenceRt, referencePoints, options);
    best = std::min(best, r.seconds / double(r.rays));
    referenceBest = std::min(referenceBest, ref.seconds / double(ref.rays));
    ratios.push_back(rayCostScale(r.seconds / double(r.rays), ref.seconds / double(ref.rays)));
    pilot.rays = r.rays;
    pilot.hitFraction = double(r.hits) / double(r.rays);
  }
  std::nth_element(ratios.begin(), ratios.begin() + ptrdiff_t(ratios.size() / 2), ratios.end());
  pilot.secondsPerRay = best;
  pilot.referenceSecondsPerRay = referenceBest;
  pilot.rayCost = ratios[ratios.size() / 2];
  return pilot;
}

}  // namespace irbake
