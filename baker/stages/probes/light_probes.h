// Irradiance probes for moving objects: a regular grid over the scene (or a box), each probe the light arriving
// there from every direction as L2 spherical harmonics (lightmap/probe_grid.h), from the same light as the maps:
//   punctual lights exact (their map value at normal incidence projected as a delta), times their visibility
//   fitted over the volume the probe blends (light_visibility_fit.h);
//   emitters kept for the clients' exact shading (exact_emitters.h) left out, their visibility stored instead;
//   the other emissive triangles by next-event estimation: K shadow rays to points picked by power, on a rotated 2D
//   Fibonacci lattice, each direction's Le projected with its solid-angle density p(ω) = p_A r²/cosθ_y (front
//   faces only);
//   every other direction by N rays on a rotated spherical Fibonacci lattice, c_k = (4π/N)(1/π) Σ L_i Y_k(ω_i):
//   a ray that escapes brings the sky's radiance, one that hits a front face the surface's outgoing radiance
//   ρ M read from the finished map (M = E/π, so ρ M is the radiance a Lambertian surface sends; docs/units.md)
//   plus its Le, one that hits a back face nothing.
// An emitter's Le is found by both: they are combined by the power heuristic (weights a²/(a² + b²), b²/(a² + b²)
// for the densities a = N/(4π), b = K p(ω)), so a small light (few lattice rays find it) comes from the shadow
// rays and a large emissive wall from the lattice, and nothing is counted twice.
// With volumeFitSamples, the lattice's and emitters' light is then fitted over the volume the clients blend, as
// the punctual lights' visibility is: S³ points in each probe's cube, each traced with fewer rays, kept where
// every probe of their blend sees them; least squares on the blend, each probe's own value one more sample
// (blend_fit.h).
// A probe whose rays meet back faces in more than maxBackFaceShare of the directions is inside geometry: moved
// through the nearest back face (at most half a spacing), else left invalid. Walls between a point and a probe
// are the reader's to test (interpolateProbes' visibility), so no light crosses them.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lights/light_kind.h"
#include "lightmap/lightmap.h"
#include "lightmap/lightmap_read.h"
#include "lightmap/probe_grid.h"

namespace irbake {

struct ProbeOptions {
  bool enabled = true;                // --probes off: no probes, no extension, nothing else changes
  std::optional<float> spacing;       // metres; unset: automatic (chooseProbeSpacing)
  double autoProbes = 1024;           // about this many probes at the automatic spacing, whatever the scale
  double autoProbesSun = 2048;        // with a directional light: its shadows are sharp and cross the whole
                                      // scene, and a blend of probes metres apart smears them (docs/validation.md,
                                      // "Probes against Cycles")
  std::optional<Bounds3> box;         // the volume the grid fills; unset: the scene's bounds
  int rays = 256;                     // lattice rays per probe (relative noise of a constant sky ≈ 1.28/√rays
                                      // for independent rays, far less on the lattice): with the volume fit, a
                                      // probe's own SH is one sample among its cube's, and its rays are better
                                      // spent there
  float maxBackFaceShare = 0.5f;      // above this share of back-face hits (double-sided surfaces have none) a
                                      // probe is inside geometry: "mostly back faces". A quarter, the share a
                                      // probe beside a wall of two coincident opposite quads meets (makeThinWall:
                                      // the ray finds either), would drop valid probes on the lit side
  size_t maxProbes = 1u << 20;        // a grid with more probes is refused (Error Usage: a spacing too small)
  size_t budget = 16384;              // a grid with more probes is refused before the bake unless this is raised
                                      // (--probe-budget): 8 times the automatic count with a sun, so a spacing
                                      // typed too small (--probes 0.01 over a level) is refused at once instead
                                      // of costing more than the bake (docs/validation.md, "Irradiance probes")
  int emitterSamples = 128;           // shadow rays per probe to the emissive triangles (0: the lattice alone)
  uint32_t seed = 0;                  // turns each probe's lattice and emitter samples
  int lightFitSamples = 4;            // S: the punctual lights' visibility fitted over S³ points per probe
                                      // (light_visibility_fit.h); 0: each probe's own shadow ray
  int volumeFitSamples = 4;           // S: the rest of the light fitted over S³ points per probe (blend_fit.h);
                                      // 0: each probe's own rays. A blend of point probes a spacing apart misses
                                      // light that changes within a cell, such as between a gallery's piers
                                      // (docs/validation.md, "Probes against Cycles")
  int volumeFitRays = 128;            // lattice rays per volume-fit point (emitter shadow rays in proportion):
                                      // more points with fewer rays each vary less over seeds than fewer points
                                      // with more rays (docs/validation.md, "Probes against Cycles")
  double volumeFitAnchor = 1.0;       // λ: the weight of each probe's own SH among its cube's samples
  float volumeFitClearance = 0.5f;    // a point is fitted only where an object's centre can be: at least this
                                      // many spacings from every surface
  int sunSubdivisions = 4;            // the strongest directional light's visibility on a lattice this many
                                      // times finer in the cells its shadow crosses (sun_level.h); 0: none
  float sunTolerance = 0.1f;          // refine a cell where that lattice and the probes' blend differ by more
  int exactEmitterTriangles = 64;     // emitters left out of the SH for the clients' exact shading, at most this
                                      // many triangles in all (exact_emitters.h); 0: every emitter in the SH
  int emitterVisibilitySamples = 64;  // shadow rays per probe to each exact emitter for its visibility
};

struct ProbeStats {
  size_t count = 0, valid = 0, moved = 0;
  float spacing = 0.0f;
  size_t rays = 0;  // lattice and shadow rays, relocation tests and the visibility fit's included
  size_t lightFitSamples = 0;  // volume samples the punctual lights' visibility was fitted to
  int lightFitSweeps = 0;      // the fit's Gauss–Seidel sweeps
  size_t volumeFitSamples = 0;  // volume samples the rest of the light was fitted to
  int volumeFitSweeps = 0;
  size_t sunCells = 0;  // cells of the sun level
  size_t sunRays = 0;   // its shadow rays (in `rays` too)
  size_t exactEmitters = 0, exactEmitterTriangles = 0;  // emitters shaded exactly by the clients
  size_t emitterVisibilityRays = 0;                     // their visibility's shadow rays (in `rays` too)
  double seconds = 0.0;
  nlohmann::json toJson() const {  // report "probes" (seconds: under "timings", as every stage's wall time)
    return {{"count", count}, {"valid", valid}, {"moved", moved}, {"spacing", spacing}, {"rays", rays},
            {"lightFitSamples", lightFitSamples}, {"lightFitSweeps", lightFitSweeps},
            {"volumeFitSamples", volumeFitSamples}, {"volumeFitSweeps", volumeFitSweeps},
            {"sunCells", sunCells}, {"sunRays", sunRays}, {"exactEmitters", exactEmitters},
            {"exactEmitterTriangles", exactEmitterTriangles}, {"emitterVisibilityRays", emitterVisibilityRays}};
  }
};

// The automatic spacing: about `probes` probes over the volume (autoProbeCount), cbrt(V / probes) with each side
// of V held to at least 1/16 of the longest (a flat scene keeps two layers), never below 1 cm. A fixed count
// follows the scene's scale and keeps the cost small beside the bake: the longest side / 16 gives a cube 16³ =
// 4096 probes, a large share of a small model's bake.
float chooseProbeSpacing(const Bounds3& volume, double probes);

// The automatic count: ProbeOptions::autoProbes, or autoProbesSun when the scene has a light at infinity (a sun).
inline double autoProbeCount(const ProbeOptions& o, const std::vector<Light>& lights) {
  for (const Light& l : lights)
    if (lightKind(l.type).atInfinity()) return o.autoProbesSun;
  return o.autoProbes;
}

// The number of probes the grid over `volume` at `spacing` holds (probeGridOver), in double: a true figure however
// small the spacing against the volume.
double probeCountOver(const Bounds3& volume, float spacing);

// The grid over `volume` at `spacing`: ceil(extent / spacing) probes per axis (at least 1), centred in the
// volume, so probes sit half a step in from its faces rather than on walls and floors at its border.
// Throws Error(Usage) when it would hold more than maxProbes, or when the volume is not finite or reaches beyond
// kMaxSceneCoordinate (the probes' rays would start where Embree aborts).
LightProbeGrid probeGridOver(const Bounds3& volume, float spacing, size_t maxProbes);

// `count` probes as a message quotes them: in full below 1e15, else in scientific notation.
std::string probeCountText(double count);

// Bakes every probe of `grid` (counts, origin, spacing set) from `maps`, the finished light maps (one per page of
// in.texels); fills coefficients, offsets and valid.
void bakeLightProbes(const BakeInputs& in, const std::vector<Lightmap>& maps, LightProbeGrid& grid,
                     const ProbeOptions& options = {}, ProbeStats* stats = nullptr);

}  // namespace irbake
