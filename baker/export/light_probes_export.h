// Irradiance probes in the export (docs/export.md, "IRBAKE_light_probes"): a root-level vendor extension with
// the grid (origin, spacing, counts) and three accessors (coefficients, per-probe offsets, validity), listed in
// extensionsUsed only: clients that do not know it show the light maps as before.
#pragma once
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "export/gltf_writer.h"
#include "lightmap/probe_grid.h"

namespace irbake {

constexpr const char* kLightProbesExtension = "IRBAKE_light_probes";
// The most triangles the `emitters` may hold in all (the clients shade each at every pixel of a probe-lit object).
constexpr int kMaxExactEmitterTriangles = 256;

// Adds the grid's accessors (appended to buffer 0, no buffer-view target) and the extension.
void addLightProbesExtension(GltfDocument& doc, const LightProbeGrid& grid);
// Removes the extension from the root and extensionsUsed (its accessors are left to compaction): a bake of an
// export replaces the probes, and one with --probes off writes none.
void removeLightProbesExtension(nlohmann::json& root);

// The probes of an exported glTF/GLB. Throws Error(InvalidData, file, ...) naming the problem: no extension,
// counts or spacing out of range, an accessor of the wrong type or shorter than the grid, a non-finite value.
LightProbeGrid readLightProbes(const std::filesystem::path& file);
// The same from a document already read (its buffers loaded); `file` names it in errors.
LightProbeGrid readLightProbes(const GltfDocument& doc, const std::string& file);

}  // namespace irbake
