// The cost model: each stage's CPU seconds as coefficients × features, the wall time over the cores.
#include "pipeline/cost_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "lights/light_kind.h"
#include "scene/triangle_area.h"
#include "stages/probes/light_probes.h"

namespace irbake {

CostCoefficients calibratedCostCoefficients() {
  CostCoefficients c;
  // fit_cost_model.py: begin
  c.loadPerTriangle = 1.11875e-07;
  c.loadPerTexturePixel = 8.98698e-08;
  c.atlasPerTriangle = 1.40788e-07;
  c.atlasPerPageTexel = 1.12095e-07;
  c.raytracePerTriangle = 8.84959e-07;
  c.texelsPerPageTexel = 4.73033e-07;
  c.texelsPerTracedPageTexel = 0;
  c.texelsPerTriangle = 0;
  c.vplsPerPath = 9.13896e-06;
  c.importancePerTexelPath = 2.92133e-11;
  c.backendFixed = 0.333565;
  c.backendGlFixed = 0;
  c.backendPerTexelPath = 4.41665e-10;
  c.backendGlPerTexelPath = 1.65506e-09;
  c.backendPerLightTexel = 4.86582e-07;
  c.shadowEdgesPerLightRay = 7.91478e-09;
  c.skyPerRay = 1.08638e-07;
  c.compensationPerRay = 5.09548e-07;
  c.compensationPerTexel = 2.49167e-07;
  c.gatherPerRay = 1.03432e-07;
  c.gatherPerTexel = 1.39966e-06;
  c.postPerPageTexel = 1.36217e-08;
  c.probesPerRay = 3.05638e-06;
  c.probesPerProbeLight = 3.78355e-06;
  c.writeFixed = 0.244748;
  c.writePerPageTexel = 1.03531e-07;
  c.parallelShare = 0.934588;
  c.rayCostExponent = 1.5;
  c.memoryBaseMiB = 23.1663;
  c.memoryGlContextMiB = 78.8951;
  c.memoryPerTriangle = 0.00053848;
  c.memoryPerTexturePixel = 0.000124247;
  c.memoryPerTexel = 0.000231364;
  c.memoryPerTexelPath = 0;
  c.memoryPerPageTexel = 0;
  // fit_cost_model.py: end
  return c;
}

nlohmann::json CostInputs::toJson() const {
  return {{"triangles", triangles},         {"texels", texels},
          {"pageTexels", pageTexels},       {"pages", pages},
          {"texturePixels", texturePixels},
          {"paths", paths},                 {"punctualLights", punctualLights},
          {"lightTexels", lightTexels},     {"skyRays", skyRays},
          {"compensationRays", compensationRays}, {"gatherRays", gatherRays},
          {"shadowEdgeRays", shadowEdgeRays}, {"probes", probes},
          {"probeRays", probeRays},         {"probeLights", probeLights},
          {"cores", cores},                 {"rayCost", rayCost},
          {"pilotHitFraction", pilotHitFraction}, {"glBackend", glBackend}};
}

nlohmann::json CostPrediction::toJson() const {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, s] : perStage) stages[name] = s;
  return {{"seconds", seconds}, {"cpuSeconds", cpuSeconds}, {"memoryPeakMiB", memoryPeakMiB}, {"perStage", stages}};
}

CostPrediction predictCost(const CostInputs& in, const CostCoefficients& c) {
  const double texelPaths = in.texels * in.paths, gl = in.glBackend;
  const double traced = std::pow(std::max(0.0, in.rayCost), c.rayCostExponent);
  std::map<std::string, double> cpu;
  cpu["load"] = c.loadPerTriangle * in.triangles + c.loadPerTexturePixel * in.texturePixels;
  cpu["atlas"] = c.atlasPerTriangle * in.triangles + c.atlasPerPageTexel * in.pageTexels;
  cpu["raytrace"] = c.raytracePerTriangle * in.triangles;
  cpu["texels"] = (c.texelsPerPageTexel + c.texelsPerTracedPageTexel * traced) * in.pageTexels +
                  c.texelsPerTriangle * in.triangles;
  cpu["vpls"] = c.vplsPerPath * in.paths;
  if (in.gatherRays > 0.0) cpu["vplImportance"] = c.importancePerTexelPath * texelPaths;
  cpu["backend"] = c.backendFixed + c.backendGlFixed * gl +
                   (c.backendPerTexelPath * (1.0 - gl) + c.backendGlPerTexelPath * gl) * texelPaths +
                   c.backendPerLightTexel * in.lightTexels;  // short shadow rays, unlike the pilot's
  if (in.shadowEdgeRays > 0.0 && in.punctualLights > 0.0)
    cpu["shadowEdges"] = c.shadowEdgesPerLightRay * in.lightTexels * in.shadowEdgeRays;
  if (in.skyRays > 0.0) cpu["sky"] = c.skyPerRay * in.skyRays * traced;
  if (in.compensationRays > 0.0)
    cpu["compensation"] = c.compensationPerRay * in.compensationRays * traced + c.compensationPerTexel * in.texels;
  if (in.gatherRays > 0.0) cpu["finalGather"] = c.gatherPerRay * in.gatherRays * traced + c.gatherPerTexel * in.texels;
  cpu["post"] = c.postPerPageTexel * in.pageTexels;
  if (in.probes > 0.0)
    cpu["probes"] = (c.probesPerRay * in.probes * in.probeRays + c.probesPerProbeLight * in.probeLights) * traced;
  cpu["write"] = c.writeFixed + c.writePerPageTexel * in.pageTexels;
  CostPrediction p;
  const double busyCores = std::max(1e-3, std::max(1.0, in.cores) * c.parallelShare);
  for (const auto& [stage, s] : cpu) {
    const double wall = std::max(0.0, s) / busyCores;
    p.perStage[stage] = wall;
    p.cpuSeconds += std::max(0.0, s);
    p.seconds += wall;
  }
  p.memoryPeakMiB = c.memoryBaseMiB + c.memoryGlContextMiB * gl + c.memoryPerTriangle * in.triangles +
                    c.memoryPerTexturePixel * in.texturePixels + c.memoryPerTexel * in.texels +
                    c.memoryPerPageTexel * in.pageTexels + c.memoryPerTexelPath * texelPaths;
  return p;
}

namespace {

// Surface area binned by triangle centroid into cubes of one edge, each cube's area at its area-weighted
// centroid: the area within a sphere is the cubes' whose centroid lies in it.
struct AreaGrid {
  struct Cell {
    double area = 0.0;
    glm::dvec3 weighted{0.0};  // sum of area × centroid
  };
  double cell = 1.0;
  std::unordered_map<uint64_t, Cell> cells;
  static uint64_t key(long x, long y, long z) {
    const uint64_t m = (1u << 21) - 1;
    return (uint64_t(x) & m) | ((uint64_t(y) & m) << 21) | ((uint64_t(z) & m) << 42);
  }
  long index(double v) const { return long(std::floor(v / cell)); }
  void add(const glm::dvec3& centroid, double area) {
    Cell& c = cells[key(index(centroid.x), index(centroid.y), index(centroid.z))];
    c.area += area;
    c.weighted += area * centroid;
  }
  double within(const glm::vec3& centre, double radius) const {
    const long r = long(std::ceil(radius / cell)) + 1;
    const long cx = index(centre.x), cy = index(centre.y), cz = index(centre.z);
    double sum = 0.0;
    for (long x = cx - r; x <= cx + r; ++x)
      for (long y = cy - r; y <= cy + r; ++y)
        for (long z = cz - r; z <= cz + r; ++z) {
          const auto it = cells.find(key(x, y, z));
          if (it == cells.end() || !(it->second.area > 0.0)) continue;
          if (glm::length(it->second.weighted / it->second.area - glm::dvec3(centre)) <= radius) sum += it->second.area;
        }
    return sum;
  }
};

// Cubes about a third of the smallest finite reach on a side, and never so small that the largest finite reach
// spans more than about 24 of them (a few ten thousand cubes per light); 0 where no light has a finite reach.
double gridCell(const LightReach& reach) {
  double smallest = 0.0, largest = 0.0;
  for (float r : reach.reach)
    if (std::isfinite(r) && r > 0.0f) {
      smallest = smallest > 0.0 ? std::min(smallest, double(r)) : double(r);
      largest = std::max(largest, double(r));
    }
  return std::max(smallest / 3.0, largest / 12.0);
}

}  // namespace

double lightTexelReach(const Scene& scene, const AtlasEstimate& atlas, const LightReach* reach) {
  const double cell = reach ? gridCell(*reach) : 0.0;
  if (!(cell > 0.0)) return atlas.texels * double(scene.lights.size());
  AreaGrid grid;
  grid.cell = cell;
  for (const Primitive& p : scene.primitives) {
    if (!p.getsLightmap()) continue;  // the texels the atlas estimate counts: mapped objects at their scale
    const double scale2 = double(p.lightmapScale) * p.lightmapScale;
    for (size_t t = 0; t < p.triangleCount(); ++t) {
      const glm::dvec3 c = (glm::dvec3(p.positions[p.indices[3 * t]]) + glm::dvec3(p.positions[p.indices[3 * t + 1]]) +
                            glm::dvec3(p.positions[p.indices[3 * t + 2]])) / 3.0;
      grid.add(c, triangleArea(p, t) * scale2);
    }
  }
  const double perArea = atlas.texelsPerUnit * atlas.texelsPerUnit;
  double sum = 0.0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const float r = i < reach->reach.size() ? reach->reach[i] : std::numeric_limits<float>::infinity();
    sum += std::isfinite(r) ? std::min(atlas.texels, grid.within(scene.lights[i].position, r) * perArea) : atlas.texels;
  }
  return sum;
}

double probeLightReach(const Scene& scene, const Bounds3& box, float spacing, const LightReach* reach) {
  const glm::dvec3 extent = glm::dvec3(box.max) - glm::dvec3(box.min), centre = 0.5 * (glm::dvec3(box.max) + glm::dvec3(box.min));
  const double s = spacing;
  glm::dvec3 counts, origin;
  for (int a = 0; a < 3; ++a) {
    counts[a] = std::max(1.0, std::ceil(extent[a] / s - 1e-6));
    origin[a] = centre[a] - 0.5 * s * (counts[a] - 1.0);
  }
  const double all = counts.x * counts.y * counts.z;
  // The lattice indices along axis a within [lo, hi].
  const auto span = [&](int a, double lo, double hi) {
    const double first = std::max(0.0, std::ceil((lo - origin[a]) / s)), last = std::min(counts[a] - 1.0, std::floor((hi - origin[a]) / s));
    return std::make_pair(first, last);
  };
  double sum = 0.0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const float r = reach && i < reach->reach.size() ? reach->reach[i] : std::numeric_limits<float>::infinity();
    if (!std::isfinite(r)) {
      sum += all;
      continue;
    }
    const glm::dvec3 p = scene.lights[i].position;
    const double R = double(r) + 0.5 * std::sqrt(3.0) * s;  // the probe's cell meets the sphere
    const auto [x0, x1] = span(0, p.x - R, p.x + R);
    const auto [z0, z1] = span(2, p.z - R, p.z + R);
    for (double ix = x0; ix <= x1; ++ix)
      for (double iz = z0; iz <= z1; ++iz) {
        const double dx = origin.x + s * ix - p.x, dz = origin.z + s * iz - p.z, h2 = R * R - dx * dx - dz * dz;
        if (h2 < 0.0) continue;
        const auto [y0, y1] = span(1, p.y - std::sqrt(h2), p.y + std::sqrt(h2));
        sum += std::max(0.0, y1 - y0 + 1.0);
      }
  }
  return sum;
}

namespace {
// The rays a stage traces over `samples` texel samples: `rays` each, fewer within `budget` (0: none), never
// fewer than `minRays` each.
double stageRays(double samples, int rays, int minRays, double budget) {
  double each = rays;
  if (budget > 0.0 && samples > 0.0) each = std::min(each, budget / samples);
  return samples * std::max(double(minRays), each);
}
}  // namespace

CostInputs costInputs(const Scene& scene, const AtlasEstimate& atlas, const BakePlan& plan, const LightCullOptions& cull,
                      double cores) {
  CostInputs in;
  in.triangles = double(scene.triangleCount());
  in.texels = atlas.texels;
  in.pageTexels = atlas.pageTexels;
  in.pages = atlas.pages;
  const bool vpls = plan.backend != BackendKind::Reference && plan.eval.includeVpls;
  in.paths = vpls ? double(plan.walk.paths) : 0.0;
  in.punctualLights = double(scene.lights.size());
  for (const Texture& t : scene.textures) in.texturePixels += double(t.width) * double(t.height);
  LightReach settled;
  const LightReach* reach = nullptr;  // null: every light everywhere
  if (calibratedCostCoefficients().cullsByReach) {
    settled = settleLightReach(scene, scene.bounds(), cull);  // as the bake settles it
    reach = &settled;
  }
  in.lightTexels = lightTexelReach(scene, atlas, reach);
  if (scene.environment.present()) in.skyRays = stageRays(in.texels, plan.sky.raysPerSample, plan.sky.minRays, plan.sky.maxRays);
  if (plan.compensate)
    in.compensationRays = stageRays(in.texels, plan.compensation.rays, plan.compensation.minRays, double(plan.compensation.rayBudget));
  if (plan.finalGather) in.gatherRays = stageRays(in.texels, plan.gather.rays, plan.gather.minRays, double(plan.gather.rayBudget));
  if (plan.shadowEdges.subSamples > 1) in.shadowEdgeRays = double(plan.shadowEdges.subSamples) * plan.shadowEdges.subSamples;
  if (plan.probes.enabled && plan.probes.spacing && plan.probes.box) {
    in.probes = probeCountOver(*plan.probes.box, *plan.probes.spacing);
    in.probeRays = plan.probes.rays;
    in.probeLights = probeLightReach(scene, *plan.probes.box, *plan.probes.spacing, reach);
  }
  in.cores = cores;
  in.glBackend = plan.backend == BackendKind::Gl ? 1.0 : 0.0;
  return in;
}

}  // namespace irbake
