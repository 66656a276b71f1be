#include "pipeline/only_group.h"

#include <fstream>
#include <optional>

#include "common/error.h"
#include "common/excerpt.h"
#include "common/file_paths.h"
#include "common/log.h"
#include "export/gltf_export.h"
#include "export/light_layers.h"
#include "export/light_probes_export.h"
#include "export/relight.h"
#include "pipeline/bake_plan.h"
#include "pipeline/light_groups.h"
#include "scene/gltf_source.h"

namespace irbake {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// What the earlier bake holds of its groups.
struct EarlierBake {
  std::string file;
  LightmapScenarios scenarios;
  std::vector<LightLayer> layers;        // in the extension's order: the order of the sum
  std::optional<LightProbeGrid> probes;  // its IRBAKE_light_probes (the sun level, the exact emitters)
  json report;                           // its report.json beside it; null where there is none
};

bool hasScenarios(const json& root) {
  return root.contains("extensions") && root["extensions"].is_object() && root["extensions"].contains(kLightScenariosExtension);
}

// The earlier bake's extension, checked for what an incremental bake needs.
LightmapScenarios readScenarios(const GltfDocument& doc, const std::string& file) {
  if (!hasScenarios(doc.root))
    throw Error(ErrorCode::Usage, file, std::string("--only-group: has no ") + kLightScenariosExtension +
                                            ": it was baked without light groups, so there are no layers to carry over");
  LightmapScenarios s = readLightmapScenarios(doc.root, file);
  for (size_t l = 0; l < s.layers.size(); ++l)
    if (s.scenarios[s.defaultScenario].weights[l] != glm::vec3(1.0f))
      throw Error(ErrorCode::Usage, file, "--only-group: the default scenario weighs layer '" + s.layers[l].name +
                                              "' other than 1 (a relit file): give the bake it was relit from");
  return s;
}

EarlierBake readEarlierBake(const fs::path& path) {
  EarlierBake e;
  e.file = path.string();
  const GltfDocument doc = documentFromSource(path);
  e.scenarios = readScenarios(doc, e.file);
  e.layers = readScenarioLayers(doc, e.scenarios, folderOf(path), e.file, nullptr);
  if (doc.root["extensions"].contains(kLightProbesExtension)) e.probes = readLightProbes(doc, e.file);
  const fs::path report = folderOf(path) / "report.json";
  std::error_code ec;
  if (fs::is_regular_file(report, ec)) {
    std::ifstream in(report);
    e.report = json::parse(in, nullptr, false);
    if (e.report.is_discarded()) {
      log::warn(report.string() + ": not JSON, its settled choices are settled again from the scene");
      e.report = json();
    }
  }
  return e;
}

std::string groupNames(const std::vector<LightGroup>& groups) {
  std::string names;
  for (const LightGroup& g : groups) names += (names.empty() ? "" : ", ") + g.name;
  return names;
}

std::string layerNames(const EarlierBake& e) {
  std::string names;
  for (const LightLayer& l : e.layers) names += (names.empty() ? "" : ", ") + l.name;
  return names;
}

const LightGroup* findGroup(const std::vector<LightGroup>& groups, const std::string& name) {
  for (const LightGroup& g : groups)
    if (g.name == name) return &g;
  return nullptr;
}

// NAME one of the scene's groups, and the scene's groups the earlier bake's layers, by name.
void checkGroupsMatch(const std::vector<LightGroup>& groups, const EarlierBake& e, const std::string& name, const std::string& scene) {
  if (groups.empty())
    throw Error(ErrorCode::Usage, scene, "--only-group: the scene has no light groups (--light-group, extras.irbake.group): "
                                         "give the groups of the earlier bake");
  if (!findGroup(groups, name))
    throw Error(ErrorCode::Usage, scene, "--only-group " + quotedExcerpt(name) + ": no such light group (the scene's groups: " +
                                             groupNames(groups) + ")");
  for (const LightGroup& g : groups)
    if (e.scenarios.layerIndex(g.name) < 0)
      throw Error(ErrorCode::Usage, e.file, "--only-group: the scene's light group '" + g.name + "' is no layer of this bake (its layers: " +
                                                layerNames(e) + "): bake every group");
  for (const LightLayer& l : e.layers)
    if (!findGroup(groups, l.name))
      throw Error(ErrorCode::Usage, e.file, "--only-group: its layer '" + l.name + "' is no light group of the scene (the scene's groups: " +
                                                groupNames(groups) + "): bake every group");
}

// What the full bake settled once, where the options leave it automatic: its report's final gather and clamp k,
// its probe spacing; the rest as the full bake settles it from the whole scene.
BakeOptions settleAsEarlier(const Scene& scene, const BakeOptions& options, const EarlierBake& e) {
  BakeOptions o = options;
  o.onlyGroup.clear();
  const json gather = e.report.is_object() ? e.report.value("/plan/final-gather/value"_json_pointer, json()) : json();
  if (o.finalGather == FinalGatherMode::Auto && gather.is_string())
    o.finalGather = gather.get<std::string>() == "on" ? FinalGatherMode::On : FinalGatherMode::Off;
  const json k = e.report.is_object() ? e.report.value("/eval/clampVplsPerMean"_json_pointer, json()) : json();
  if (!(o.clampVplsPerMean > 0.0) && k.is_number() && k.get<double>() > 0.0) o.clampVplsPerMean = k.get<double>();
  if (e.probes.has_value() != o.probes.enabled)
    throw Error(ErrorCode::Usage, e.file, std::string("--only-group: ") + (o.probes.enabled ? "this bake has no probes, give --probes off"
                                                                                           : "this bake has probes, do not turn them off") +
                                              ": the layers' probes are summed probe by probe");
  if (e.probes && !o.probes.spacing) o.probes.spacing = e.probes->spacing;
  return settleGroupedOptions(scene, o);
}

// The probes of the re-baked group on the earlier bake's grid, else refused.
void checkProbeGrid(const LightProbeGrid& now, const EarlierBake& e) {
  if (!e.probes) return;
  const LightProbeGrid& was = *e.probes;
  if (now.counts == was.counts && now.spacing == was.spacing && now.origin == was.origin) return;
  auto text = [](const LightProbeGrid& g) {
    return std::to_string(g.counts.x) + "×" + std::to_string(g.counts.y) + "×" + std::to_string(g.counts.z) + " probes " +
           std::to_string(g.spacing) + " m apart";
  };
  throw Error(ErrorCode::InvalidData, e.file, "--only-group: the probe grid came out as " + text(now) + ", this bake's is " +
                                                  text(was) + " (another --probes or --probe-box?): the layers' probes cannot be summed");
}

// A layer of the earlier bake as a part of the sum: its pages (with the re-baked layer's valid texels: one atlas),
// probes, the sun level where it holds it, its report's estimate.
GroupPart carriedPart(const EarlierBake& e, size_t l, const LightGroup& group, const LightLayer& rebaked) {
  GroupPart part;
  part.carried = true;
  part.layer = e.layers[l];
  part.layer.lights = group.sources;
  for (size_t p = 0; p < part.layer.maps.size() && p < rebaked.maps.size(); ++p) part.layer.maps[p].valid = rebaked.maps[p].valid;
  if (part.layer.holdsSun && e.probes) part.sun = e.probes->sun;
  part.report = {{"timings", {{"seconds", {{"bake", 0.0}}}, {"cpuSeconds", {{"bake", 0.0}}}}}};
  if (e.report.is_object() && e.report.contains("lightGroups") && e.report["lightGroups"].is_array())
    for (const json& entry : e.report["lightGroups"])
      if (entry.is_object() && entry.value("name", "") == group.name && entry.contains("estimatedError"))
        part.report["estimatedError"] = entry["estimatedError"];
  return part;
}

// Exact probe emitters are not split by layer in the file: a group with emissive materials (where they come from)
// cannot be re-baked alone when the file has some; otherwise they are all the carried groups'.
void checkEmitters(const LightGroup& group, const EarlierBake& e) {
  if (!group.materials.empty() && e.probes && !e.probes->emitters.empty())
    throw Error(ErrorCode::Usage, e.file, "--only-group '" + group.name + "': its IRBAKE_light_probes has exact emitters, which are in no " +
                                              "layer, and the group has emissive materials: bake every group");
}

}  // namespace

std::vector<fs::path> onlyGroupInputs(const fs::path& bakedFile) {
  const GltfDocument doc = documentFromSource(bakedFile);
  if (!hasScenarios(doc.root)) return {};
  const LightmapScenarios s = readLightmapScenarios(doc.root, bakedFile.string());
  const fs::path folder = folderOf(bakedFile);
  std::vector<fs::path> files = {folder / "report.json"};
  for (const ScenarioLayer& l : s.layers)
    for (const std::string& name : l.exr) files.push_back(folder / name);
  const json pages = doc.root.contains("extras") && doc.root["extras"].is_object() ? doc.root["extras"].value("lightmapPages", json()) : json();
  if (pages.is_array())
    for (const json& name : pages)
      if (name.is_string() && uriStaysInFolder(name.get<std::string>())) files.push_back(folder / name.get<std::string>());
  return files;
}

BakeResult bakeOnlyGroup(Scene scene, const BakeOptions& options) {
  if (options.atlasFrom.empty())
    throw Error(ErrorCode::Usage, scene.sourcePath, "--only-group re-bakes one group on an earlier grouped bake: give --atlas-from BAKED.gltf");
  const std::vector<LightGroup> groups = resolveLightGroups(scene, options.lightGroups);
  const EarlierBake earlier = readEarlierBake(options.atlasFrom);
  checkGroupsMatch(groups, earlier, options.onlyGroup, scene.sourcePath);
  const LightGroup& group = *findGroup(groups, options.onlyGroup);
  checkEmitters(group, earlier);
  const BakeOptions o = settleAsEarlier(scene, options, earlier);
  const std::vector<Light> lights = scene.lights;
  const std::vector<Material> materials = scene.materials;
  const Environment environment = scene.environment;
  log::info("light group '" + group.name + "' alone, the other layers from " + earlier.file);
  BakeResult total = bake(groupScene(std::move(scene), group), o);
  checkProbeGrid(total.probes, earlier);
  GroupPart rebaked = groupPart(group, lights, total);
  std::vector<GroupPart> parts;
  size_t at = 0;
  json carried = json::array();
  for (size_t l = 0; l < earlier.layers.size(); ++l) {
    if (earlier.layers[l].name == group.name) {
      at = l;
      parts.push_back(rebaked);
      continue;
    }
    parts.push_back(carriedPart(earlier, l, *findGroup(groups, earlier.layers[l].name), rebaked.layer));
    if (carried.empty() && earlier.probes) parts.back().emitters = earlier.probes->emitters;  // checkEmitters: none is the group's
    carried.push_back(earlier.layers[l].name);
  }
  total.scene.lights = lights;
  total.scene.materials = materials;
  total.scene.environment = environment;
  total.lightModes.assign(lights.size(), LightMode::Baked);
  total.maskChannels = {};
  sumParts(parts, total, earlier.scenarios.scenarios[earlier.scenarios.defaultScenario].weights, at);
  total.report["onlyGroup"] = {{"rebaked", group.name}, {"carried", carried}, {"from", fs::absolute(options.atlasFrom).string()}};
  return total;
}

}  // namespace irbake
