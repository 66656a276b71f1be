// The clamp compensation measured on probe grids (gridSamples over a region of interest, such as the texels
// near a corner) rather than on whole atlas pages. ClampGather reads the radiance of what its rays hit from
// the baked maps, so the scene gets an atlas and its pages are baked beside the probes.
#pragma once
#include <vector>

#include "lightmap/lightmap.h"
#include "stages/compensation/clamp_compensation.h"
#include "vpl/vpl.h"
#include "testing/scenes.h"

namespace irbake::testing {

// The probes baked by the Embree backend with eval's clamp, then with the residual ClampGather adds back.
struct ProbeBake {
  std::vector<Lightmap> clamped, compensated;  // one map per probe grid, in order
};

ProbeBake bakeProbesCompensated(const AtlasedScene& atlased, const std::vector<TexelSamples>& probes,
                                const VplSet& vpls, const VplEvalOptions& eval,
                                const ClampCompensationOptions& options = {});

}  // namespace irbake::testing
