// Stage 3 of the atlas: a chart's UVs (orthographic projection when planar, LSCM otherwise) and
// the checks that make a chart usable: no flip, no zero area, simple boundary, bounded stretch.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "atlas/atlas_mesh.h"

namespace irbake::atlas {

struct ParamOptions {
  double planarDegrees = 0.5;   // all face normals within this of the mean: orthographic projection
  double stretchLow = 0.88;     // area-weighted p5 of (UV area / 3D area ÷ chart mean) must be ≥ this
  double stretchHigh = 1.12;    // ... and p95 ≤ this
  double minAreaRatio = 1e-3;   // a face whose relative UV area is below this counts as zero-area
  double arapHopeless = 10.0;   // skip ARAP when the conformal map's p95/p5 area ratio exceeds this (it will be split)
  double maxAbsCurvature = 60.0;  // radians of Σ|angle deficit|; above it a chart is split unsolved (so curved a chart seldom flattens validly)
  int arapIterations = 5;       // as-rigid-as-possible rounds after LSCM (0: conformal only)
};

enum class ChartCheck { Valid, NoBoundary, Flipped, ZeroArea, SelfIntersecting, Stretched, SolveFailed };
const char* toString(ChartCheck check);

// A parameterised chart. uv is in 3D units (UV area = 3D area overall) until the packer scales it.
struct ChartUv {
  std::vector<uint32_t> faces;                    // primitive triangle indices
  std::vector<uint32_t> vertex;                   // local vertex -> welded mesh vertex
  std::vector<std::array<uint32_t, 3>> corner;    // per face: local vertex of each corner
  std::vector<glm::dvec2> uv;                     // per local vertex
  bool planar = false;
  double area3d = 0.0;
  double stretchP5 = 1.0, stretchP95 = 1.0;  // area-weighted percentiles of the relative area (last check)
};

// Parameterises the faces (an edge-connected chart) and checks the result.
ChartCheck parameterizeChart(const AtlasMesh& mesh, const std::vector<uint32_t>& faces,
                             const ParamOptions& options, ChartUv& out);

// Σ |2π − angle sum| over the chart's interior vertices (radians): how far it is from developable.
// Scale-free; charts far above what passes the checks are bisected before any solve.
double absoluteCurvature(const AtlasMesh& mesh, const std::vector<uint32_t>& faces);

// Signed UV area of a face of the chart (positive = same winding as in 3D).
double uvArea(const ChartUv& chart, size_t face);

}  // namespace irbake::atlas
