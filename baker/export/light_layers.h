// Light groups' layers (docs/export.md, "Scenarios and light groups: IRBAKE_lightmap_scenarios"): each group's
// light baked on the same atlas into a layer of its own (float pages, probe coefficients); a scenario's maps are
// Σ_L w_L ⊙ layer_L with an RGB weight per layer. The bake writes the default scenario (every weight 1) as the
// document's own maps; `irbake relight` recombines the layers read back from an export with other weights. Both
// combine through combineLayers, so a relit file and a bake agree texel for texel.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "export/gltf_writer.h"
#include "export/map_encoding.h"
#include "lightmap/lightmap.h"
#include "lightmap/probe_grid.h"

namespace irbake {

constexpr const char* kLightScenariosExtension = "IRBAKE_lightmap_scenarios";

// One light group's share of the bake.
struct LightLayer {
  std::string name;                    // the group's name, [A-Za-z0-9_-]{1,64} (validLayerName)
  nlohmann::json lights;               // what it holds: the extension's `lights` list ({"light": I, "name": …}, …)
  std::vector<Lightmap> maps;          // per page, E/π, post-processed like the bake's maps
  std::vector<ShCoefficients> probes;  // per probe, the grid's layout; empty without probes
  bool holdsSun = false;               // the layer with the probes' sun level's light (its irradiance and SH at weight 1)
};

// True for a name of [A-Za-z0-9_-]{1,64}: a layer's, a group's (and so a file name's part).
bool validLayerName(const std::string& name);
// True for the names other pages beside lightmap_<page> take in its place (the shadow mask's, the L1 pages'):
// no group may take one, and a lightmap_<page>_<name> file with one is not a layer.
bool otherPageName(const std::string& name);

// What a scenario's weights make of the layers.
struct CombinedLayers {
  std::vector<Lightmap> maps;          // per page: Σ_L w_L ⊙ maps_L, valid where any layer's page is
  std::vector<ShCoefficients> probes;  // per probe: Σ_L w_L ⊙ probes_L (empty when the layers have none)
};

// Σ_L weights[L] ⊙ layer L, texel by texel and coefficient by coefficient, summed in layer order in float (the
// bake's own sum of its groups). Throws Error(InvalidData) when the layers' pages or probe counts differ or a
// weight is negative or not finite; weights.size() must equal layers.size().
CombinedLayers combineLayers(const std::vector<LightLayer>& layers, const std::vector<glm::vec3>& weights);

// The layers' EXR page name: <prefix>_<page>_<layer>.exr.
std::string layerPageUri(const std::string& prefix, int page, const std::string& layer);

// Adds the extension with each layer's 8-bit PNGs (encoded as the main map: `encoding`, each its own range and
// intensity), its EXR names (exrPrefix "": none) and the scenarios `default` (every weight 1) and one per layer
// alone. `pages` (per page: the texture MOZ_lightmap names) is read from the document's materials. Call before
// the document's last compaction (the textures are kept: a root extension stops their collection).
void addLightScenariosExtension(GltfDocument& doc, const std::vector<LightLayer>& layers, const MapEncodeOptions& encoding,
                                const std::string& exrPrefix);
// Adds each layer's probe coefficients (and the sun level's irradiance and SH on the layer that holds it) as
// accessors; call after the last compaction, with the grid of IRBAKE_light_probes.
void addLightScenarioProbes(GltfDocument& doc, const std::vector<LightLayer>& layers, const LightProbeGrid& grid);
// Removes a source's extension (a bake of a grouped export writes its own, or none).
void removeLightScenariosExtension(nlohmann::json& root);

}  // namespace irbake
