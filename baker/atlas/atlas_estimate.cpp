#include "atlas/atlas_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scene/triangle_area.h"

namespace irbake {
namespace {

// The page texels a packing gives, as predicted: the charts over the fill of large charts (the gaps between
// their boxes), plus the padding and box waste of small ones, which a level has about one of per few triangles:
// kPaddingTexelsPerTriangle × padding per triangle. Calibrated on the samples, Sponza and Sibenik; the tests
// compare it with the real atlas on the samples, a generated level and Sponza.
constexpr double kLargeChartFill = 0.95;
constexpr double kPaddingTexelsPerTriangle = 6.0;

std::string densityText(double density) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", density);
  return text;
}

}  // namespace

DensityChoice chooseTexelsPerUnit(double scaledArea, size_t triangles, const AtlasOptions& options) {
  DensityChoice choice;
  if (options.texelsPerUnit > 0.0) {  // given: used as it is (over the budget, buildAtlas refuses it)
    choice.texelsPerUnit = choice.ruleTexelsPerUnit = options.texelsPerUnit;
    return choice;
  }
  if (!(scaledArea > 0.0)) return choice;
  // The floor for small scenes: charts of about kWorstPageFill of one targetPageSize² page, or of
  // texelsPerTriangle per triangle where that is more (at most maxAutoTexels).
  const double page = double(options.targetPageSize) * options.targetPageSize;
  const double byTriangles = std::min(double(options.texelsPerTriangle) * double(triangles), double(options.maxAutoTexels));
  const double floor = std::sqrt(kWorstPageFill * std::max(page, byTriangles) / scaledArea);
  double density = std::max(options.autoTexelsPerUnit, floor);
  choice.ruleTexelsPerUnit = density;
  if (options.maxTexels > 0 && scaledArea * density * density / kWorstPageFill > double(options.maxTexels)) {
    density = std::sqrt(kWorstPageFill * double(options.maxTexels) / scaledArea);
    choice.lowered = true;
    char text[300];
    std::snprintf(text, sizeof(text),
                  "the density rule's %s texels per metre would need about %.4g M texels, over the budget of %.4g M "
                  "(--max-texels): lowered to %s texels per metre for every object",
                  densityText(choice.ruleTexelsPerUnit).c_str(),
                  scaledArea * choice.ruleTexelsPerUnit * choice.ruleTexelsPerUnit / kWorstPageFill / 1e6,
                  double(options.maxTexels) / 1e6, densityText(density).c_str());
    choice.warning = text;
  }
  choice.texelsPerUnit = density;
  return choice;
}

int choosePageSize(double scaledArea, double texelsPerUnit, const AtlasOptions& options) {
  if (options.maxPageSize > 0) return options.maxPageSize;
  const double pageTexels = scaledArea * texelsPerUnit * texelsPerUnit / kWorstPageFill;
  for (int edge = kMinAutoPageSize; edge < kMaxAutoPageSize; edge *= 2)
    if (double(edge) * edge >= 2.0 * pageTexels) return edge;
  return kMaxAutoPageSize;
}

double scaledLightmapArea(const Scene& scene) {
  double scaledArea = 0.0;
  for (const Primitive& p : scene.primitives) {
    if (!p.getsLightmap()) continue;  // shadow-only, probe-lit, off: no charts
    double area = 0.0;
    for (size_t t = 0; t < p.triangleCount(); ++t) area += triangleArea(p, t);
    scaledArea += area * double(p.lightmapScale) * double(p.lightmapScale);
  }
  return scaledArea;
}

AtlasEstimate estimateAtlas(const Scene& scene, const AtlasOptions& options) {
  AtlasEstimate estimate;
  const double scaledArea = scaledLightmapArea(scene);
  const DensityChoice density = chooseTexelsPerUnit(scaledArea, scene.triangleCount(), options);
  if (!density.warning.empty()) estimate.warnings.push_back(density.warning);
  estimate.texelsPerUnit = density.texelsPerUnit;
  estimate.texels = scaledArea * density.texelsPerUnit * density.texelsPerUnit;
  estimate.pageTexels = estimate.texels > 0.0 ? estimate.texels / kLargeChartFill + kPaddingTexelsPerTriangle *
                                                       std::max(0, options.padding) * double(scene.triangleCount())
                                               : 0.0;
  estimate.pageSize = choosePageSize(scaledArea, density.texelsPerUnit, options);
  const double perPage = double(estimate.pageSize) * estimate.pageSize;
  estimate.pages = estimate.texels > 0.0 ? std::max(1, int(std::ceil(estimate.pageTexels / perPage))) : 0;
  return estimate;
}

}  // namespace irbake
