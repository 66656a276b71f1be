// The incremental bake of one light group (irbake bake --only-group NAME --atlas-from BAKED.gltf; docs/guide.md,
// "Scenarios and light groups"): the group's sources are baked alone on the earlier bake's atlas, every other
// group's layer (float EXR pages, probe coefficients, the sun level where it holds the sun) is read back from the
// earlier bake and carried over as it is, and the maps and probes are the layers' sum with the earlier bake's
// default-scenario weights (combineLayers, as the full grouped bake sums them). The result is what
// bakeLightGroups returns, so the export writes a complete grouped bake.
//
// What must match the earlier bake: its groups (the scene's, resolved as for a full grouped bake, against its
// IRBAKE_lightmap_scenarios layers, by name), its geometry (atlasFromBake), and what a grouped bake settles once
// for the whole scene: the final gather and the clamp's k are read from the earlier bake's report.json where it
// is beside it (else settled from the scene as the full bake does), the automatic probe spacing from its
// IRBAKE_light_probes, and the probe grid is checked to be the earlier's after the bake.
#pragma once
#include <filesystem>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/bake_options.h"
#include "scene/scene.h"

namespace irbake {

// The earlier bake's files an incremental bake reads besides the glTF (its layers' and default EXR pages, its
// report), for the output guard; empty where `bakedFile` has no IRBAKE_lightmap_scenarios (refused later).
std::vector<std::filesystem::path> onlyGroupInputs(const std::filesystem::path& bakedFile);

// The bake of options.onlyGroup alone, the other layers carried over from options.atlasFrom. Throws
// Error(Usage) naming the file and the problem, before anything is traced: no --atlas-from, a scene without light
// groups, a NAME that is not one of its groups, groups that are not the earlier bake's layers (the missing or
// extra one named), an earlier bake without IRBAKE_lightmap_scenarios or with default weights other than 1 (a
// relit file), probes in one and not the other, and a group with exact probe emitters; Error(InvalidData) when
// the probe grid comes out other than the earlier bake's.
BakeResult bakeOnlyGroup(Scene scene, const BakeOptions& options);

}  // namespace irbake
