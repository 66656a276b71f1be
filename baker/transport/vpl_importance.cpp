#include "transport/vpl_importance.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>

#include "transport/geometry_term.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

struct Probe {
  glm::vec3 x, n;
};

double luminance(const glm::vec3& c) { return channelMean(glm::dvec3(c)); }

// Up to `count` probes drawn uniformly over the pages' weighted texel samples: a slot uniform over all slots,
// redrawn while it carries no weight (no list of the millions of weighted slots; a bounded number of draws).
std::vector<Probe> drawProbes(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                              int count, uint64_t seed) {
  std::vector<size_t> end;  // running slot count after each page
  for (const TexelSamples& ts : pages) end.push_back((end.empty() ? 0 : end.back()) + ts.positionWeight.size());
  std::vector<Probe> probes;
  if (end.empty() || end.back() == 0 || count <= 0) return probes;
  Rng rng(hashSeed(seed, 0x1e5c7ull));
  for (size_t draws = 0; probes.size() < static_cast<size_t>(count) && draws < 64 * static_cast<size_t>(count); ++draws) {
    const size_t global = std::min(end.back() - 1, static_cast<size_t>(rng.uniform() * double(end.back())));
    const size_t p = static_cast<size_t>(std::upper_bound(end.begin(), end.end(), global) - end.begin());
    const TexelSamples& ts = pages[p];
    const size_t s = global - (p == 0 ? 0 : end[p - 1]);
    if (!(ts.positionWeight[s].w > 0.0f)) continue;
    glm::vec3 x(ts.positionWeight[s]);
    if (s < ts.primitive.size() && ts.primitive[s] < scene.primitives.size())
      x = rt.insetPoint(ts.primitive[s], ts.triangle[s], x);
    probes.push_back({x, glm::vec3(ts.normal[s])});
  }
  return probes;
}

}  // namespace

double vplImportanceEvenness(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                             const std::vector<Vpl>& vpls, const VplImportanceOptions& options, float clampBound,
                             uint64_t seed) {
  size_t lit = 0;
  const std::vector<double> importance =
      measureVplImportance(scene, rt, pages, vpls, options, options.pilotProbes, clampBound, seed, &lit);
  double sum = 0.0, squares = 0.0;
  for (double i : importance) {
    sum += i;
    squares += i * i;
  }
  return lit > 0 && squares > 0.0 ? sum * sum / (double(importance.size()) * squares) : 1.0;
}

double chooseCandidateFactor(const VplImportanceOptions& options, size_t plainVpls, double evenness) {
  if (options.candidateFactor) return std::max(1.0, *options.candidateFactor);
  if (plainVpls == 0 || options.probes <= 0 || evenness > options.maxEvenness) return 1.0;
  const double f = std::floor(options.pairBudget / (double(options.probes) * double(plainVpls)));
  return f < 2.0 ? 1.0 : std::min(f, std::max(1.0, options.maxFactor));
}

std::vector<double> measureVplImportance(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                                         const std::vector<Vpl>& vpls, const VplImportanceOptions& options,
                                         int probeCount, float clampBound, uint64_t seed, size_t* litProbes) {
  std::vector<double> importance(vpls.size(), 0.0);
  if (litProbes) *litProbes = 0;
  const std::vector<Probe> probes = drawProbes(scene, rt, pages, probeCount, seed);
  if (probes.empty() || vpls.empty()) return importance;
  // Each probe's visible candidates and their (clamped) contributions, and its total: direct light + all
  // candidates.
  std::vector<std::vector<std::pair<uint32_t, float>>> seen(probes.size());
  std::vector<double> total(probes.size(), 0.0);
  tbb::parallel_for(size_t(0), probes.size(), [&](size_t t) {
    const Probe& pr = probes[t];
    double sum = 0.0;
    for (const Light& l : scene.lights) {
      const PunctualContribution c = punctualDirect(l, pr.x, pr.n);
      if (c.mapValue == glm::vec3(0.0f)) continue;
      const float tmax = std::isinf(c.distance) ? 1e30f : c.distance - rt.epsilon();
      if (tmax > 0.0f && rt.occluded(pr.x + pr.n * rt.epsilon(), c.toLight, 0.0f, tmax)) continue;
      sum += luminance(c.mapValue);
    }
    if (scene.environment.present() && options.skyRays > 0) {  // irradiance/π of the sky, cosine rays
      Rng sky(hashSeed(seed, 0x5c7ull, t));
      const glm::vec3 origin = pr.x + pr.n * rt.epsilon();
      double s = 0.0;
      for (int i = 0; i < options.skyRays; ++i) {
        const glm::vec3 dir = cosineHemisphere(pr.n, sky.uniform(), sky.uniform());
        if (!rt.occluded(origin, dir, 0.0f, 1e30f)) s += luminance(scene.environment.radiance(dir));
      }
      sum += s / options.skyRays;  // E/π = mean of L over cosine rays
    }
    constexpr size_t kBatch = 64;
    ShadowRay rays[kBatch];
    uint32_t which[kBatch];
    float value[kBatch];
    uint8_t blocked[kBatch];
    size_t count = 0;
    auto flush = [&]() {
      rt.occludedPackets(rays, count, blocked);
      for (size_t i = 0; i < count; ++i)
        if (!blocked[i]) {
          seen[t].emplace_back(which[i], value[i]);
          sum += value[i];
        }
      count = 0;
    };
    for (size_t v = 0; v < vpls.size(); ++v) {
      const float g = vplGeometryTerm(pr.x, pr.n, vpls[v].position, vpls[v].normal);
      if (g <= 0.0f) continue;
      const float c = static_cast<float>(luminance(vplMapValue(vpls[v].power, clampGeometryTerm(g, clampBound))));
      if (!(c > 0.0f)) continue;
      if (!rt.visibilityRay(pr.x, pr.n, vpls[v].position, vpls[v].normal, rays[count])) {
        seen[t].emplace_back(static_cast<uint32_t>(v), c);
        sum += c;
        continue;
      }
      which[count] = static_cast<uint32_t>(v);
      value[count++] = c;
      if (count == kBatch) flush();
    }
    if (count) flush();
    total[t] = sum;
  });
  std::vector<double> positive;
  for (double e : total)
    if (e > 0.0) positive.push_back(e);
  if (litProbes) *litProbes = positive.size();
  if (positive.empty()) return importance;
  std::nth_element(positive.begin(), positive.begin() + positive.size() / 2, positive.end());
  const double floor = options.floorFraction * positive[positive.size() / 2];
  // I_v = √(Σ_t (c_vt / E_t)²): with p_v ∝ I_v the kept set's Σ_t Var_t / E_t² (the relative variances the
  // probes see, Horvitz–Thompson: Σ_v (c_vt/E_t)² (1/p_v − 1)) is least for its expected count.
  for (size_t t = 0; t < probes.size(); ++t) {
    const double inv = 1.0 / std::max(total[t], floor);
    for (const auto& [v, c] : seen[t]) importance[v] += (c * inv) * (c * inv);
  }
  for (double& i : importance) i = std::sqrt(i);
  return importance;
}

void selectVplsByImportance(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                            VplSet& set, const VplImportanceOptions& options, const VplSelection& selection,
                            VplImportanceStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  VplImportanceStats unused;
  VplImportanceStats& st = stats ? *stats : unused;  // only the selection's own fields are written
  std::vector<Vpl>& vpls = set.vpls;
  st.candidates = vpls.size();
  st.kept = vpls.size();
  if (vpls.empty() || !(selection.keepFraction < 1.0)) return;
  st.probes = static_cast<size_t>(std::max(0, options.probes));
  const std::vector<double> importance = measureVplImportance(scene, rt, pages, vpls, options, options.probes,
                                                              selection.clampBound, selection.seed, &st.litProbes);
  if (st.litProbes == 0) return;
  // I* such that the expected kept count is keepFraction of the candidates.
  const double target = selection.keepFraction * static_cast<double>(vpls.size());
  const double pMin = std::clamp(selection.keepFraction / std::max(1.0, options.maxBoost), 1e-9, 1.0);
  auto expected = [&](double iStar) {
    double sum = 0.0;
    for (double i : importance) sum += std::clamp(i / iStar, pMin, 1.0);
    return sum;
  };
  double lo = 1e-30, hi = std::max(1e-30, *std::max_element(importance.begin(), importance.end())) / pMin;
  for (int it = 0; it < 200 && hi / lo > 1.0 + 1e-9; ++it) {
    const double mid = std::sqrt(lo * hi);
    (expected(mid) > target ? lo : hi) = mid;
  }
  const double iStar = hi;
  // Systematic sampling per bounce (the candidates of a bounce are contiguous, in the walk's quasi-random
  // order): one uniform offset, and candidate v is kept where the running sum of p crosses an integer. The
  // kept count is Σp within one and the picks stay spread like the walk's. Each kept VPL carries Φ/p, and
  // then each bounce's kept power is scaled to the candidates' own (per channel): the walk's exact power
  // bookkeeping survives the thinning, so the emitters' light (bounce 0) does not move with the draw.
  std::vector<Vpl> kept;
  kept.reserve(static_cast<size_t>(selection.keepFraction * double(vpls.size()) * 1.2) + 16);
  for (size_t begin = 0; begin < vpls.size();) {
    size_t end = begin;
    while (end < vpls.size() && vpls[end].bounce == vpls[begin].bounce) ++end;
    Rng r(hashSeed(selection.seed, 0x5e1ec7ull, static_cast<uint64_t>(vpls[begin].bounce)));
    double running = r.uniform();
    glm::dvec3 candidatePower(0.0), keptPower(0.0);
    const size_t first = kept.size();
    for (size_t v = begin; v < end; ++v) {
      candidatePower += glm::dvec3(vpls[v].power);
      const double p = std::clamp(importance[v] / iStar, pMin, 1.0);
      const double before = std::floor(running);
      running += p;
      if (std::floor(running) == before) continue;
      Vpl k = vpls[v];
      k.power = glm::vec3(glm::dvec3(k.power) / p);
      keptPower += glm::dvec3(k.power);
      kept.push_back(k);
    }
    for (int c = 0; c < 3; ++c) {
      const double scale = keptPower[c] > 0.0 ? candidatePower[c] / keptPower[c] : 0.0;
      for (size_t k = first; k < kept.size(); ++k) kept[k].power[c] = static_cast<float>(kept[k].power[c] * scale);
    }
    begin = end;
  }
  vpls.swap(kept);
  std::fill(set.countPerBounce.begin(), set.countPerBounce.end(), size_t(0));
  std::fill(set.powerPerBounce.begin(), set.powerPerBounce.end(), glm::dvec3(0.0));
  for (const Vpl& v : vpls) {
    const size_t b = static_cast<size_t>(v.bounce);
    if (b >= set.countPerBounce.size()) set.countPerBounce.resize(b + 1, 0);
    if (b >= set.powerPerBounce.size()) set.powerPerBounce.resize(b + 1, glm::dvec3(0.0));
    ++set.countPerBounce[b];
    set.powerPerBounce[b] += glm::dvec3(v.power);
  }
  st.kept = vpls.size();
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace irbake
