// Path-traced reference. In map units (irradiance / π) the recursion with cosine sampling is simply
//   M(x) ≈ L(y → x) = Le(y) + ρ(y) · M(y),
// since E(x) = ∫ L cosθ dω is estimated by π L for pdf cosθ / π. Emitted radiance is gathered twice,
// by light sampling and by hemisphere hits, and weighted with the power heuristic.
#include "evaluators/reference/reference_integrator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "transport/geometry_term.h"
#include "common/error.h"
#include "common/maths.h"

namespace irbake {

namespace {

glm::vec3 punctualAt(const Scene& scene, const RayTracer& rt, const glm::vec3& origin, const glm::vec3& x,
                     const glm::vec3& n) {
  glm::vec3 sum(0.0f);
  for (const Light& l : scene.lights) {
    PunctualContribution c = punctualDirect(l, x, n);
    if (c.mapValue == glm::vec3(0.0f)) continue;
    float tmax = shadowRayLength(c, rt.epsilon());
    if (tmax > 0.0f && rt.occluded(origin, c.toLight, 0.0f, tmax)) continue;
    sum += tmax > 0.0f ? c.mapValue * rt.transmittance(origin, c.toLight, 0.0f, tmax) : c.mapValue;
  }
  return sum;
}

double powerHeuristic(double a, double b) { return a * a / (a * a + b * b); }
}  // namespace

glm::vec3 referencePathSample(const Scene& scene, const RayTracer& rt, const LightSources& lights, const glm::vec3& x0,
                              const glm::vec3& n0, Rng& rng, const ReferenceOptions& options) {
  glm::dvec3 value(0.0), beta(1.0);
  glm::vec3 x = x0, n = n0;
  glm::vec3 origin = x0 + n0 * rt.epsilon();  // texel samples carry no triangle inset
  const bool haveEmitters = !lights.areaOnly.empty() && lights.areaOnly.total() > 0.0;
  for (int depth = 0; depth <= options.maxDepth; ++depth) {
    // Punctual lights: exact.
    value += beta * glm::dvec3(punctualAt(scene, rt, origin, x, n));
    // Area emitters by power, MIS-weighted against the hemisphere sample below.
    if (haveEmitters) {
      size_t k = lights.areaOnly.sample(rng.uniform());
      const EmitterTriangle& e = lights.triangles[k];
      const Primitive& prim = scene.primitives[e.primitive];
      glm::vec2 b = uniformTriangle(rng.uniform(), rng.uniform());
      const uint32_t* idx = &prim.indices[3 * e.triangle];
      glm::vec3 y = prim.positions[idx[0]] * (1.0f - b.x - b.y) + prim.positions[idx[1]] * b.x + prim.positions[idx[2]] * b.y;
      glm::vec3 d = y - x;
      float r2 = glm::dot(d, d);
      if (r2 > 0.0f) {
        float r = std::sqrt(r2);
        glm::vec3 w = d / r;
        float cosX = glm::dot(n, w), cosY = -glm::dot(e.normal, w);
        ShadowRay ray;
        const bool clear = !rt.visibilityRay(x, n, y, e.normal, ray) || !rt.occluded(ray.origin, ray.dir, 0.0f, ray.tmax);
        if (cosX > 0.0f && cosY > 0.0f && clear) {
          double pdfLight = lights.areaOnly.pdf(k) / e.area * r2 / cosY;  // solid angle
          double pdfHemi = cosX / kPi;
          glm::dvec3 Le(scene.emissionAt(prim, e.triangle, b));
          if (rt.hasTransmission() && ray.tmax > 0.0f) Le *= glm::dvec3(rt.transmittance(ray.origin, ray.dir, 0.0f, ray.tmax));
          value += beta * Le * (cosX / (kPi * pdfLight) * powerHeuristic(pdfLight, pdfHemi));
        }
      }
    }
    // Hemisphere sample: emission found here is MIS-weighted; reflection continues the path.
    glm::vec3 dir = cosineHemisphere(n, rng.uniform(), rng.uniform());
    RayHit hit = rt.intersect(origin, dir, 0.0f, 1e30f);
    if (!hit.hit) {  // escaped: the sky, found by the hemisphere sample alone (no sky sampling here)
      if (scene.environment.present()) value += beta * glm::dvec3(scene.environment.radiance(dir));
      break;
    }
    // A see-through surface: with probability `fraction` the path goes straight on, tinted (the hemisphere
    // direction is kept, so emission and the sky behind it are found as before); else it meets the
    // surface's Lambertian part below.
    glm::vec3 straightOrigin;
    while (hit.hit) {
      const SurfaceTransmission transmission = scene.transmissionAt(scene.primitives[hit.primitive], hit.triangle, hit.barycentric);
      if (transmission.fraction <= 0.0f || rng.uniform() >= transmission.fraction) break;
      beta *= glm::dvec3(transmission.tint);
      straightOrigin = hit.position + dir * rt.epsilon();
      hit = rt.intersect(straightOrigin, dir, 0.0f, 1e30f);
    }
    if (!hit.hit) {
      if (scene.environment.present()) value += beta * glm::dvec3(scene.environment.radiance(dir));
      break;
    }
    const Primitive& hitPrim = scene.primitives[hit.primitive];
    if (!hit.backFace && scene.materials[hitPrim.material].isEmissive()) {
      glm::dvec3 Le(scene.emissionAt(hitPrim, hit.triangle, hit.barycentric));
      double weight = 1.0;
      if (haveEmitters) {
        double cosY = -glm::dot(hit.geometricNormal, dir);
        const double dist = glm::length(hit.position - x);  // through any see-through surfaces on the way
        double pdfLight = cosY > 0.0 ? lights.areaPdf(hit.primitive, hit.triangle) * dist * dist / cosY : 0.0;
        weight = powerHeuristic(glm::dot(n, dir) / kPi, pdfLight);
      }
      value += beta * Le * weight;
    }
    glm::dvec3 albedo(rt.albedoAt(hit));
    double q = std::min(0.95, std::max(albedo.x, std::max(albedo.y, albedo.z)));
    if (q <= 0.0) break;
    beta *= albedo;
    if (depth >= options.rouletteStart) {
      if (rng.uniform() >= q) break;
      beta /= q;
    }
    n = hit.backFace ? -hit.geometricNormal : hit.geometricNormal;
    x = rt.insetPoint(hit.primitive, hit.triangle, hit.position);
    origin = x + n * rt.epsilon();
  }
  return glm::vec3(value);
}

std::vector<Lightmap> bakeReference(const BakeInputs& in, const ReferenceOptions& options,
                                    std::vector<Lightmap>* standardError, const EvaluationRequest& request) {
  if (options.spp < 1) throw Error(ErrorCode::Usage, "", "the reference needs at least one path per sample (--spp)");
  if (request.directional)
    throw Error(ErrorCode::Usage, "", "the reference makes no L1 pages: directional maps need a VPL evaluator");
  const LightSources lights = collectLightSources(in.scene);
  std::vector<Lightmap> maps;
  if (standardError) standardError->clear();
  size_t totalSlots = 0, doneSlots = 0;
  for (const auto& t : in.texels) totalSlots += t.slotCount();
  std::atomic<size_t> progressSlots{0};

  for (size_t page = 0; page < in.texels.size(); ++page) {
    const TexelSamples& ts = in.texels[page];
    const size_t slots = ts.slotCount(), layer = ts.layerSize();
    const std::vector<uint8_t>* subset =
        request.texelSubset && page < request.texelSubset->size() ? &(*request.texelSubset)[page] : nullptr;
    auto wanted = [&](size_t t) { return !subset || (t < subset->size() && (*subset)[t] != 0); };
    std::vector<glm::dvec3> mean(slots, glm::dvec3(0.0)), varianceOfMean(slots, glm::dvec3(0.0));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, slots, 16), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t s = r.begin(); s != r.end(); ++s) {
        if (!(ts.positionWeight[s].w > 0.0f) || !wanted(s % layer)) continue;
        Rng rng(hashSeed(options.seed, static_cast<uint64_t>(ts.page), s));
        glm::vec3 x(ts.positionWeight[s]), n(ts.normal[s]);
        // Moved ε into its triangle: a sample snapped onto an edge would start paths on the plane of the
        // neighbouring face at concave corners.
        if (s < ts.primitive.size() && s < ts.triangle.size() && ts.primitive[s] < in.scene.primitives.size() &&
            ts.triangle[s] < in.scene.primitives[ts.primitive[s]].triangleCount())
          x = in.rayTracer.insetPoint(ts.primitive[s], ts.triangle[s], x);
        glm::dvec3 sum(0.0), sum2(0.0);
        for (int k = 0; k < options.spp; ++k) {
          glm::dvec3 v(referencePathSample(in.scene, in.rayTracer, lights, x, n, rng, options));
          sum += v;
          sum2 += v * v;
        }
        double N = options.spp;
        mean[s] = sum / N;
        if (options.spp > 1) varianceOfMean[s] = glm::max(glm::dvec3(0.0), (sum2 - sum * sum / N) / (N - 1.0)) / N;
      }
      size_t d = progressSlots.fetch_add(r.size()) + r.size();
      if (in.progress) in.progress("reference", static_cast<double>(doneSlots + d) / std::max<size_t>(1, totalSlots));
    });
    doneSlots += slots;
    progressSlots = 0;

    Lightmap map, err;
    map.page = err.page = ts.page;
    map.width = err.width = ts.width;
    map.height = err.height = ts.height;
    map.texels.assign(layer, glm::vec3(0.0f));
    err.texels.assign(layer, glm::vec3(0.0f));
    map.valid.assign(layer, 0);
    const int layers = ts.supersample * ts.supersample;
    for (size_t t = 0; t < layer; ++t) {
      if (!wanted(t)) continue;
      glm::dvec3 value(0.0), var(0.0);
      double weight = 0.0;
      for (int l = 0; l < layers; ++l) {
        size_t s = static_cast<size_t>(l) * layer + t;
        double w = ts.positionWeight[s].w;
        if (!(w > 0.0)) continue;
        value += w * mean[s];
        var += w * w * varianceOfMean[s];
        weight += w;
      }
      bool valid = ts.valid.empty() ? weight > 0.0 : (ts.valid[t] != 0 && weight > 0.0);
      if (!valid) continue;
      value /= weight;
      var /= weight * weight;
      if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z))
        throw Error(ErrorCode::NumericError, in.scene.sourcePath,
                    "reference produced a non-finite value at page " + std::to_string(ts.page) + " texel " +
                        std::to_string(t % ts.width) + "," + std::to_string(t / ts.width));
      map.texels[t] = glm::vec3(value);
      map.valid[t] = 1;
      err.texels[t] = glm::vec3(glm::sqrt(var));
    }
    err.valid = map.valid;
    maps.push_back(std::move(map));
    if (standardError) standardError->push_back(std::move(err));
  }
  if (in.progress) in.progress("reference", 1.0);
  return maps;
}

std::vector<Lightmap> ReferenceEvaluator::evaluate(const BakeInputs& inputs, const EvaluationRequest& request) const {
  std::vector<Lightmap> standardError;
  std::vector<Lightmap> maps = bakeReference(inputs, options_, &standardError, request);
  double se = 0.0, value = 0.0;
  for (size_t p = 0; p < maps.size() && p < standardError.size(); ++p)
    for (size_t i = 0; i < maps[p].size() && i < standardError[p].size(); ++i) {
      if (i < maps[p].valid.size() && !maps[p].valid[i]) continue;
      se += channelMean(standardError[p].texels[i]);
      value += channelMean(maps[p].texels[i]);
    }
  relativeStandardError_ = value > 0.0 ? se / value : 0.0;
  return maps;
}

nlohmann::json ReferenceEvaluator::stats() const {
  return {{"spp", options_.spp}, {"relativeStandardError", relativeStandardError_}};
}

void ReferenceEvaluator::describe(nlohmann::json& report) const {
  report["reference"] = stats();  // its paths per sample and how converged it is
  report["eval"]["referenceSpp"] = options_.spp;
}

}  // namespace irbake
