#include "stages/probes/light_probes.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/error.h"
#include "common/progress.h"
#include "sampling/sampling.h"
#include "transport/geometry_term.h"

namespace irbake {
namespace {

constexpr uint64_t kProbeStream = 0x9b;  // the probes' lattice rotations
constexpr double kGoldenRatio = 1.6180339887498949;
constexpr double kAutoProbes = 1024.0;   // about this many probes at the automatic spacing, whatever the scale

// What one probe's lattice rays found.
struct ProbeTrace {
  ShCoefficients sh{};
  int backFaces = 0;
  float nearestBack = 1e30f;  // distance to the nearest back face hit, and the direction it lies in
  glm::vec3 nearestBackDir{0.0f};
};

// The finished maps, packed once for the rays' reads (M; ρ is read at the hit).
struct MapReader {
  const BakeInputs& in;
  std::vector<PackedLightmap> packed;
  std::vector<int32_t> mapOfPage;
  MapReader(const BakeInputs& inputs, const std::vector<Lightmap>& maps) : in(inputs), mapOfPage(mapIndexOfPages(inputs.texels)) {
    packed.reserve(maps.size());
    for (const Lightmap& m : maps) packed.emplace_back(m, m.texels);
  }
  // Outgoing radiance of a front-face hit: Le + ρ M.
  glm::vec3 radiance(const RayHit& hit) const {
    const Primitive& prim = in.scene.primitives[hit.primitive];
    glm::vec3 L = in.scene.emissionAt(prim, hit.triangle, hit.barycentric);
    const MapPoint point = mapPointOf(in.scene, mapOfPage, in.texels, hit);
    if (point.map >= 0 && static_cast<size_t>(point.map) < packed.size())
      L += in.albedoAtHit(hit) * packed[point.map].read(point.texel);
    return L;
  }
};

bool doubleSided(const Scene& scene, uint32_t primitive) {
  if (primitive >= scene.primitives.size()) return false;
  const int m = scene.primitives[primitive].material;
  return m >= 0 && m < static_cast<int>(scene.materials.size()) && scene.materials[m].doubleSided;
}

ProbeTrace traceProbe(const MapReader& reader, const glm::vec3& p, int rays, double r1, double r2) {
  const Scene& scene = reader.in.scene;
  const RayTracer& rt = reader.in.rayTracer;
  ProbeTrace out;
  constexpr int kChunk = 32;
  glm::vec3 dirs[kChunk];
  RayHit hits[kChunk];
  for (int begin = 0; begin < rays; begin += kChunk) {
    const int count = std::min(kChunk, rays - begin);
    for (int k = 0; k < count; ++k) {
      const double i = begin + k;
      const double u = (i + 0.5) / rays + r1, v = i / kGoldenRatio + r2;
      dirs[k] = uniformSphere(u - std::floor(u), v - std::floor(v));
    }
    rt.intersectPackets(p, dirs, static_cast<size_t>(count), hits, RayTracer::HitDetail::Full);
    for (int k = 0; k < count; ++k) {
      const RayHit& hit = hits[k];
      glm::vec3 L(0.0f);
      if (!hit.hit) {
        if (scene.environment.present()) L = scene.environment.radiance(dirs[k]);
      } else if (hit.backFace) {  // no map on a back face; a double-sided surface's back is no inside
        if (!doubleSided(scene, hit.primitive)) {
          ++out.backFaces;
          if (hit.t < out.nearestBack) out.nearestBack = hit.t, out.nearestBackDir = dirs[k];
        }
      } else {
        L = reader.radiance(hit);
      }
      if (L != glm::vec3(0.0f)) shAddDirectional(out.sh, dirs[k], L);
    }
  }
  // (4π / N) per ray, and 1/π for map units.
  for (auto& c : out.sh) c *= 4.0f / static_cast<float>(rays);
  return out;
}

// Every punctual light as a delta from its direction, shadowed; returns the shadow rays traced.
size_t addPunctualLights(const BakeInputs& in, const glm::vec3& p, ShCoefficients& sh) {
  size_t traced = 0;
  for (const Light& light : in.scene.lights) {
    const glm::vec3 toward = light.type == LightType::Directional ? -glm::normalize(light.direction)
                                                                  : light.position - p;
    if (!(glm::dot(toward, toward) > 0.0f)) continue;
    const PunctualContribution c = punctualDirect(light, p, glm::normalize(toward));  // at normal incidence
    if (c.mapValue == glm::vec3(0.0f)) continue;
    ++traced;
    if (in.rayTracer.occluded(p, c.toLight, 0.0f, c.distance)) continue;
    shAddDirectional(sh, c.toLight, c.mapValue * in.rayTracer.transmittance(p, c.toLight, 0.0f, c.distance));
  }
  return traced;
}

}  // namespace

float chooseProbeSpacing(const Bounds3& volume) {
  const glm::vec3 e = volume.extent();
  const double longest = std::max({e.x, e.y, e.z}), shortest = longest / 16.0;
  const double v = std::max<double>(e.x, shortest) * std::max<double>(e.y, shortest) * std::max<double>(e.z, shortest);
  return std::max(0.01f, static_cast<float>(std::cbrt(v / kAutoProbes)));
}

LightProbeGrid probeGridOver(const Bounds3& volume, float spacing, size_t maxProbes) {
  if (!volume.valid()) throw Error(ErrorCode::Usage, "", "the probe volume is empty");
  if (!(spacing > 0.0f) || !std::isfinite(spacing))
    throw Error(ErrorCode::Usage, "", "the probe spacing must be a positive number of metres (got " + std::to_string(spacing) + ")");
  LightProbeGrid g;
  g.spacing = spacing;
  const glm::vec3 e = volume.extent(), centre = 0.5f * (volume.min + volume.max);
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double n = std::max(1.0, std::ceil(static_cast<double>(e[a]) / spacing - 1e-6));
    total *= n;
    g.counts[a] = static_cast<int>(std::min(n, 1e9));
  }
  if (total > static_cast<double>(maxProbes))
    throw Error(ErrorCode::Usage, "", "a probe spacing of " + std::to_string(spacing) + " m gives " +
                                          std::to_string(static_cast<long long>(total)) + " probes (at most " +
                                          std::to_string(maxProbes) + "): choose a larger spacing");
  g.origin = centre - 0.5f * spacing * glm::vec3(g.counts - 1);
  return g;
}

void bakeLightProbes(const BakeInputs& in, const std::vector<Lightmap>& maps, LightProbeGrid& grid,
                     const ProbeOptions& options, ProbeStats* stats) {
  Stopwatch watch;
  const size_t n = grid.size();
  grid.coefficients.assign(n, ShCoefficients{});
  grid.offsets.assign(n, glm::vec3(0.0f));
  grid.valid.assign(n, 0);
  const MapReader reader(in, maps);
  const int rays = std::max(16, options.rays);
  const int tooManyBack = static_cast<int>(std::floor(options.maxBackFaceShare * rays));
  std::atomic<size_t> traced{0}, moved{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    Rng rng(hashSeed(options.seed, kProbeStream, i));
    const double r1 = rng.uniform(), r2 = rng.uniform();
    const glm::vec3 at = grid.position(i);
    ProbeTrace t = traceProbe(reader, at, rays, r1, r2);
    size_t count = static_cast<size_t>(rays);
    glm::vec3 offset(0.0f);
    if (t.backFaces > tooManyBack) {
      // Through the nearest back face, just past it, if that stays within half a spacing of the grid point.
      const float step = t.nearestBack + 0.05f * grid.spacing;
      if (step <= 0.5f * grid.spacing) {
        offset = t.nearestBackDir * step;
        t = traceProbe(reader, at + offset, rays, r1, r2);
        count += static_cast<size_t>(rays);
        if (t.backFaces <= tooManyBack) ++moved;
      }
    }
    if (t.backFaces <= tooManyBack) {
      count += addPunctualLights(in, at + offset, t.sh);
      grid.coefficients[i] = t.sh;
      grid.offsets[i] = offset;
      grid.valid[i] = 1;
    }
    traced += count;
  });
  if (stats) {
    stats->count = n;
    stats->valid = static_cast<size_t>(std::count(grid.valid.begin(), grid.valid.end(), uint8_t(1)));
    stats->moved = moved;
    stats->spacing = grid.spacing;
    stats->rays = traced;
    stats->seconds = watch.seconds();
  }
}

}  // namespace irbake
