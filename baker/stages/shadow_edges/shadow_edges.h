// Punctual lights' shadow edges, area-averaged. The backends evaluate a punctual light once per texel sample,
// at the texel's centre: a texel a hard shadow edge crosses stores the centre's side of the edge, and the
// bilinear read spreads that over the texel's whole square, so a region's mean is off by up to half a texel
// of shadow along every edge (narrow sunlit strips show it most). Here the texels where the lights' visibility jumps between neighbours get the mean of that light over
// their own square instead: S×S sub-points on the chart's triangles that cover it, one shadow ray each, so the map's mean
// over any region equals the irradiance's up to the bilinear blur. Both backends: the direct stage's pages
// (punctual lights only) before the VPLs are added; the centre's value is replaced, not corrected, so GL's
// shadow-map texels on an edge come out as the rays say. docs/units.md, "Shadow edges".
#pragma once
#include <cstddef>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

struct ShadowEdgeOptions {
  int subSamples = 8;           // S: S×S sub-points per edge texel (0 or 1: the stage is off)
  float jump = 0.1f;            // an edge: the share of the lights' unshadowed value that arrives differs from a
                                // valid neighbour's by more (smooth falloff leaves the share at 1)
  float faintShare = 0.5f;      // the faintest lights at a texel's centre, together under faintShare × jump of its
                                // light, are traced at the centre only, in the probe and the refinement (0: none)
};

struct ShadowEdgeStats {
  size_t edgeTexels = 0;     // texels whose value was replaced
  size_t subPoints = 0;      // sub-points traced (on a triangle of the chart)
  size_t droppedInside = 0;  // of those, cut off from the texel's centre by a surface (under a box on the floor)
  double seconds = 0.0;
};

// A subset of the lights whose own refined value is wanted beside the total, on the same edge texels
// (mixed lighting: the lights left out of what is written). pages: their direct pages, refined in place.
struct ShadowEdgePart {
  const std::vector<uint8_t>* lights = nullptr;  // per scene light, 1: in the part
  std::vector<Lightmap>* pages = nullptr;
};

// The light the lights' cut leaves out, per page and texel (stages/light_tail's estimate), with and without its
// shadows: the visible share counts it on both sides, so a texel's jump is weighed against all of the lights'
// light and a bake with cut lights finds the edges a bake without the cut finds, far lights' shadows included.
struct CutLightPages {
  const std::vector<std::vector<glm::vec3>>* shadowed = nullptr;
  const std::vector<std::vector<float>>* unshadowed = nullptr;  // channel mean
};

// In place on the punctual lights' pages (one per in.texels page, as the direct stage returns them). Pages
// with supersampled texels (S > 1) are left alone: their samples already spread over the texel. cutLight: null
// where no light is cut.
ShadowEdgeStats refineShadowEdges(const BakeInputs& in, std::vector<Lightmap>& directPages,
                                  const ShadowEdgeOptions& options = {}, const ShadowEdgePart* part = nullptr,
                                  const CutLightPages* cutLight = nullptr);

}  // namespace irbake
