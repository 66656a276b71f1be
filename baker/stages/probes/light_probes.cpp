#include "stages/probes/light_probes.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <tbb/parallel_for.h>

#include "common/error.h"
#include "common/maths.h"
#include "common/progress.h"
#include "scene/scene_limits.h"
#include "sampling/sampling.h"
#include "transport/geometry_term.h"
#include "stages/probes/blend_fit.h"
#include "stages/probes/exact_emitters.h"
#include "stages/probes/light_visibility_fit.h"
#include "stages/probes/sun_level.h"
#include "vpl/light_sources.h"

namespace irbake {
namespace {

constexpr uint64_t kProbeStream = 0x9b;  // the probes' lattice rotations and emitter-sample offsets
constexpr uint64_t kVolumeStream = 0x9d;  // the volume fit's sample points and their lattices
constexpr double kGoldenRatio = 1.6180339887498949;

// What one probe's lattice rays found.
struct ProbeTrace {
  ShCoefficients sh{};
  int backFaces = 0;
  float nearestBack = 1e30f;  // distance to the nearest back face hit, and the direction it lies in
  glm::vec3 nearestBackDir{0.0f};
};

// The emissive triangles' direct light by next-event estimation: K points per probe, picked by power, each
// combined with the lattice by the power heuristic (Veach 1997). The lattice samples directions with density
// a = N/(4π), the emitter samples with b = K p(ω), p(ω) = p_A r²/cosθ_y; weighted a²/(a² + b²) and b²/(a² + b²),
// an emitter's direction ω counts Le a/(a² + b²) per lattice ray and Le b/(a² + b²) per shadow ray: a small
// emitter is nearly all shadow rays, a wall nearly all lattice, and no direction is counted twice.
// The exact emitters' emission counts in neither (weight 0, never sampled): the clients shade it.
struct EmitterSampler {
  LightSources sources;
  const ExactEmitters& exact;
  int samples = 0;              // K
  double latticeDensity = 0.0;  // N/(4π)
  EmitterSampler(const Scene& scene, const ExactEmitters& kept, int k, int rays)
      : sources(collectLightSources(scene)), exact(kept), latticeDensity(rays / (4.0 * kPi)) {
    if (!exact.primitives.empty() && !sources.triangles.empty()) {
      std::vector<double> weights(sources.triangles.size());
      for (size_t t = 0; t < weights.size(); ++t)
        weights[t] = exact.contains(sources.triangles[t].primitive) ? 0.0 : channelMean(sources.triangles[t].power);
      sources.areaOnly = AliasTable(weights);
    }
    const bool any = !sources.triangles.empty() && sources.areaOnly.total() > 0.0;
    samples = any ? std::max(0, k) : 0;
  }
  // The weight of a lattice ray's front-face hit on an emitter (1 where no shadow ray could find it).
  double latticeWeight(const RayHit& hit, const glm::vec3& dir) const {
    if (exact.contains(hit.primitive)) return 0.0;
    if (samples == 0) return 1.0;
    const double pA = sources.areaPdf(hit.primitive, hit.triangle), cosY = -glm::dot(hit.geometricNormal, dir);
    if (!(pA > 0.0) || !(cosY > 0.0)) return 1.0;
    const double a = latticeDensity, b = samples * pA * double(hit.t) * hit.t / cosY;
    return a * a / (a * a + b * b);
  }
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
  // Outgoing radiance of a front-face hit: w Le + ρ M, w the lattice's balance weight of the emission.
  glm::vec3 radiance(const RayHit& hit, double emissionWeight) const {
    const Primitive& prim = in.scene.primitives[hit.primitive];
    glm::vec3 L = in.scene.emissionAt(prim, hit.triangle, hit.barycentric);
    if (L != glm::vec3(0.0f)) L *= static_cast<float>(emissionWeight);
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

// The spherical Fibonacci lattice of n directions turned by (r1, r2): direction i is uniformSphere(u, v) for
// u = (i + ½)/n + r1, v = i/φ + r2, its azimuth read from a table of 2π i/φ and turned by 2π r2, so that a ray
// costs a rotation instead of a sincos. n is at most 65536 (--probe-rays, --probe-volume-rays).
class TurnedLattice {
 public:
  TurnedLattice(int n, double r1, double r2)
      : n_(std::min(n, kMaxRays)), r1_(r1), tc_(std::cos(2.0 * kPi * r2)), ts_(std::sin(2.0 * kPi * r2)) {}
  int size() const { return n_; }
  glm::vec3 operator[](int i) const {
    const double u = (i + 0.5) / n_ + r1_, z = 1.0 - 2.0 * (u - std::floor(u));
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const glm::dvec2 a = azimuths()[i];
    return glm::vec3(float(r * (a.x * tc_ - a.y * ts_)), float(r * (a.y * tc_ + a.x * ts_)), float(z));
  }

 private:
  static constexpr int kMaxRays = 65536;
  static const glm::dvec2* azimuths() {
    static const std::vector<glm::dvec2> table = [] {
      std::vector<glm::dvec2> t(kMaxRays);
      for (size_t i = 0; i < t.size(); ++i) {
        const double a = 2.0 * kPi * (i / kGoldenRatio - std::floor(i / kGoldenRatio));
        t[i] = glm::dvec2(std::cos(a), std::sin(a));
      }
      return t;
    }();
    return table.data();
  }
  int n_;
  double r1_, tc_, ts_;
};

ProbeTrace traceProbe(const MapReader& reader, const EmitterSampler& emitters, const glm::vec3& p, int rays, double r1,
                      double r2) {
  const Scene& scene = reader.in.scene;
  const RayTracer& rt = reader.in.rayTracer;
  ProbeTrace out;
  constexpr int kChunk = 32;
  glm::vec3 dirs[kChunk];
  RayHit hits[kChunk];
  const TurnedLattice lattice(rays, r1, r2);
  rays = lattice.size();
  for (int begin = 0; begin < rays; begin += kChunk) {
    const int count = std::min(kChunk, rays - begin);
    for (int k = 0; k < count; ++k) dirs[k] = lattice[begin + k];
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
        L = reader.radiance(hit, emitters.latticeWeight(hit, dirs[k]));
      }
      if (L != glm::vec3(0.0f)) shAddDirectional(out.sh, dirs[k], L);
    }
  }
  // (4π / N) per ray, and 1/π for map units.
  for (auto& c : out.sh) c *= 4.0f / static_cast<float>(rays);
  return out;
}

// Whether no surface lies within `clearance` of p along 32 short occlusion rays on a rotated lattice, the first
// hit ending the test: where an object's centre can be, for the volume fit's samples. Inside geometry needs no
// test of its own there: a sample is kept only where valid probes see it. Adds the rays traced to `traced`.
bool clearOfSurfaces(const RayTracer& rt, const glm::vec3& p, float clearance, double r1, double r2, size_t& traced) {
  if (!(clearance > 0.0f)) return true;
  const TurnedLattice lattice(32, r1, r2);
  for (int k = 0; k < lattice.size(); ++k) {
    ++traced;
    if (rt.occluded(p, lattice[k], 0.0f, clearance)) return false;
  }
  return true;
}

// Every punctual light as a delta from its direction, times its visibility at the probe (`visibility`, one per
// light: the fitted value, light_visibility_fit.h) and the colour of the see-through surfaces on the way.
void addPunctualLights(const BakeInputs& in, const glm::vec3& p, const float* visibility, ShCoefficients& sh) {
  for (uint32_t l : in.lightsNear(p)) {
    const Light& light = in.scene.lights[l];
    if (!(visibility[l] > 0.0f)) continue;
    const PunctualContribution c = lightKind(light.type).atNormalIncidence(light, p);
    if (c.mapValue == glm::vec3(0.0f)) continue;
    glm::vec3 colour(1.0f);
    const float own = punctualVisibility(in, light, p, &colour);
    if (!(own > 0.0f)) colour = glm::vec3(1.0f);  // shadowed here, lit in the fit: the light's own colour
    else colour /= own;                           // the transmittance's hue; its strength is the fit's
    shAddDirectional(sh, c.toLight, c.mapValue * colour * visibility[l]);
  }
}

// The emitters' share by K shadow rays to points on a rotated 2D Fibonacci lattice (the first coordinate picks the
// triangle by power and, rescaled, stays stratified within it); returns the shadow rays traced.
size_t addEmitters(const BakeInputs& in, const EmitterSampler& emitters, const glm::vec3& p, double r3, double r4,
                   ShCoefficients& sh) {
  const RayTracer& rt = in.rayTracer;
  const int K = emitters.samples;
  size_t traced = 0;
  for (int j = 0; j < K; ++j) {
    const double u = (j + 0.5) / K + r3, v = j / kGoldenRatio + r4;
    double residual = 0.0;
    const size_t k = emitters.sources.areaOnly.sample(u - std::floor(u), &residual);
    const EmitterTriangle& e = emitters.sources.triangles[k];
    const Primitive& prim = in.scene.primitives[e.primitive];
    const glm::vec2 b = uniformTriangle(residual, v - std::floor(v));
    const uint32_t* idx = &prim.indices[3 * e.triangle];
    const glm::vec3 y = prim.positions[idx[0]] * (1.0f - b.x - b.y) + prim.positions[idx[1]] * b.x + prim.positions[idx[2]] * b.y;
    const glm::vec3 d = y - p;
    const float r2 = glm::dot(d, d);
    if (!(r2 > 0.0f)) continue;
    const float r = std::sqrt(r2);
    const glm::vec3 w = d / r;
    const float cosY = -glm::dot(e.normal, w);  // emission leaves the front face only
    if (!(cosY > 0.0f)) continue;
    glm::vec3 Le = in.scene.emissionAt(prim, e.triangle, b);
    if (Le == glm::vec3(0.0f)) continue;
    ++traced;
    const float tmax = r - 2.0f * rt.epsilon();
    if (tmax > 0.0f && rt.occluded(p, w, 0.0f, tmax)) continue;
    if (rt.hasTransmission() && tmax > 0.0f) Le *= rt.transmittance(p, w, 0.0f, tmax);
    const double da = emitters.latticeDensity, db = K * emitters.sources.areaOnly.pdf(k) / e.area * r2 / cosY;
    shAddDirectional(sh, w, Le * static_cast<float>(db / (kPi * (da * da + db * db))));  // 1/π: map units
  }
  return traced;
}

// The lattice's and emitters' light (everything but the punctual lights) fitted over each probe's cube
// (ProbeOptions::volumeFitSamples): S³ jittered points per valid probe, kept where every probe of their blend sees
// them and they are not inside geometry, each traced with `volumeFitRays` lattice rays; each probe's own SH is
// one more sample, weighted volumeFitAnchor.
struct VolumeFitStats {
  size_t rays = 0, samples = 0;
  int sweeps = 0;
};

VolumeFitStats fitProbeVolume(const BakeInputs& in, const MapReader& reader, const ExactEmitters& exact,
                              LightProbeGrid& grid, const ProbeOptions& options) {
  VolumeFitStats out;
  const int S = std::max(0, options.volumeFitSamples);
  if (S == 0) return out;
  const int rays = std::max(16, options.volumeFitRays);
  const float clearance = std::max(0.0f, options.volumeFitClearance) * grid.spacing;
  const int emitterSamples = options.emitterSamples > 0
                                 ? std::max(1, static_cast<int>(std::lround(double(options.emitterSamples) * rays / std::max(16, options.rays))))
                                 : 0;
  const EmitterSampler emitters(in.scene, exact, emitterSamples, rays);
  const int tooManyBack = static_cast<int>(std::floor(options.maxBackFaceShare * rays));
  const size_t n = grid.size(), perProbe = static_cast<size_t>(S) * S * S, m = 3 * kShCoefficients;
  std::vector<BlendSample> samples(n * perProbe);
  std::vector<float> targets(n * perProbe * m, 0.0f);
  std::atomic<size_t> traced{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    if (!grid.valid[i]) return;
    Rng rng(hashSeed(options.seed, kVolumeStream, i));
    const glm::vec3 at = grid.position(i), corner = at - grid.offsets[i] - 0.5f * grid.spacing;
    size_t count = 0;
    for (size_t s = 0; s < perProbe; ++s) {
      const glm::vec3 cell(static_cast<float>(s % S), static_cast<float>(s / S % S), static_cast<float>(s / (S * S)));
      const glm::vec3 jitter(rng.uniform(), rng.uniform(), rng.uniform());
      const double r1 = rng.uniform(), r2 = rng.uniform(), r3 = rng.uniform(), r4 = rng.uniform();
      const glm::vec3 x = corner + grid.spacing * (cell + jitter) / static_cast<float>(S);
      // Kept only where an object's centre can be: at least `clearance` from every surface (the light right
      // beside a wall, which no object's centre reaches, would bend the blend).
      if (!clearOfSurfaces(in.rayTracer, x, clearance, r1, r2, count)) continue;
      ++count;
      if (!probeSees(in, at, x)) continue;
      // Kept only where every probe of its blend sees it: a cell across a floor or a wall would otherwise fit
      // the probes on one side to the light on the other (the clients blend without visibility).
      const BlendSample blend = blendSampleAt(grid, x);
      bool seen = blend.corners > 0;
      for (int c = 0; c < blend.corners && seen; ++c, ++count) seen = probeSees(in, grid.position(blend.probe[c]), x);
      if (!seen) continue;
      ProbeTrace t = traceProbe(reader, emitters, x, rays, r1, r2);
      count += static_cast<size_t>(rays);
      if (t.backFaces > tooManyBack) continue;  // inside geometry: no light a client would read there
      count += addEmitters(in, emitters, x, r3, r4, t.sh);
      std::memcpy(&targets[(i * perProbe + s) * m], t.sh.data(), m * sizeof(float));
      samples[i * perProbe + s] = blend;
    }
    traced += count;
  });
  std::vector<float> anchors(n * m);
  for (size_t i = 0; i < n; ++i) std::memcpy(&anchors[i * m], grid.coefficients[i].data(), m * sizeof(float));
  std::vector<float> x = anchors;
  float scale = 0.0f;
  for (float v : anchors) scale = std::max(scale, std::abs(v));
  const BlendFitResult r = solveBlendFit(grid, samples, targets, anchors, m, options.volumeFitAnchor, std::nullopt,
                                         1e-5 * std::max(scale, 1e-6f), 400, x);
  for (size_t i = 0; i < n; ++i)
    if (grid.valid[i]) std::memcpy(grid.coefficients[i].data(), &x[i * m], m * sizeof(float));
  out.rays = traced;
  out.samples = r.samples;
  out.sweeps = r.sweeps;
  return out;
}

}  // namespace

float chooseProbeSpacing(const Bounds3& volume, double probes) {
  const glm::vec3 e = volume.extent();
  const double longest = std::max({e.x, e.y, e.z}), shortest = longest / 16.0;
  const double v = std::max<double>(e.x, shortest) * std::max<double>(e.y, shortest) * std::max<double>(e.z, shortest);
  return std::max(kMinProbeSpacing, static_cast<float>(std::cbrt(v / std::max(1.0, probes))));
}

double probeCountOver(const Bounds3& volume, float spacing) {
  const glm::vec3 e = volume.extent();
  double total = 1.0;
  for (int a = 0; a < 3; ++a) total *= std::max(1.0, std::ceil(static_cast<double>(e[a]) / spacing - 1e-6));
  return total;
}

std::string probeCountText(double count) {
  char text[32];
  std::snprintf(text, sizeof text, count < 1e15 ? "%.0f" : "%.3g", count);
  return text;
}

LightProbeGrid probeGridOver(const Bounds3& volume, float spacing, size_t maxProbes) {
  if (!volume.valid()) throw Error(ErrorCode::Usage, "", "the probe volume is empty");
  const double limit = kMaxSceneCoordinate * (1.0 + kSceneLimitSlack);
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(volume.min[a]) <= limit) || !(std::abs(volume.max[a]) <= limit))
      throw Error(ErrorCode::Usage, "", "the probe volume reaches beyond the supported 1e9 m from the origin");
  if (!(spacing > 0.0f) || !std::isfinite(spacing))
    throw Error(ErrorCode::Usage, "", "the probe spacing must be a positive number of metres (got " + std::to_string(spacing) + ")");
  LightProbeGrid g;
  g.spacing = spacing;
  const glm::vec3 e = volume.extent(), centre = 0.5f * (volume.min + volume.max);
  const double total = probeCountOver(volume, spacing);
  if (total > static_cast<double>(maxProbes)) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", spacing);
    throw Error(ErrorCode::Usage, "", std::string("a probe spacing of ") + text + " m gives " + probeCountText(total) +
                                          " probes (at most " + std::to_string(maxProbes) + "): choose a larger spacing");
  }
  for (int a = 0; a < 3; ++a)
    g.counts[a] = static_cast<int>(std::max(1.0, std::ceil(static_cast<double>(e[a]) / spacing - 1e-6)));
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
  const ExactEmitters exact = chooseExactEmitters(in.scene, grid.spacing, std::max(0, options.exactEmitterTriangles));
  const EmitterSampler emitters(in.scene, exact, options.emitterSamples, rays);
  const int tooManyBack = static_cast<int>(std::floor(options.maxBackFaceShare * rays));
  std::atomic<size_t> traced{0}, moved{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    Rng rng(hashSeed(options.seed, kProbeStream, i));
    const double r1 = rng.uniform(), r2 = rng.uniform(), r3 = rng.uniform(), r4 = rng.uniform();
    const glm::vec3 at = grid.position(i);
    ProbeTrace t = traceProbe(reader, emitters, at, rays, r1, r2);
    size_t count = static_cast<size_t>(rays);
    glm::vec3 offset(0.0f);
    if (t.backFaces > tooManyBack) {
      // Through the nearest back face, just past it, if that stays within half a spacing of the grid point.
      const float step = t.nearestBack + 0.05f * grid.spacing;
      if (step <= 0.5f * grid.spacing) {
        offset = t.nearestBackDir * step;
        t = traceProbe(reader, emitters, at + offset, rays, r1, r2);
        count += static_cast<size_t>(rays);
        if (t.backFaces <= tooManyBack) ++moved;
      }
    }
    if (t.backFaces <= tooManyBack) {
      count += addEmitters(in, emitters, at + offset, r3, r4, t.sh);
      grid.coefficients[i] = t.sh;
      grid.offsets[i] = offset;
      grid.valid[i] = 1;
    }
    traced += count;
  });
  // The rest of the light fitted over the blend, then the punctual lights, once every probe's validity is known:
  // their visibility is fitted over the blend as well.
  const VolumeFitStats volume = fitProbeVolume(in, reader, exact, grid, options);
  traced += volume.rays;
  const size_t emitterRays = bakeEmitterVisibility(in, exact, options.emitterVisibilitySamples, options.seed, grid);
  traced += emitterRays;
  LightVisibilityFit fit = fitLightVisibility(in, grid, options.lightFitSamples, options.seed);
  // The sun level's light: its visibilities in steps of 1/255, as the export stores them (a byte each), so that
  // what the clients subtract is what the coefficients carry.
  const int sun = options.sunSubdivisions > 0 ? strongestDirectionalLight(in.scene.lights) : -1;
  if (sun >= 0 && fit.lights > 0)
    for (size_t i = 0; i < n; ++i) {
      float& v = fit.visibility[i * fit.lights + static_cast<size_t>(sun)];
      v = std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
    }
  if (fit.lights > 0)
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      if (grid.valid[i]) addPunctualLights(in, grid.position(i), &fit.visibility[i * fit.lights], grid.coefficients[i]);
    });
  traced += fit.rays;
  // The strongest directional light's visibility refined where its shadow crosses a cell (sun_level.h).
  SunLevelStats sunStats;
  grid.sun = ProbeSunLevel{};
  if (sun >= 0 && fit.lights > 0) {
    std::vector<float> carried(n, 0.0f);
    for (size_t i = 0; i < n; ++i)
      if (grid.valid[i]) carried[i] = fit.visibility[i * fit.lights + static_cast<size_t>(sun)];
    SunLevelOptions sunOptions;
    sunOptions.subdivisions = options.sunSubdivisions;
    sunOptions.tolerance = options.sunTolerance;
    grid.sun = bakeSunLevel(in, grid, static_cast<size_t>(sun), carried, sunOptions, &sunStats);
  }
  traced += sunStats.rays;
  if (stats) {
    stats->count = n;
    stats->valid = static_cast<size_t>(std::count(grid.valid.begin(), grid.valid.end(), uint8_t(1)));
    stats->moved = moved;
    stats->spacing = grid.spacing;
    stats->rays = traced;
    stats->lightFitSamples = fit.samples;
    stats->lightFitSweeps = fit.sweeps;
    stats->volumeFitSamples = volume.samples;
    stats->volumeFitSweeps = volume.sweeps;
    stats->sunCells = sunStats.cells;
    stats->sunRays = sunStats.rays;
    stats->exactEmitters = exact.emitters.size();
    for (const ProbeEmitter& e : exact.emitters) stats->exactEmitterTriangles += e.positions.size() / 3;
    stats->emitterVisibilityRays = emitterRays;
    stats->seconds = watch.seconds();
  }
}

}  // namespace irbake
