// Stage 4 of the atlas: charts scaled to a texel density, turned to their minimum-area box,
// rasterised conservatively, dilated by the padding and placed into pages (first fit, lowest top).
#pragma once
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "atlas/parameterize.h"

namespace irbake::atlas {

struct PackOptions {
  double texelsPerUnit = 1.0;  // UV units (3D units after parameterisation) -> texels
  int padding = 2;             // empty texels between any two charts
  int maxPageSize = 2048;      // page edge limit; charts go to a new page when one is full
  int widthTrials = 3;         // page widths tried when everything fits one page (the smallest area wins)
};

struct PackResult {
  std::vector<AtlasPage> pages;
  std::vector<int> chartPage;         // page of each chart
  std::vector<std::string> warnings;  // charts scaled down to fit a page
};

// Rewrites every chart's uv into texel coordinates of its page ([0,W]×[0,H], texel (x,y) covers
// [x,x+1]×[y,y+1]); orientation is preserved (rotations only, never mirrored).
PackResult packCharts(std::vector<ChartUv>& charts, const PackOptions& options);

// Conservative coverage: does the UV triangle overlap the open texel square (x,y) grown by margin?
bool triangleOverlapsTexel(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, int x, int y, double margin = 0.0);

}  // namespace irbake::atlas
