// Keller's quasi-random walk (Instant Radiosity, 1997).
//
// N paths start on the lights (chosen by power with one alias table over emissive triangles and punctual
// lights). Path i uses the i-th Halton point: dimension 0 picks the light and, through the alias
// residual, gives with dimension 1 the point on the emitter; dimensions 2+2j, 3+2j give the
// direction leaving bounce j (cosine for surfaces; by intensity for punctual lights).
//
// Fractional absorption: at bounce j only the first M_j = floor(N ρ̄^j) paths continue. A path that
// starts with power Φ_s / (p_s N) leaves at bounce j a VPL of power
//     Φ_s / (p_s N) · Π_k (a_k / ρ̄) · ρ̄^j N / M_j  =  Φ_s / (p_s M_j) · Π_k a_k,
// i.e. "power scaled by albedo over ρ̄" with the ρ̄^j N / M_j factor that makes the bookkeeping exact:
// with a grey scene of albedo ρ̄ in a closed room the bounce-j VPLs carry exactly Φ ρ̄^j.
// Depth (auto): the walk goes as deep as the light left is worth placing and the VPL budget allows
// (autoBounceDepth); the bounces beyond the deepest one, J, are added to bounce J's VPLs as a geometric
// series with the ratio the walk measured between its last two bounces (geometricTailFactor). A fixed
// cap would lose ρ̄^(J+1) of the light: 17% at ρ̄ = 0.9 with 16 bounces, 84% at ρ̄ = 0.99.
// Punctual lights leave no bounce-0 VPL (the backends evaluate them exactly); their paths start at bounce 1.
#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/error.h"
#include "common/maths.h"
#include "lights/light_kind.h"
#include "vpl/light_sources.h"
#include "vpl/resample.h"
#include "sampling/sampling.h"
#include "vpl/vpl.h"

namespace irbake {

namespace {

// M_j = ⌊N ρ̄^j⌋: the paths still walking at bounce j.
uint64_t survivorCount(uint64_t N, double rho, int j) {
  return static_cast<uint64_t>(std::floor(static_cast<double>(N) * std::pow(rho, j) + 1e-9));
}

}  // namespace

int autoBounceDepth(uint64_t paths, double rho, const WalkOptions& options) {
  constexpr int kHardLimit = 100000;  // ρ̄ within 1e-4 of 1 with a vast budget: still a finite loop
  double vpls = static_cast<double>(paths);  // bounce 0
  const double budget = options.maxVplsPerPath * static_cast<double>(paths);
  int J = 0;
  for (int j = 1; j < kHardLimit; ++j) {
    const uint64_t m = survivorCount(paths, rho, j);
    if (m == 0 || std::pow(rho, j) < options.tailEnergy || vpls + static_cast<double>(m) > budget) break;
    vpls += static_cast<double>(m);
    J = j;
  }
  return J;
}

glm::dvec3 geometricTailFactor(const glm::dvec3& lastPower, const glm::dvec3& previousPower) {
  glm::dvec3 f(1.0);
  for (int c = 0; c < 3; ++c) {
    if (!(previousPower[c] > 0.0) || !(lastPower[c] > 0.0)) continue;
    const double r = std::clamp(lastPower[c] / previousPower[c], 0.0, 0.999);
    f[c] = 1.0 / (1.0 - r);
  }
  return f;
}

namespace {

// Where path i leaves its light: the point, direction and power (Φ_s / (p_s N), before the albedo
// products). An emitter surface also leaves the path's bounce-0 VPL in `vpls`.
struct PathStart {
  glm::vec3 origin{0.0f}, dir{0.0f}, normal{0.0f};
  glm::dvec3 power{0.0};
  bool onSurface = false;  // starts on a surface (origin inset): rays leave along the normal
  const Light* light = nullptr;  // the punctual light it leaves (its range windows the first hit)
};

// Where a ray leaves punctual light l for the random numbers (u0..u3): its origin and direction, as its kind
// emits (a light at infinity: on a disc covering the scene's bounding sphere, upstream of it); returns the path's
// weight (LightKind::emit).
double lightRay(const Light& l, const LightSources& sources, double u0, double u1, double u2, double u3,
                glm::vec3& origin, glm::vec3& dir) {
  return lightKind(l.type).emit(l, sources.sceneCentre, sources.sceneRadius, u0, u1, u2, u3, origin, dir);
}

// The sky's ray: a direction towards the sky by radiance (u2, u3; its density in `pdf`) and a point on a
// disc covering the bounding sphere upstream (u0, u1). Returns the direction towards the sky.
glm::vec3 skyRay(const Scene& scene, const LightSources& sources, double u0, double u1, double u2, double u3,
                 glm::vec3& origin, glm::vec3& dir, double& pdf) {
  const glm::vec3 toSky = scene.environment.sample(u2, u3, pdf);
  dir = -toSky;
  glm::vec3 t, b;
  orthonormalBasis(dir, t, b);
  const double r = sources.sceneRadius * std::sqrt(u0), phi = 2.0 * kPi * u1;
  origin = sources.sceneCentre - dir * (1.01f * sources.sceneRadius) + t * float(r * std::cos(phi)) +
           b * float(r * std::sin(phi));
  return toSky;
}

PathStart startPath(const Scene& scene, const RayTracer& rt, const LightSources& sources, const Halton& halton,
                    uint64_t i, uint64_t N, std::vector<Vpl>& vpls) {
  const size_t numTriangles = sources.triangles.size();
  double residual = 0.0;
  size_t s = sources.all.sample(halton.sample(0, i), &residual);
  double u1 = halton.sample(1, i);
  double p = sources.all.pdf(s);
  PathStart path;
  glm::dvec3& pathPower = path.power;
  glm::vec3 &origin = path.origin, &dir = path.dir, &normal = path.normal;
  bool& surfaceStart = path.onSurface;
  if (s < numTriangles) {
    const EmitterTriangle& e = sources.triangles[s];
    const Primitive& prim = scene.primitives[e.primitive];
    glm::vec2 bary = uniformTriangle(residual, u1);
    const uint32_t* idx = &prim.indices[3 * e.triangle];
    origin = rt.insetPoint(e.primitive, e.triangle,
                           prim.positions[idx[0]] * (1.0f - bary.x - bary.y) + prim.positions[idx[1]] * bary.x +
                               prim.positions[idx[2]] * bary.y);
    normal = e.normal;
    // Emission at the sampled point (textures), so the estimate is unbiased for textured emitters.
    glm::dvec3 Le(scene.emissionAt(prim, e.triangle, bary));
    pathPower = Le * (kPi * e.area) / (p * static_cast<double>(N));
    vpls.push_back(Vpl{origin, normal, glm::vec3(pathPower), 0});
    dir = cosineHemisphere(normal, halton.sample(2, i), halton.sample(3, i));
    surfaceStart = true;
  } else if (sources.hasSky && s == numTriangles + scene.lights.size()) {
    // The sky: a direction towards it by luminance, a point on a disc covering the bounding sphere
    // upstream; the path carries L(ω)/p(ω) · π R² / N (its colour included).
    double pdf = 0.0;
    const glm::vec3 toSky = skyRay(scene, sources, residual, u1, halton.sample(2, i), halton.sample(3, i), origin, dir, pdf);
    const double R = sources.sceneRadius;
    pathPower = pdf > 0.0 ? glm::dvec3(scene.environment.radiance(toSky)) * (kPi * R * R / (pdf * p * static_cast<double>(N)))
                          : glm::dvec3(0.0);
  } else {
    const Light& l = scene.lights[s - numTriangles];
    path.light = &l;
    const double weight = lightRay(l, sources, residual, u1, halton.sample(2, i), halton.sample(3, i), origin, dir);
    pathPower = sources.lightPower[s - numTriangles] * weight / (p * static_cast<double>(N));
  }
  return path;
}

// Budgets follow the light that reaches the scene. A punctual light or sky whose rays land on the outside of
// a closed room (the backs of its one-sided walls) or miss everything would otherwise take the paths the
// light inside needs (the sample box under a sun it never lets in: every path, and a third of the map's
// light lost). So each such source's weight in the start table is its power times its reach: the share of
// kReachPilots rays whose first hit is a side that receives light (a front face, or either face of a
// double-sided material). Sources no pilot ray reached keep a small weight, together at most
// kUnreachedShare of the rest, so every source can still start paths and the walk stays unbiased. A ray of a
// light with a range counts with the light's window at its hit (Light::rangeWindow), as its path's VPL will.
constexpr int kReachPilots = 1024;
constexpr double kUnreachedShare = 0.01;

// Returns the reach of each punctual light, then the sky's when there is one, and rebuilds `sources.all`.
std::vector<double> weighByReach(const Scene& scene, const RayTracer& rt, LightSources& sources, uint32_t seed) {
  std::vector<double> reach;
  const size_t lights = scene.lights.size() + (sources.hasSky ? 1 : 0);
  if (lights == 0) return reach;
  reach.assign(lights, 0.0);
  tbb::parallel_for(size_t(0), lights, [&](size_t k) {
    Rng rng(hashSeed(seed, 0x72656163680000ull, k));  // "reach"
    double received = 0.0;  // pilots' weights (LightKind::emit), 1 each for the sky
    for (int n = 0; n < kReachPilots; ++n) {
      const double u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
      glm::vec3 origin, dir;
      double pdf = 0.0, weight = 1.0;
      if (k < scene.lights.size()) weight = lightRay(scene.lights[k], sources, u0, u1, u2, u3, origin, dir);
      else skyRay(scene, sources, u0, u1, u2, u3, origin, dir, pdf);
      const RayHit hit = rt.intersect(origin, dir, 0.0f, 1e30f);
      if (!hit.hit) continue;
      if (k < scene.lights.size()) weight *= scene.lights[k].rangeWindow(glm::length(hit.position - origin));
      const Primitive& prim = scene.primitives[hit.primitive];
      const bool doubleSided = prim.material >= 0 && prim.material < static_cast<int>(scene.materials.size()) &&
                               scene.materials[prim.material].doubleSided;
      if (!hit.backFace || doubleSided) received += weight;
    }
    reach[k] = received / kReachPilots;
  });
  // The lights' and the sky's start weights times their reach; the triangles' (emitters light what faces them)
  // stay as they are.
  std::vector<double> weights = sources.startWeights;
  const size_t first = sources.triangles.size();
  double reached = 0.0, unreached = 0.0;
  for (size_t i = 0; i < weights.size(); ++i) {
    const bool light = i >= first;
    if (light && reach[i - first] <= 0.0) {
      unreached += weights[i];
      continue;
    }
    if (light) weights[i] *= reach[i - first];
    reached += weights[i];
  }
  // Unreached sources: their power in proportion, scaled to kUnreachedShare of the reached weight (or
  // their plain power when nothing was reached at all).
  const double scale = reached > 0.0 ? kUnreachedShare * reached / std::max(unreached, 1e-300) : 1.0;
  for (size_t k = 0; k < lights; ++k)
    if (reach[k] <= 0.0) weights[first + k] *= scale;
  sources.all = AliasTable(weights);
  return reach;
}

// From `start` along `dir` to the next surface the path bounces on: see-through surfaces let it go straight
// on with probability `fraction`, tinted (into `throughput`), and that is no bounce; otherwise it meets the
// surface's Lambertian part. The probabilities come from a hash of (path id, bounce, layer), so the walk
// stays deterministic and the Halton dimensions keep their meaning. A miss (hit.hit false): escaped.
RayHit nextBounce(const Scene& scene, const RayTracer& rt, uint64_t seed, uint64_t pathId, int j, const glm::vec3& start,
                  const glm::vec3& dir, glm::dvec3& throughput) {
  RayHit hit = rt.intersect(start, dir, 0.0f, 1e30f);
  for (int layer = 0; hit.hit && layer < 64; ++layer) {
    const SurfaceTransmission transmission =
        scene.transmissionAt(scene.primitives[hit.primitive], hit.triangle, hit.barycentric);
    if (transmission.fraction <= 0.0f) break;
    Rng pass(hashSeed(seed, pathId, static_cast<uint64_t>(j) << 8 | static_cast<uint64_t>(layer)));
    if (pass.uniform() >= transmission.fraction) break;
    throughput *= glm::dvec3(transmission.tint);
    hit = rt.intersect(hit.position + dir * rt.epsilon(), dir, 0.0f, 1e30f);
  }
  return hit;
}

// Follows path i from its start while it is among the survivors of the next bounce, leaving one VPL
// per bounce in `vpls` (power × albedo products × N / M_j). With split s > 1 the path forks where it
// leaves bounce 1: child k (index c = i s + k, its own Halton point from there on) carries 1/s of the
// power, so each surviving path leaves s VPLs per deeper bounce and the bookkeeping stays exact.
void followPath(const Scene& scene, const RayTracer& rt, const Halton& halton, const std::vector<uint64_t>& survivors,
                uint64_t seed, uint64_t i, int split, const PathStart& path, std::vector<Vpl>& vpls) {
  const int maxBounce = static_cast<int>(survivors.size()) - 1;
  const uint64_t N = survivors[0];
  const float eps = rt.epsilon();
  // The hit of bounce j becomes a VPL of this power share; returns where it sits and its lit side.
  auto leaveVpl = [&](const RayHit& hit, int j, glm::dvec3& throughput, double share, glm::vec3& at, glm::vec3& n) {
    throughput *= glm::dvec3(rt.albedoAt(hit));
    n = hit.backFace ? -hit.geometricNormal : hit.geometricNormal;
    at = rt.insetPoint(hit.primitive, hit.triangle, hit.position);
    const glm::dvec3 power = path.power * throughput * (share * static_cast<double>(N) / static_cast<double>(survivors[j]));
    vpls.push_back(Vpl{at, n, glm::vec3(power), j});
  };
  if (maxBounce < 1 || i >= survivors[1]) return;
  // Bounce 1, shared by the children (the origin of a start on a surface is already inset).
  glm::dvec3 throughput1(1.0);
  const glm::vec3 start = path.onSurface ? path.origin + path.normal * eps : path.origin;
  const RayHit first = nextBounce(scene, rt, seed, i, 1, start, path.dir, throughput1);
  if (!first.hit) return;  // escaped: its energy leaves the scene
  // A punctual light's range windows what reaches the first hit, as it windows the direct term
  // (Light::rangeWindow): the light reflected there is the light that arrived. Beyond the range, nothing did.
  if (path.light) {
    const float window = path.light->rangeWindow(glm::length(first.position - start));
    if (window == 0.0f) return;
    throughput1 *= static_cast<double>(window);
  }
  glm::vec3 at1, n1;
  leaveVpl(first, 1, throughput1, 1.0, at1, n1);
  if (maxBounce < 2 || i >= survivors[2]) return;
  for (int k = 0; k < split; ++k) {
    const uint64_t c = i * static_cast<uint64_t>(split) + static_cast<uint64_t>(k);  // Halton index past bounce 1
    glm::dvec3 throughput = throughput1;
    glm::vec3 at = at1, n = n1;
    for (int j = 2; j <= maxBounce && i < survivors[j]; ++j) {
      const glm::vec3 dir = cosineHemisphere(n, halton.sample(2 * j, c), halton.sample(1 + 2 * j, c));
      const RayHit hit = nextBounce(scene, rt, seed, c, j, at + n * eps, dir, throughput);
      if (!hit.hit) break;
      leaveVpl(hit, j, throughput, 1.0 / split, at, n);
    }
  }
}

// Collects every path's VPLs ordered by bounce, then path: deterministic whatever the thread
// schedule. Sets the counts and powers per bounce and the deepest bounce reached.
void orderByBounce(const std::vector<std::vector<Vpl>>& perPath, int maxBounce, VplSet& out) {
  out.countPerBounce.assign(maxBounce + 1, 0);
  out.powerPerBounce.assign(maxBounce + 1, glm::dvec3(0.0));
  for (const auto& path : perPath)
    for (const Vpl& v : path) ++out.countPerBounce[v.bounce];
  std::vector<size_t> offset(maxBounce + 2, 0);
  for (int j = 0; j <= maxBounce; ++j) offset[j + 1] = offset[j] + out.countPerBounce[j];
  out.vpls.resize(offset.back());
  for (const auto& path : perPath)
    for (const Vpl& v : path) {
      out.vpls[offset[v.bounce]++] = v;
      out.powerPerBounce[v.bounce] += glm::dvec3(v.power);
    }
  while (!out.countPerBounce.empty() && out.countPerBounce.back() == 0) {
    out.countPerBounce.pop_back();
    out.powerPerBounce.pop_back();
  }
  out.bounces = std::max(0, static_cast<int>(out.countPerBounce.size()) - 1);
}

}  // namespace

// The bounces beyond J (auto depth only): their power, P_J r/(1 − r), shared by the VPLs of the deeper
// half of the walk (bounces ⌈J/2⌉…J, in proportion to their power). Deep bounces have forgotten where
// the light entered, so they share one distribution; many VPLs carrying the tail instead of bounce J's
// few keeps its noise down (vpl_test's furnace).
void addGeometricTail(VplSet& out) {
  const int J = out.bounces, from = std::max(1, (J + 1) / 2);
  // The ratio r pooled over the same bounces (P_j for j = from−1…J, bounce 0 counted as the emitted
  // power): deep bounces have few paths, and one bounce's ratio alone can be far off.
  auto bouncePower = [&](int j) { return j == 0 ? out.emittedPower : out.powerPerBounce[j]; };
  // Only bounces that many paths reach tell the ratio: the few paths alive at depth are those that stayed
  // among bright, enclosed surfaces, so their bounces decay slower than the scene's light does, and the
  // tail would multiply one trapped path's VPLs. So the pool skips
  // bounces with fewer than kTailMinVpls VPLs, and when the deeper half has none, it takes the deepest
  // bounces that have them.
  constexpr size_t kTailMinVpls = 16;
  auto populated = [&](int j) {
    return out.countPerBounce[j] >= kTailMinVpls && (j == 1 || out.countPerBounce[j - 1] >= kTailMinVpls);
  };
  int deepest = 0;
  for (int j = J; j >= 1 && deepest == 0; --j)
    if (populated(j)) deepest = j;
  int poolFrom = from, poolTo = J;  // no populated bounce at all (tiny walks): the deeper half, all of it
  if (deepest > 0 && deepest < from) poolFrom = std::max(1, deepest - (J - from)), poolTo = deepest;
  glm::dvec3 later(0.0), earlier(0.0);
  for (int j = poolFrom; j <= poolTo; ++j) {
    if (deepest > 0 && !populated(j)) continue;
    later += bouncePower(j);
    earlier += bouncePower(j - 1);
  }
  const glm::dvec3 tail = out.powerPerBounce[J] * (geometricTailFactor(later, earlier) - 1.0);
  glm::dvec3 carriers(0.0);
  size_t first = out.vpls.size();
  for (int j = from; j <= J; ++j) {
    carriers += out.powerPerBounce[j];
    first -= out.countPerBounce[j];
  }
  for (int c = 0; c < 3; ++c) out.tailFactor[c] = carriers[c] > 0.0 ? 1.0 + tail[c] / carriers[c] : 1.0;
  for (size_t v = first; v < out.vpls.size(); ++v)
    out.vpls[v].power = glm::vec3(glm::dvec3(out.vpls[v].power) * out.tailFactor);
  for (int j = from; j <= J; ++j) out.powerPerBounce[j] *= out.tailFactor;
}

VplSet generateVpls(const Scene& scene, const RayTracer& rt, const WalkOptions& options) {
  VplSet out;
  if (options.paths <= 0) throw Error(ErrorCode::Usage, "", "the walk needs at least one path (--vpls)");
  LightSources sources = collectLightSources(scene);
  out.lightReach = weighByReach(scene, rt, sources, options.seed);
  out.emittedPower = sources.totalPower;
  const double rho = meanReflectivity(scene);
  out.meanReflectivity = rho;
  if (sources.all.empty() || channelMean(sources.totalPower) <= 0.0) return out;

  // Surviving path counts M_j (fractional absorption) and the deepest bounce.
  const int walkFactor = std::max(1, options.walkFactor);
  const uint64_t N = static_cast<uint64_t>(options.paths) * static_cast<uint64_t>(walkFactor);
  const bool autoDepth = !options.maxBounces.has_value();
  const int cap = autoDepth ? autoBounceDepth(N, rho, options) : *options.maxBounces;
  std::vector<uint64_t> survivors{N};
  for (int j = 1; j <= cap; ++j) {
    const uint64_t m = survivorCount(N, rho, j);
    if (m == 0) break;
    survivors.push_back(m);
  }
  const int maxBounce = static_cast<int>(survivors.size()) - 1;
  const Halton halton(4 + 2 * std::max(maxBounce, 1), options.seed);

  std::vector<std::vector<Vpl>> perPath(N);
  auto walk = [&](int split, bool report) {
    std::atomic<uint64_t> done{0};
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, N, 64), [&](const tbb::blocked_range<uint64_t>& range) {
      for (uint64_t i = range.begin(); i != range.end(); ++i) {
        perPath[i].clear();
        const PathStart path = startPath(scene, rt, sources, halton, i, N, perPath[i]);
        followPath(scene, rt, halton, survivors, options.seed, i, split, path, perPath[i]);
        uint64_t d = ++done;
        if (report && options.progress && (d & 1023) == 0) options.progress("walk", static_cast<double>(d) / N);
      }
    });
  };
  if (options.progress) options.progress("walk", 0.0);
  int split = std::max(1, options.split.value_or(1));
  walk(split, options.split.has_value());
  if (!options.split.has_value() && maxBounce >= 2) {
    // Auto: how much of the light leaving bounce 1 meets the scene again, from the unsplit walk's counts
    // (V_2 / V_1 against M_2 / M_1). In a closed scene that is 1 and nothing changes; in an open one
    // (an open courtyard) the deeper bounces would rest on a few dozen VPLs, so paths split.
    size_t v1 = 0, v2 = 0;
    for (const auto& path : perPath)
      for (const Vpl& v : path) v1 += v.bounce == 1, v2 += v.bounce == 2;
    out.rehitFraction = v1 > 0 ? (static_cast<double>(v2) * static_cast<double>(survivors[1])) /
                                     (static_cast<double>(v1) * static_cast<double>(survivors[2]))
                               : 1.0;
    const int least = std::max(1, options.minAutoSplit);
    split = std::clamp(static_cast<int>(std::floor(1.0 / std::max(out.rehitFraction, 1e-6))), least,
                       std::max(least, options.maxAutoSplit));
    if (split > 1) walk(split, true);
  }
  out.split = split;
  orderByBounce(perPath, maxBounce, out);
  if (autoDepth && options.geometricTail && out.bounces >= 1) addGeometricTail(out);
  out.walked = out.vpls.size();
  if (walkFactor > 1) {
    // Bounce j keeps V_j / walkFactor VPLs (V_j: the walk's count there), past bounce 1 also divided by the
    // split and times evaluatedSplit: the counts a walk of `paths` would leave, escapes included; bounce 0
    // (the emitters') times evaluatedEmitterShare.
    std::vector<size_t> keep(out.countPerBounce.size());
    const double deep = static_cast<double>(std::clamp(options.evaluatedSplit, 1, split)) / split;
    const double emitter = std::clamp(options.evaluatedEmitterShare, 1e-6, 1.0);
    for (size_t j = 0; j < keep.size(); ++j) {
      const double share = j >= 2 ? deep : j == 0 ? emitter : 1.0;
      keep[j] = static_cast<size_t>(std::ceil(share * static_cast<double>(out.countPerBounce[j]) / walkFactor - 1e-9));
    }
    resampleVpls(out, keep, options.seed);
  }
  if (options.progress) options.progress("walk", 1.0);
  return out;
}

}  // namespace irbake
