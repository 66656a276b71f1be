// A bake onto an earlier bake's atlas (irbake bake --atlas-from BAKED.gltf): its TEXCOORD_1 and pages are read
// back from the export instead of unwrapping again, so several bakes of one scene (lighting scenarios) share the
// light-map UVs and a client swaps maps without touching the geometry. The export records what this needs
// (docs/export.md, "irbakeAtlas"): the pages, the mapped primitives with a hash of their geometry, and on each
// exported primitive the source primitive it is a part of.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "atlas/atlas_estimate.h"
#include "scene/scene.h"

namespace irbake {

// The root extras key of the atlas record in an export.
constexpr const char* kAtlasRecordKey = "irbakeAtlas";

// (node, mesh, primitive, GPU instance) of the source glTF: which source primitive a part belongs to.
using SourcePrimitiveKey = std::array<int, 4>;

// The primitives of `scene` that get a light map, before any atlas: what a later bake checks its geometry against.
std::vector<SourcePrimitiveRecord> recordSourcePrimitives(const Scene& scene);
// XXH3-64 (hex) over every record: equal for two scenes whose light-mapped geometry is the same.
std::string geometryHash(const std::vector<SourcePrimitiveRecord>& records);
// The export's root extras record of an atlas (docs/export.md, "irbakeAtlas").
nlohmann::json atlasRecordJson(const AtlasResult& atlas);

// One light-mapped primitive of an earlier bake's export, as the loader reads it (world space, TEXCOORD_1 as
// uv1, its page), and the source primitive it is a part of.
struct BakedPart {
  SourcePrimitiveKey source{};
  Primitive primitive;
};

// What an earlier bake's export holds of its atlas.
struct BakedAtlas {
  std::filesystem::path file;                  // the export read
  std::vector<AtlasPage> pages;                // every page's size, in page order
  int padding = 0;                             // empty texels around every chart
  double texelsPerUnit = 0.0;                  // the density it was unwrapped at
  std::string geometryHash;                    // geometryHash of sources
  std::vector<SourcePrimitiveRecord> sources;  // the primitives it mapped, before its atlas
  std::vector<BakedPart> parts;                // its light-mapped primitives, in the export's order
};

// Reads an earlier bake's export (.gltf or .glb). Throws Error(Io, file) when it cannot be read,
// Error(InvalidData, file) when it is no irbake bake (no atlas record) or its record or primitives are malformed.
BakedAtlas readBakedAtlas(const std::filesystem::path& file);

// Applies `baked`'s atlas to `scene` (as loaded, before any atlas) as buildAtlas applies its own: each light-mapped
// primitive becomes its parts, one per page, with the vertices, order and TEXCOORD_1 of the earlier bake, so the
// same geometry gives the same scene the earlier bake's stages saw. Throws Error(InvalidData, scene's file) naming
// the first primitive whose geometry differs (missing, vertex or triangle count, positions); Error(Usage) when
// `options` asks for an atlas of its own (texelsPerUnit, maxPageSize, keepUv1). lightmapScale is ignored, with a
// warning where it is not 1.
AtlasResult atlasFromBake(Scene& scene, const BakedAtlas& baked, const AtlasOptions& options);

// What `irbake plan --atlas-from` predicts: the earlier bake's pages and density as they are, its chart texels
// from the surface at that density (the charts hold each object's lightmapScale already).
AtlasEstimate estimateBakedAtlas(const Scene& scene, const BakedAtlas& baked);

}  // namespace irbake
