// Stage 2 of the atlas: segmentation of a mesh into charts (lists of faces) by region growing.
#pragma once
#include <cstdint>
#include <vector>

#include "atlas/atlas_mesh.h"

namespace irbake::atlas {

struct ChartOptions {
  double planarDegrees = 0.5;       // faces within this of a seed's normal form a planar region
  double planarMinAreaFraction = 0.002;  // a planar region of ≥ 2 faces and ≥ this × mesh area is locked as a chart
  double softBendDegrees = 20.0;    // a planar region mostly bordered by bends below this is part of a curved surface
  double coneDegrees = 60.0;        // a curved chart's faces stay within this of its mean normal
  double creaseDegrees = 75.0;      // growth never crosses an edge whose dihedral exceeds this
  double mergeAreaFraction = 0.5;   // curved charts below this × the median curved chart area are merged
  double mergeConeDegrees = 75.0;
  double maxAreaFraction = 1.0;    // a curved chart stops growing at this × mesh area (big charts rarely pass the checks)
  int normalSmoothing = 3;          // rounds of neighbour averaging of face normals for the curved cone tests   // ... into a neighbour if the union stays within this cone
};

struct ChartFaces {
  std::vector<uint32_t> faces;
  bool planarRegion = false;  // grown as a planar region (its faces are coplanar)
};

// Every non-degenerate face lands in exactly one chart; charts are edge-connected and never
// cross seams or creases. Thresholds are angles or ratios only, so the result is scale-free.
std::vector<ChartFaces> segmentCharts(const AtlasMesh& mesh, const ChartOptions& options = {});

// Splits a chart into two edge-connected halves around two far-apart seeds (geodesic Voronoi).
// Returns one chart (the input) when it has a single face.
std::vector<ChartFaces> bisectChart(const AtlasMesh& mesh, const ChartFaces& chart);

}  // namespace irbake::atlas
