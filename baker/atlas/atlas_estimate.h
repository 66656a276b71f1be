// The texel-density rule (docs/guide.md "Texel density") and the atlas it predicts from surface areas alone.
// buildAtlas picks its density and page edge with the same functions, so a prediction and a bake agree on both.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "scene/scene.h"

namespace irbake {

struct AtlasEstimate {
  double texelsPerUnit = 0.0;  // the density the rule picks (before any per-object scale)
  double texels = 0.0;         // predicted texels in charts (surface area x density^2 x scale^2, summed)
  double pageTexels = 0.0;     // predicted page texels (the charts over the packing's fill ratio)
  int pageSize = 0;            // page edge
  int pages = 0;               // predicted page count
  std::vector<std::string> warnings;  // what the bake's atlas would warn (budget lowered the density, ...)
};
// The density rule and its page layout predicted from the surface areas alone, without unwrapping.
AtlasEstimate estimateAtlas(const Scene& scene, const AtlasOptions& options);
// The surface that gets light-map texels: each light-mapped primitive's area times its lightmapScale² (m²).
double scaledLightmapArea(const Scene& scene);

// The density rule. scaledArea: the surface to map, each primitive's area times its lightmapScale² (m²);
// triangles: the scene's triangle count.
struct DensityChoice {
  double texelsPerUnit = 0.0;  // the density used (before per-object scale)
  double ruleTexelsPerUnit = 0.0;  // what the rule asked for before the budget
  bool lowered = false;        // the rule's atlas was over --max-texels: the density was lowered to fit
  std::string warning;         // set when lowered
};
DensityChoice chooseTexelsPerUnit(double scaledArea, size_t triangles, const AtlasOptions& options);

// The page edge: options.maxPageSize where given, else the smallest power of two from kMinAutoPageSize to
// kMaxAutoPageSize whose square holds twice the rule's page texels (a packed page is seldom square), else
// kMaxAutoPageSize.
constexpr int kMinAutoPageSize = 512, kMaxAutoPageSize = 4096;
int choosePageSize(double scaledArea, double texelsPerUnit, const AtlasOptions& options);

// Page texels per chart texel that the budget and the page edge assume: charts fill at least this share of
// their pages in practice.
constexpr double kWorstPageFill = 0.6;

}  // namespace irbake
