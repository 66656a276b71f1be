// The bake's cost predicted before anything is traced: time per stage and peak memory from what the plan and
// the atlas estimate know (texels, triangles, paths, rays per stage, probes, the lights' reach) and the cores.
// One plain struct of coefficients, calibrated by bench/levels/fit_cost_model.py from measured bakes.
#pragma once
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "atlas/atlas_estimate.h"
#include "lights/light_reach.h"
#include "pipeline/bake_plan.h"
#include "scene/scene.h"

namespace irbake {

// What the cost depends on, as the plan and the atlas estimate predict it.
struct CostInputs {
  double triangles = 0.0;         // the scene's triangles
  double texels = 0.0;            // chart texels (the texels the stages shade)
  double pageTexels = 0.0;        // page texels (what the pages hold in memory)
  double pages = 0.0;             // pages
  double texturePixels = 0.0;     // the scene's decoded texture pixels (held as float RGBA)
  double paths = 0.0;             // light paths evaluated (0: no VPLs, as with the reference backend)
  double punctualLights = 0.0;    // point, spot and directional lights (the sun included)
  double lightTexels = 0.0;       // sum over punctual lights of the texels each one's direct term is computed for
  double skyRays = 0.0;           // the sky stage's rays (0: no sky)
  double compensationRays = 0.0;  // the clamp compensation's first-round rays (0: it does not run)
  double gatherRays = 0.0;        // the final gather's rays (0: it does not run)
  double shadowEdgeRays = 0.0;    // the shadow-edge stage's rays per light texel (S×S; 0: the stage is off)
  double probes = 0.0;            // irradiance probes (0: none)
  double probeRays = 0.0;         // lattice rays per probe
  double probeLights = 0.0;       // sum over punctual lights of the probes whose cell each one's reach meets
  double cores = 1.0;             // the cores the bake may use
  double rayCost = 1.0;           // the ray pilot's CPU time per ray here over its reference scene's (pipeline/ray_pilot.h)
  double pilotHitFraction = 0.0;  // the share of the ray pilot's rays that hit the scene
  double glBackend = 0.0;         // 1 where the GL evaluator sums the VPLs (its context; a software rasteriser), else 0
  nlohmann::json toJson() const;
};

// Each stage's CPU seconds are a sum of coefficient × feature; the wall time divides them over the cores. A
// "traced" count is multiplied by the ray pilot's rayCost to the power rayCostExponent: the coefficient is per
// ray of the pilot's reference scene.
struct CostCoefficients {
  double loadPerTriangle = 0.0;          // s per triangle: reading and decoding the scene
  double loadPerTexturePixel = 0.0;      // s per texture pixel: decoding the images
  double atlasPerTriangle = 0.0;         // s per triangle: charts and parameterisation
  double atlasPerPageTexel = 0.0;        // s per page texel: packing and rasterising the charts
  double raytracePerTriangle = 0.0;      // s per triangle: the BVH build
  double texelsPerPageTexel = 0.0;       // s per page texel: the texel samples
  double texelsPerTracedPageTexel = 0.0; // s per page texel, traced: their leak tests
  double texelsPerTriangle = 0.0;        // s per triangle: rasterising triangles into texels
  double vplsPerPath = 0.0;              // s per path: the walk
  double importancePerTexelPath = 0.0;   // s per texel × path: the importance pilot and selection (final gather only)
  double backendPerTexelPath = 0.0;      // s per texel × path: the VPL sums on the CPU (Embree) evaluator
  double backendGlPerTexelPath = 0.0;    // s per texel × path: the VPL sums on the GL evaluator (a software rasteriser)
  double backendPerLightTexel = 0.0;     // s per light texel: the punctual lights' direct term and shadows
  double backendFixed = 0.0;             // s: the evaluator's set-up
  double backendGlFixed = 0.0;           // s: the GL evaluator's context and programs, besides backendFixed
  double shadowEdgesPerLightRay = 0.0;   // s per light texel × S²: the edge texels' area-averaged visibility
  double skyPerRay = 0.0;                // s per sky ray, traced
  double compensationPerRay = 0.0;       // s per compensation ray, traced (the refinement and sweeps in proportion)
  double compensationPerTexel = 0.0;     // s per texel: the compensation's sweeps and filter
  double gatherPerRay = 0.0;             // s per final-gather ray, traced
  double gatherPerTexel = 0.0;           // s per texel: the gather's filter and its pre-pass map
  double postPerPageTexel = 0.0;         // s per page texel: dilation and seams
  double probesPerRay = 0.0;             // s per probe ray, traced (the volume fit in proportion)
  double probesPerProbeLight = 0.0;      // s per probe × punctual light reaching it, traced: its shadow rays and fit
  double writeFixed = 0.0;               // s: the process's start and exit, the plan, the glTF and the report
  double writePerPageTexel = 0.0;        // s per page texel: the EXR and PNG pages
  // The pilot's rays run warm in cache; the bake's stages stream texels and maps between rays, which evicts
  // the BVH, so a scene whose pilot rays cost twice as much costs more than twice as much per bake ray: its
  // traced counts are weighed by rayCost^rayCostExponent (1: in proportion).
  double rayCostExponent = 1.0;
  bool cullsByReach = true;              // the stages compute a light's direct term only within its reach
  double parallelShare = 1.0;            // the share of the cores the bake keeps busy on an idle machine
  double memoryBaseMiB = 0.0;            // MiB: the process, its libraries and the scene's fixed parts
  double memoryGlContextMiB = 0.0;       // MiB: the GL evaluator's context (the software rasteriser's buffers)
  double memoryPerTriangle = 0.0;        // MiB per triangle: the scene, its BVH and atlas meshes
  double memoryPerTexturePixel = 0.0;    // MiB per texture pixel: the decoded images
  double memoryPerTexel = 0.0;           // MiB per chart texel: texel samples, sums, maps and the gathers' copies
  double memoryPerPageTexel = 0.0;       // MiB per page texel: what is held for the whole page
  double memoryPerTexelPath = 0.0;       // MiB per texel × path: the walk's VPLs held beside the pages
};

// The coefficients fitted by bench/levels/fit_cost_model.py (its output, pasted).
CostCoefficients calibratedCostCoefficients();

struct CostPrediction {
  double seconds = 0.0;        // predicted wall time on an idle machine, every stage
  double cpuSeconds = 0.0;     // the CPU time behind it
  double memoryPeakMiB = 0.0;  // predicted peak resident memory
  std::map<std::string, double> perStage;  // wall seconds by the report's stage names (timings.seconds), and "write"
  // {"seconds", "cpuSeconds", "memoryPeakMiB", "perStage"}
  nlohmann::json toJson() const;
};

CostPrediction predictCost(const CostInputs& inputs, const CostCoefficients& c = calibratedCostCoefficients());

// The texels each punctual light's direct term is computed for, summed over the lights: the texels on surfaces
// within each light's reach (the surface area there × density²), as the bake's light grid settles it
// (lights/light_reach.h: the range, or the cut's distance for a light without range); every texel for a light
// that reaches everywhere, and for every light where `reach` is null (no culling).
double lightTexelReach(const Scene& scene, const AtlasEstimate& atlas, const LightReach* reach);

// The probes each punctual light's work is done for, summed over the lights: the probes of the grid over `box`
// at `spacing` (probeGridOver's lattice) whose cell a light's reach meets, every probe for a light that reaches
// everywhere, and for every light where `reach` is null.
double probeLightReach(const Scene& scene, const Bounds3& box, float spacing, const LightReach* reach);

// The inputs for a scene, its atlas estimate and plan, with the bake's light cull, on `cores` cores; rayCost 1 until
// the ray pilot weighs them (weighRays in bake_prediction.h).
CostInputs costInputs(const Scene& scene, const AtlasEstimate& atlas, const BakePlan& plan, const LightCullOptions& cull,
                      double cores);

}  // namespace irbake
