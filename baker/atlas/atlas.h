// Lightmap UV atlas: charts, parameterisation (planar / LSCM), packing into pages -> TEXCOORD_1.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/progress.h"
#include "scene/scene.h"

namespace irbake {

struct AtlasOptions {
  double texelsPerUnit = 0.0;  // texels per metre; 0 = the density rule (atlas_estimate.h, docs/guide.md)
  double autoTexelsPerUnit = 0.0;  // the rule: at least this many texels per metre (the command's --quality sets it)
  int targetPageSize = 1024;   // the rule's floor for small scenes: the charts fill about one page of this edge
  float texelsPerTriangle = 64.0f;       // the rule's floor: at least this many chart texels per triangle, so a
                                         // detailed model gets a finer map than one page
  size_t maxAutoTexels = size_t(1) << 22;  // the per-triangle floor never asks for more chart texels than this (4M)
  int padding = 2;             // empty texels kept around every chart (bilinear-safe)
  int maxPageSize = 0;         // largest page edge (more pages are opened when one is full); 0 = the rule's edge
  bool keepUv1 = false;        // keep an input TEXCOORD_1 and only repack its islands
  size_t maxTexels = size_t(1) << 24;  // budget for all pages together (16M texels, 64 MiB per float RGBA
                                       // layer): the rule's density is lowered to fit it (with a warning); a
                                       // given texelsPerUnit over it fails early naming the density that fits.
                                       // 0 = no limit
  int maxSplitDepth = 24;      // bisections of one segmented chart before its faces become one planar chart each
  ProgressCallback progress;   // optional
};

struct AtlasPage {
  int width = 0, height = 0;   // multiples of 4
};

// An object's map density: the primitives of one node (instance) together.
struct ObjectDensity {
  std::string name;                   // the mesh's name
  int node = -1, instance = -1;       // the glTF node (and EXT_mesh_gpu_instancing instance, -1: none)
  double texelsPerSquareMetre = 0.0;  // packed chart texels over its surface area
};

struct AtlasStats {
  size_t charts = 0, planarCharts = 0, lscmCharts = 0;
  size_t degenerateFaces = 0;      // faces with no area (reported, still mapped to a point)
  size_t uncoveredTriangles = 0;   // non-degenerate triangles covering no texel centre
  size_t overlappingTexels = 0;    // must be 0
  size_t flippedTriangles = 0;     // must be 0
  double centreUtilisation = 0.0;  // texels whose centre lies inside a triangle / page area
  double areaStretchP5 = 0.0, areaStretchP50 = 0.0, areaStretchP95 = 0.0;
  double l2Stretch = 0.0;
  double texelsPerUnit = 0.0;      // the density used (texels per metre, before per-object lightmapScale)
  int pageSize = 0;                // the page edge limit used (the rule's or the one given)
  std::vector<ObjectDensity> sparsest;  // the five objects with the fewest texels per square metre, fewest first
  // Mesh, charts and parameterisation are summed over primitives (which run in parallel); the others are wall.
  double secondsMesh = 0.0, secondsCharts = 0.0, secondsParam = 0.0, secondsPack = 0.0;
  size_t nonManifoldFaces = 0;     // faces given their own vertex copies so the half-edge mesh accepts them
  size_t chartsSplit = 0;          // charts that failed a check (flip, zero area, overlap, stretch) and were bisected
  double secondsOutput = 0.0, secondsStats = 0.0;
  double secondsTotal = 0.0;       // wall clock of buildAtlas
  std::vector<std::string> warnings;
};

// A primitive the atlas mapped, as it was before the atlas split it: what a later bake onto the same atlas
// (--atlas-from, atlas/atlas_from_bake.h) checks its own geometry against.
struct SourcePrimitiveRecord {
  int node = -1, mesh = -1, primitive = -1, instance = -1;  // the source glTF's node, mesh, primitive, GPU instance
  std::string name;                  // the primitive's name (its mesh's), for messages
  size_t vertices = 0, triangles = 0;
  std::string positions;             // XXH3-64 (hex) of its world positions and then its triangles' indices
};

struct AtlasResult {
  std::vector<AtlasPage> pages;
  AtlasStats stats;
  int padding = 0;                               // empty texels around every chart
  std::vector<SourcePrimitiveRecord> sources;    // the mapped primitives before the atlas, in scene order
  nlohmann::json toJson() const {  // report "atlas": page sizes and the figures a user checks
    nlohmann::json sizes = nlohmann::json::array();
    for (const auto& pg : pages) sizes.push_back({{"width", pg.width}, {"height", pg.height}});
    nlohmann::json sparsest = nlohmann::json::array();
    for (const ObjectDensity& o : stats.sparsest)
      sparsest.push_back({{"name", o.name}, {"node", o.node}, {"instance", o.instance},
                          {"texelsPerSquareMetre", o.texelsPerSquareMetre}});
    return {{"pages", sizes},
            {"pageCount", pages.size()},
            {"pageSize", stats.pageSize},
            {"charts", stats.charts},
            {"texelsPerUnit", stats.texelsPerUnit},
            {"texelsPerMetre", stats.texelsPerUnit},
            {"sparsestObjects", sparsest},
            {"centreUtilisation", stats.centreUtilisation},
            {"warnings", stats.warnings}};
  }
};

// UV winding: every non-degenerate triangle has a positive signed area (u1-u0)(v2-v0)-(v1-v0)(u2-u0)
// in uv1, as its counter-clockwise 3D winding; charts are only rotated, never mirrored.
// Unwraps every primitive of `scene` in place: vertices are split along chart seams (sourceVertex
// records where each came from), uv1 is set in [0,1] over the primitive's page, and
// primitive.lightmap names the page. A primitive whose charts land on several pages is split into
// one primitive per page. Every primitive is lightmapped, emissive ones included, except those whose
// extras.irbake.mode says otherwise (Primitive::mode): they keep page −1 and no uv1. A primitive's charts are
// scaled by its lightmapScale (texel area × scale²).
AtlasResult buildAtlas(Scene& scene, const AtlasOptions& options);

// The part of `src` that lies on `lightmap`'s page, without vertices yet: src's material, node, instance, glTF
// origin, lightmapScale and mode; named "<src>#page<N>" when nameThePage (src spread over several pages).
Primitive primitivePart(const Primitive& src, LightmapRef lightmap, bool nameThePage);

}  // namespace irbake
