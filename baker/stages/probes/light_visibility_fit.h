// The punctual lights' visibility at each probe, fitted to the volume rather than sampled at the grid point.
// A client blends the 8 probes around an object (trilinear, valid ones only, weights renormalised: irview and the
// three.js plugin, lightmap/probe_grid.h). With each probe's own shadow ray, a sun's shadow edge between two
// probes is smeared over a whole spacing, on whichever side the grid points happen to fall: a sunlit object
// between a sunlit and a shaded probe gets half the sun. Here each probe's visibility v_i ∈ [0, 1] of each light
// is the one whose blend best matches the light's visibility over the free volume:
//   minimise Σ_s (Σ_i a_si v_i − f_s)² + Σ_i (v_i − f(p_i))²
// over S³ jittered points s per probe (its cube of one spacing around the grid point; only the points the probe
// sees: not under a floor, behind a wall or inside geometry), a_si the blend's weights at s, f_s the light's
// visibility there (0 or the see-through transmittance's mean), and each probe's own point p_i as one more
// sample; solved by projected Gauss–Seidel on the normal equations (27-point stencil), bounded to [0, 1] so
// that a probe never holds more of a light than reaches it unoccluded, nor less than none.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lightmap/probe_grid.h"

namespace irbake {

struct LightVisibilityFit {
  size_t lights = 0;             // the scene's punctual lights, in order
  std::vector<float> visibility;  // [probe × lights + light]: the fitted visibility (0 for invalid probes)
  std::vector<float> pointVisibility;  // the same at each probe's baked position alone (one shadow ray)
  size_t samples = 0;            // volume samples kept (seen by their probe, near a valid probe)
  size_t rays = 0;               // shadow rays traced (to the lights and from each probe to its samples)
  int sweeps = 0;                // Gauss–Seidel sweeps run
};

// `grid` with positions, offsets and valid set; samplesPerAxis S (0: each probe's own point alone, no fit).
LightVisibilityFit fitLightVisibility(const BakeInputs& in, const LightProbeGrid& grid, int samplesPerAxis,
                                      uint32_t seed);

// The visibility of `light` from x: 0 when an opaque surface is in the way, else the mean of the see-through
// surfaces' transmittance (1 in a scene without them); `colour`, when given, receives that transmittance.
float punctualVisibility(const BakeInputs& in, const Light& light, const glm::vec3& x, glm::vec3* colour = nullptr);

}  // namespace irbake
