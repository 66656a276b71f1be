// irbake relight: a bake with light groups (IRBAKE_lightmap_scenarios, docs/export.md) written again with other
// weights on its layers, without tracing a ray. The layers' float EXR pages are summed with the new RGB weights
// (combineLayers, the bake's own sum: at the bake's weights the pages come back bit for bit) into the default EXR pages, the MOZ_lightmap PNGs are encoded from that sum (the bake's encoding) with the
// materials' intensity set to match, the probes' coefficients and sun level are summed the same way, and the
// extension's default scenario gets the new weights; the layers and everything else of the document are kept.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common/output_guard.h"
#include "export/gltf_writer.h"
#include "export/light_layers.h"
#include "lightmap/lightmap.h"

namespace irbake {

// One layer of the extension: a light group's own light on every page.
struct ScenarioLayer {
  std::string name;
  std::vector<int> textures;       // per page: the layer's 8-bit PNG texture
  std::vector<double> intensity;   // per page: E = sRGBToLinear(texel) × intensity
  std::vector<std::string> exr;    // per page: its float EXR page (E/π), relative to the document; empty: none
  int probes = -1;                 // accessor of its probe coefficients (FLOAT VEC3, 9 per probe), -1: none
  bool hasSun = false;             // holds the probes' sun (IRBAKE_light_probes.sun) at weight 1
  glm::vec3 sunIrradiance{0.0f};   // that sun's irradiance
  int sunSh = -1;                  // accessor of that sun's SH (FLOAT VEC3, 9)
};

// A named set of RGB weights, one per layer (in layer order; a layer the scenario does not name: 0).
struct LightScenario {
  std::string name;
  std::vector<glm::vec3> weights;
};

// The extension as read and checked.
struct LightmapScenarios {
  std::vector<int> pages;  // per page: the texture the materials' MOZ_lightmap names (the default scenario)
  std::vector<ScenarioLayer> layers;
  std::vector<LightScenario> scenarios;
  int defaultScenario = 0;  // index into scenarios: what the document's own maps hold
  int layerIndex(const std::string& name) const;  // -1 when no layer has that name
};

// The root's IRBAKE_lightmap_scenarios, checked: names ([A-Za-z0-9_-]{1,64}, unique), one texture, intensity
// (finite, ≥ 0) and EXR name per page in every layer, textures the document has, weights of 3 finite numbers ≥ 0
// naming layers it has, the default scenario in range. Throws Error(InvalidData, file) naming the field; a
// document without the extension: Error(InvalidData, file, "... has no IRBAKE_lightmap_scenarios ...").
LightmapScenarios readLightmapScenarios(const nlohmann::json& root, const std::string& file);

// Every layer's float EXR pages (read from `folder`, each the size of the first layer's, else refused naming the
// page) and probe coefficients (the count of the root's IRBAKE_light_probes, else refused), in layer order, each
// marked with whether it holds the probes' sun; `texels` (if given) adds every page's size. Throws
// Error(InvalidData, file) naming the problem.
std::vector<LightLayer> readScenarioLayers(const GltfDocument& doc, const LightmapScenarios& scenarios,
                                           const std::filesystem::path& folder, const std::string& file, size_t* texels);

// "NAME=W" of --group: the layer's name and its RGB weight, W one number (every channel) or R,G,B, each finite
// and from 0 to 1e20. Throws Error(Usage) quoting the text.
std::pair<std::string, glm::vec3> parseLayerWeight(const std::string& text);

// What relight is asked for.
struct RelightOptions {
  std::filesystem::path input;   // the grouped bake, .gltf or .glb
  std::filesystem::path output;  // .gltf (JSON + .bin, PNGs and EXR pages beside it) or .glb (EXR pages beside it)
  std::vector<std::pair<std::string, glm::vec3>> weights;  // new weights of the layers named; the rest keep the base's
  std::string scenario;          // the base scenario by name ("": the document's default scenario)
};

// What a relight did, for the command's summary.
struct RelightSummary {
  std::vector<std::string> layers;
  std::vector<glm::vec3> weights;  // per layer, the new default scenario
  int pages = 0;
  size_t texels = 0;               // summed per layer, over every page
  size_t probes = 0;               // probes recombined (0: the document has none)
  std::vector<double> intensity;   // per page: the new MOZ_lightmap intensity
};

// A relight: constructed from the options, it reads the document and the extension and settles the weights
// (refusing an unknown layer, a scenario the file lacks, a document without the extension); inputs() and
// outputs() are the files to declare to the output guard before any work; write() sums, encodes and writes the
// whole set through the guard, all or nothing.
class Relight {
 public:
  explicit Relight(const RelightOptions& options);
  // The bake's files this reads or copies: the document and its files, every EXR page the document names.
  std::vector<std::filesystem::path> inputs() const;
  // The files written beside the output by name (EXR pages: the default ones and the copies; the .bin of a .gltf).
  std::vector<std::filesystem::path> outputs() const;
  RelightSummary write(const OutputGuard& guard);

 private:
  std::vector<std::string> exrNames() const;  // every EXR page the document names, relative to its folder
  std::vector<LightLayer> readLayers(RelightSummary& summary) const;  // the layers' EXR pages and probe coefficients
  void encodePages(const std::vector<Lightmap>& sums, RelightSummary& summary);
  void writeProbes(const std::vector<ShCoefficients>& sum, RelightSummary& summary);

  RelightOptions options_;
  std::filesystem::path folder_;  // the input's folder
  GltfDocument doc_;
  LightmapScenarios scenarios_;
  std::vector<glm::vec3> weights_;     // per layer
  std::vector<std::string> pageExr_;   // per page: the default EXR page's name (extras.lightmapPages)
};

}  // namespace irbake
