// The cost model: each stage's CPU seconds as coefficients × features, the wall time over the cores.
#include "pipeline/cost_model.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "lights/light_kind.h"
#include "scene/triangle_area.h"
#include "stages/probes/light_probes.h"

namespace irbake {

CostCoefficients calibratedCostCoefficients() {
  CostCoefficients c;
  // fit_cost_model.py: begin
  c.loadPerTriangle = 2.5304e-07;
  c.atlasPerTriangle = 3.34184e-06;
  c.atlasPerPageTexel = 1.26379e-07;
  c.raytracePerTriangle = 1.4308e-06;
  c.texelsPerPageTexel = 1.05197e-06;
  c.texelsPerTriangle = 1.96366e-06;
  c.vplsPerPath = 1.31289e-05;
  c.importancePerTexelPath = 1.21357e-10;
  c.backendFixed = 0.847738;
  c.backendPerTexelPath = 8.55067e-10;
  c.backendPerLightTexel = 4.36667e-08;
  c.shadowEdgesPerLightRay = 9.51939e-10;
  c.skyPerRay = 1.17619e-07;
  c.compensationPerRay = 5.04334e-09;
  c.compensationPerTexel = 2.31682e-06;
  c.gatherPerRay = 6.56773e-08;
  c.gatherPerTexel = 2.13485e-06;
  c.postPerPageTexel = 1.82561e-08;
  c.probesPerRay = 2.99883e-06;
  c.probesPerProbeLight = 1.08171e-05;
  c.writePerPageTexel = 5.32289e-07;
  c.parallelShare = 0.85;
  c.memoryBaseMiB = 120.256;
  c.memoryPerTriangle = 0.000593771;
  c.memoryPerPageTexel = 0.000126465;
  c.memoryPerTexelPath = 0;
  // fit_cost_model.py: end
  return c;
}

nlohmann::json CostInputs::toJson() const {
  return {{"triangles", triangles},         {"texels", texels},
          {"pageTexels", pageTexels},       {"pages", pages},
          {"paths", paths},                 {"punctualLights", punctualLights},
          {"lightTexels", lightTexels},     {"skyRays", skyRays},
          {"compensationRays", compensationRays}, {"gatherRays", gatherRays},
          {"shadowEdgeRays", shadowEdgeRays}, {"probes", probes},
          {"probeRays", probeRays},         {"cores", cores}};
}

nlohmann::json CostPrediction::toJson() const {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, s] : perStage) stages[name] = s;
  return {{"seconds", seconds}, {"cpuSeconds", cpuSeconds}, {"memoryPeakMiB", memoryPeakMiB}, {"perStage", stages}};
}

CostPrediction predictCost(const CostInputs& in, const CostCoefficients& c) {
  const double texelPaths = in.texels * in.paths;
  std::map<std::string, double> cpu;
  cpu["load"] = c.loadPerTriangle * in.triangles;
  cpu["atlas"] = c.atlasPerTriangle * in.triangles + c.atlasPerPageTexel * in.pageTexels;
  cpu["raytrace"] = c.raytracePerTriangle * in.triangles;
  cpu["texels"] = c.texelsPerPageTexel * in.pageTexels + c.texelsPerTriangle * in.triangles;
  cpu["vpls"] = c.vplsPerPath * in.paths;
  if (in.gatherRays > 0.0) cpu["vplImportance"] = c.importancePerTexelPath * texelPaths;
  cpu["backend"] = c.backendFixed + c.backendPerTexelPath * texelPaths + c.backendPerLightTexel * in.lightTexels;
  if (in.shadowEdgeRays > 0.0 && in.punctualLights > 0.0)
    cpu["shadowEdges"] = c.shadowEdgesPerLightRay * in.lightTexels * in.shadowEdgeRays;
  if (in.skyRays > 0.0) cpu["sky"] = c.skyPerRay * in.skyRays;
  if (in.compensationRays > 0.0)
    cpu["compensation"] = c.compensationPerRay * in.compensationRays + c.compensationPerTexel * in.texels;
  if (in.gatherRays > 0.0) cpu["finalGather"] = c.gatherPerRay * in.gatherRays + c.gatherPerTexel * in.texels;
  cpu["post"] = c.postPerPageTexel * in.pageTexels;
  if (in.probes > 0.0)
    cpu["probes"] = c.probesPerRay * in.probes * in.probeRays + c.probesPerProbeLight * in.probes * in.punctualLights;
  cpu["write"] = c.writePerPageTexel * in.pageTexels;
  CostPrediction p;
  const double busyCores = std::max(1e-3, std::max(1.0, in.cores) * c.parallelShare);
  for (const auto& [stage, s] : cpu) {
    const double wall = std::max(0.0, s) / busyCores;
    p.perStage[stage] = wall;
    p.cpuSeconds += std::max(0.0, s);
    p.seconds += wall;
  }
  p.memoryPeakMiB = c.memoryBaseMiB + c.memoryPerTriangle * in.triangles + c.memoryPerPageTexel * in.pageTexels +
                    c.memoryPerTexelPath * texelPaths;
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

// Cubes about a third of the smallest range on a side, and never so small that a light's sphere spans more
// than a few thousand of them.
double gridCell(const Scene& scene) {
  double smallest = 0.0;
  for (const Light& l : scene.lights)
    if (l.range > 0.0f) smallest = smallest > 0.0 ? std::min(smallest, double(l.range)) : double(l.range);
  return smallest / 3.0;
}

}  // namespace

double lightTexelReach(const Scene& scene, const AtlasEstimate& atlas, bool reachOnly) {
  double sum = 0.0;
  bool anyRange = false;
  for (const Light& l : scene.lights) anyRange |= l.range > 0.0f;
  if (!reachOnly || !anyRange) return atlas.texels * double(scene.lights.size());
  AreaGrid grid;
  grid.cell = gridCell(scene);
  for (const Primitive& p : scene.primitives)
    for (size_t t = 0; t < p.triangleCount(); ++t) {
      const glm::dvec3 c = (glm::dvec3(p.positions[p.indices[3 * t]]) + glm::dvec3(p.positions[p.indices[3 * t + 1]]) +
                            glm::dvec3(p.positions[p.indices[3 * t + 2]])) / 3.0;
      grid.add(c, triangleArea(p, t));
    }
  const double perArea = atlas.texelsPerUnit * atlas.texelsPerUnit;
  for (const Light& l : scene.lights)
    sum += l.range > 0.0f && !lightKind(l.type).atInfinity() ? std::min(atlas.texels, grid.within(l.position, l.range) * perArea)
                                                            : atlas.texels;
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

CostInputs costInputs(const Scene& scene, const AtlasEstimate& atlas, const BakePlan& plan, double cores) {
  CostInputs in;
  in.triangles = double(scene.triangleCount());
  in.texels = atlas.texels;
  in.pageTexels = atlas.pageTexels;
  in.pages = atlas.pages;
  const bool vpls = plan.backend != BackendKind::Reference && plan.eval.includeVpls;
  in.paths = vpls ? double(plan.walk.paths) : 0.0;
  in.punctualLights = double(scene.lights.size());
  in.lightTexels = lightTexelReach(scene, atlas, calibratedCostCoefficients().cullsByReach);
  if (scene.environment.present()) in.skyRays = stageRays(in.texels, plan.sky.raysPerSample, plan.sky.minRays, plan.sky.maxRays);
  if (plan.compensate)
    in.compensationRays = stageRays(in.texels, plan.compensation.rays, plan.compensation.minRays, double(plan.compensation.rayBudget));
  if (plan.finalGather) in.gatherRays = stageRays(in.texels, plan.gather.rays, plan.gather.minRays, double(plan.gather.rayBudget));
  if (plan.shadowEdges.subSamples > 1) in.shadowEdgeRays = double(plan.shadowEdges.subSamples) * plan.shadowEdges.subSamples;
  if (plan.probes.enabled && plan.probes.spacing && plan.probes.box) {
    in.probes = probeCountOver(*plan.probes.box, *plan.probes.spacing);
    in.probeRays = plan.probes.rays;
  }
  in.cores = cores;
  return in;
}

}  // namespace irbake
