#include "export/relight.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>

#include "common/command_line.h"
#include "common/error.h"
#include "common/file_paths.h"
#include "common/log.h"
#include "export/exr_io.h"
#include "export/gltf_compact.h"
#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "export/map_encoding.h"
#include "scene/gltf_source.h"
#include "scene/scene_files.h"

namespace irbake {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr int kFloat = 5126;
const std::string kExt = kLightScenariosExtension;

// A number the file holds as a finite value ≥ 0 (also as a 32-bit float).
bool finiteNonNegative(const json& v) {
  if (!v.is_number()) return false;
  const double x = v.get<double>();
  return std::isfinite(x) && x >= 0.0 && std::isfinite(static_cast<float>(x));
}

// An array of `count` entries at key, each checked by `ok`; throws naming `what`.
const json& arrayOf(const json& object, const char* key, size_t count, const std::string& what, const std::string& file) {
  if (!object.contains(key) || !object[key].is_array() || object[key].size() != count)
    throw Error(ErrorCode::InvalidData, file, what + "." + key + ": needs an array of " + std::to_string(count) +
                                                  " entries, one per page");
  return object[key];
}

glm::vec3 weightOf(const json& w, const std::string& what, const std::string& file) {
  if (!w.is_array() || w.size() != 3 || !finiteNonNegative(w[0]) || !finiteNonNegative(w[1]) || !finiteNonNegative(w[2]))
    throw Error(ErrorCode::InvalidData, file, what + ": needs 3 finite numbers ≥ 0 (an RGB weight)");
  return glm::vec3(w[0].get<float>(), w[1].get<float>(), w[2].get<float>());
}

ScenarioLayer readLayer(const json& l, size_t pages, int textureCount, const std::string& what, const std::string& file) {
  ScenarioLayer layer;
  if (!l.is_object() || !l.contains("name") || !l["name"].is_string() || !validLayerName(l["name"].get<std::string>()))
    throw Error(ErrorCode::InvalidData, file, what + ".name: needs 1 to 64 of A-Z a-z 0-9 _ -");
  layer.name = l["name"].get<std::string>();
  const std::string named = what + " ('" + layer.name + "')";
  for (const json& t : arrayOf(l, "textures", pages, named, file)) {
    if (!t.is_number_integer() || t.get<int>() < 0 || t.get<int>() >= textureCount)
      throw Error(ErrorCode::InvalidData, file, named + ".textures: " + t.dump() + " is not a texture of the file (it has " +
                                                    std::to_string(textureCount) + ")");
    layer.textures.push_back(t.get<int>());
  }
  for (const json& i : arrayOf(l, "intensity", pages, named, file)) {
    if (!finiteNonNegative(i)) throw Error(ErrorCode::InvalidData, file, named + ".intensity: " + i.dump() + " must be a finite number ≥ 0");
    layer.intensity.push_back(i.get<double>());
  }
  if (l.contains("exr"))
    for (const json& e : arrayOf(l, "exr", pages, named, file)) {
      if (!e.is_string() || e.get<std::string>().empty() || !uriStaysInFolder(e.get<std::string>()))
        throw Error(ErrorCode::InvalidData, file, named + ".exr: " + e.dump() + " is not a file name beside the document");
      layer.exr.push_back(e.get<std::string>());
    }
  if (l.contains("probes")) {
    if (!l["probes"].is_number_integer()) throw Error(ErrorCode::InvalidData, file, named + ".probes: no accessor index");
    layer.probes = l["probes"].get<int>();
  }
  if (l.contains("sun")) {
    const json& sun = l["sun"];
    if (!sun.is_object() || !sun.contains("sh") || !sun["sh"].is_number_integer() || !sun.contains("irradiance"))
      throw Error(ErrorCode::InvalidData, file, named + ".sun: needs irradiance and an sh accessor");
    layer.hasSun = true;
    layer.sunIrradiance = weightOf(sun["irradiance"], named + ".sun.irradiance", file);
    layer.sunSh = sun["sh"].get<int>();
  }
  return layer;
}

}  // namespace

int LightmapScenarios::layerIndex(const std::string& name) const {
  for (size_t i = 0; i < layers.size(); ++i)
    if (layers[i].name == name) return static_cast<int>(i);
  return -1;
}

LightmapScenarios readLightmapScenarios(const json& root, const std::string& file) {
  if (!root.contains("extensions") || !root["extensions"].is_object() || !root["extensions"].contains(kExt))
    throw Error(ErrorCode::InvalidData, file, "has no " + kExt + " (bake it with --light-group to relight it)");
  const json& ext = root["extensions"][kExt];
  if (!ext.is_object()) throw Error(ErrorCode::InvalidData, file, kExt + ": not an object");
  const int textureCount = root.contains("textures") && root["textures"].is_array() ? static_cast<int>(root["textures"].size()) : 0;
  LightmapScenarios out;
  if (!ext.contains("pages") || !ext["pages"].is_array() || ext["pages"].empty())
    throw Error(ErrorCode::InvalidData, file, kExt + ".pages: needs one texture per light-map page");
  for (const json& t : ext["pages"]) {
    if (!t.is_number_integer() || t.get<int>() < 0 || t.get<int>() >= textureCount)
      throw Error(ErrorCode::InvalidData, file, kExt + ".pages: " + t.dump() + " is not a texture of the file");
    out.pages.push_back(t.get<int>());
  }
  if (!ext.contains("layers") || !ext["layers"].is_array() || ext["layers"].empty())
    throw Error(ErrorCode::InvalidData, file, kExt + ".layers: needs at least one layer");
  for (size_t i = 0; i < ext["layers"].size(); ++i) {
    ScenarioLayer layer = readLayer(ext["layers"][i], out.pages.size(), textureCount, kExt + ".layers[" + std::to_string(i) + "]", file);
    if (out.layerIndex(layer.name) >= 0)
      throw Error(ErrorCode::InvalidData, file, kExt + ".layers[" + std::to_string(i) + "]: name '" + layer.name + "' given twice");
    out.layers.push_back(std::move(layer));
  }
  if (!ext.contains("scenarios") || !ext["scenarios"].is_array() || ext["scenarios"].empty())
    throw Error(ErrorCode::InvalidData, file, kExt + ".scenarios: needs at least the default scenario");
  for (size_t s = 0; s < ext["scenarios"].size(); ++s) {
    const json& sc = ext["scenarios"][s];
    const std::string what = kExt + ".scenarios[" + std::to_string(s) + "]";
    if (!sc.is_object() || !sc.contains("name") || !sc["name"].is_string() || !sc.contains("weights") || !sc["weights"].is_object())
      throw Error(ErrorCode::InvalidData, file, what + ": needs a name and an object of weights");
    LightScenario scenario{sc["name"].get<std::string>(), std::vector<glm::vec3>(out.layers.size(), glm::vec3(0.0f))};
    for (const auto& [name, w] : sc["weights"].items()) {
      const int layer = out.layerIndex(name);
      if (layer < 0) throw Error(ErrorCode::InvalidData, file, what + ".weights: '" + name + "' is not a layer of the file");
      scenario.weights[layer] = weightOf(w, what + ".weights." + name, file);
    }
    out.scenarios.push_back(std::move(scenario));
  }
  const json d = ext.value("default", json(0));
  if (!d.is_number_integer() || d.get<int>() < 0 || d.get<int>() >= static_cast<int>(out.scenarios.size()))
    throw Error(ErrorCode::InvalidData, file, kExt + ".default: " + d.dump() + " is not a scenario of the file");
  out.defaultScenario = d.get<int>();
  return out;
}

namespace {

// The layers' names, for messages: "day, street".
std::string layerNames(const LightmapScenarios& s) {
  std::string names;
  for (const ScenarioLayer& l : s.layers) names += (names.empty() ? "" : ", ") + l.name;
  return names;
}

// Accessor `index` as FLOAT VEC3 of `count` elements (count 0: any), or Error(InvalidData) naming `what`.
std::vector<glm::vec3> vec3Accessor(const GltfDocument& doc, int index, size_t count, const std::string& what,
                                    const std::string& file) {
  const AccessorBytes a = readAccessor(doc, index, file);
  if (a.componentType != kFloat || a.type != "VEC3" || (count && a.count != count))
    throw Error(ErrorCode::InvalidData, file, what + ": accessor " + std::to_string(index) + " is " + std::to_string(a.count) +
                                                  " × " + a.type + " of componentType " + std::to_string(a.componentType) +
                                                  ", expected " + std::to_string(count) + " × VEC3 FLOAT");
  std::vector<glm::vec3> out(a.count);
  std::memcpy(out.data(), a.bytes.data(), a.bytes.size());
  for (const glm::vec3& v : out)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw Error(ErrorCode::InvalidData, file, what + ": a non-finite value");
  return out;
}

// Points accessor `index` at new data (its old view left to compactBufferViews); an accessor another reference
// shares (`shared`) is left as it is and a new one is made. Returns the accessor now holding `values`.
int setVec3Accessor(GltfDocument& doc, int index, const std::vector<glm::vec3>& values, bool shared) {
  const int view = doc.addBufferView(values.data(), values.size() * sizeof(glm::vec3));
  if (shared) return doc.append("accessors", {{"bufferView", view}, {"componentType", kFloat}, {"count", values.size()}, {"type", "VEC3"}});
  json& a = doc.root["accessors"][index];
  a["bufferView"] = view;
  a.erase("byteOffset");
  a.erase("sparse");
  return index;
}

// Every accessor index the extension's layers name (their probes and sun SH).
std::set<int> layerAccessors(const LightmapScenarios& s) {
  std::set<int> out;
  for (const ScenarioLayer& l : s.layers) {
    if (l.probes >= 0) out.insert(l.probes);
    if (l.sunSh >= 0) out.insert(l.sunSh);
  }
  return out;
}

}  // namespace

std::pair<std::string, glm::vec3> parseLayerWeight(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(ErrorCode::Usage, "", "--group needs NAME=W (W one number or R,G,B), got '" + text + "'");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  for (size_t count : {size_t(1), size_t(3)}) {
    std::string checked = value;
    if (!cli::numberList(count)(checked).empty()) continue;
    const std::vector<double> w = cli::parseNumberList(checked);
    for (double x : w)
      if (!(x >= 0.0) || !(x <= 1e20))
        throw Error(ErrorCode::Usage, "", "--group '" + text + "': a weight must be a finite number from 0 to 1e20");
    return {name, count == 1 ? glm::vec3(float(w[0])) : glm::vec3(float(w[0]), float(w[1]), float(w[2]))};
  }
  throw Error(ErrorCode::Usage, "", "--group '" + text + "': W must be one finite number ≥ 0 or three (R,G,B)");
}

Relight::Relight(const RelightOptions& options)
    : options_(options), folder_(folderOf(options.input)), doc_(documentFromSource(options.input)) {
  const std::string file = options.input.string();
  scenarios_ = readLightmapScenarios(doc_.root, file);
  int base = scenarios_.defaultScenario;
  if (!options.scenario.empty()) {
    base = -1;
    std::string names;
    for (size_t s = 0; s < scenarios_.scenarios.size(); ++s) {
      if (scenarios_.scenarios[s].name == options.scenario) base = static_cast<int>(s);
      names += (names.empty() ? "" : ", ") + scenarios_.scenarios[s].name;
    }
    if (base < 0) throw Error(ErrorCode::Usage, file, "--scenario '" + options.scenario + "': no such scenario (the file has " + names + ")");
  }
  weights_ = scenarios_.scenarios[base].weights;
  for (const auto& [name, w] : options.weights) {
    const int layer = scenarios_.layerIndex(name);
    if (layer < 0)
      throw Error(ErrorCode::Usage, file, "--group '" + name + "': no such light group (the file's layers: " + layerNames(scenarios_) + ")");
    weights_[layer] = w;
  }
  for (const ScenarioLayer& l : scenarios_.layers)
    if (l.exr.empty())
      throw Error(ErrorCode::InvalidData, file, "layer '" + l.name + "' has no EXR pages (" + kExt + " exr): relight sums the " +
                                                    "float pages, bake without --no-exr");
  const json& pages = doc_.root.contains("extras") && doc_.root["extras"].is_object() ? doc_.root["extras"].value("lightmapPages", json()) : json();
  if (!pages.is_array() || pages.size() < scenarios_.pages.size())
    throw Error(ErrorCode::InvalidData, file, "extras.lightmapPages: needs the default scenario's EXR page of each of the " +
                                                  std::to_string(scenarios_.pages.size()) + " page(s)");
  for (const json& name : pages)
    if (!name.is_string() || !uriStaysInFolder(name.get<std::string>()))
      throw Error(ErrorCode::InvalidData, file, "extras.lightmapPages: " + name.dump() + " is not a file name beside the document");
  for (size_t p = 0; p < scenarios_.pages.size(); ++p) pageExr_.push_back(pages[p].get<std::string>());
  for (const std::string& name : exrNames()) {  // before any work: every page this reads or copies is there
    std::error_code ec;
    if (!fs::is_regular_file(folder_ / name, ec))
      throw Error(ErrorCode::Io, (folder_ / name).string(), "no such file: an EXR page " + file + " names");
  }
}

std::vector<std::string> Relight::exrNames() const {
  std::vector<std::string> names;
  std::set<std::string> seen;
  auto add = [&](const std::string& n) {
    if (seen.insert(n).second) names.push_back(n);
  };
  for (const json& n : doc_.root["extras"]["lightmapPages"]) add(n.get<std::string>());
  for (const ScenarioLayer& l : scenarios_.layers)
    for (const std::string& n : l.exr) add(n);
  return names;
}

std::vector<fs::path> Relight::inputs() const {
  std::vector<fs::path> files = sceneInputFiles(options_.input);
  for (const std::string& n : exrNames()) files.push_back(folder_ / n);
  return files;
}

std::vector<fs::path> Relight::outputs() const {
  std::vector<fs::path> files;
  for (const std::string& n : exrNames()) files.push_back(folderOf(options_.output) / n);
  return files;
}

std::vector<LightLayer> readScenarioLayers(const GltfDocument& doc, const LightmapScenarios& scenarios, const fs::path& folder,
                                           const std::string& file, size_t* texels) {
  const json& ext = doc.root.value("extensions", json::object());
  const bool hasProbes = ext.contains(kLightProbesExtension);
  size_t withProbes = 0, count = 0;
  for (const ScenarioLayer& l : scenarios.layers) withProbes += l.probes >= 0 ? 1 : 0;
  if ((hasProbes || withProbes > 0) && (!hasProbes || withProbes != scenarios.layers.size()))
    throw Error(ErrorCode::InvalidData, file, hasProbes ? "IRBAKE_light_probes, but not every layer of " + kExt + " has its probes"
                                                        : kExt + " layers have probes, but the file has no IRBAKE_light_probes");
  if (hasProbes) {
    const json& probes = ext[kLightProbesExtension];
    if (!probes.contains("coefficients") || !probes["coefficients"].is_number_integer())
      throw Error(ErrorCode::InvalidData, file, "IRBAKE_light_probes.coefficients: no accessor index");
    count = vec3Accessor(doc, probes["coefficients"].get<int>(), 0, "IRBAKE_light_probes.coefficients", file).size();
  }
  std::vector<LightLayer> layers;
  for (const ScenarioLayer& l : scenarios.layers) {
    LightLayer layer;
    layer.name = l.name;
    layer.holdsSun = l.hasSun;
    if (l.exr.size() != scenarios.pages.size())
      throw Error(ErrorCode::InvalidData, file, "layer '" + l.name + "' has no EXR pages (" + kExt + " exr): its float pages are " +
                                                    "what is read, bake without --no-exr");
    for (size_t p = 0; p < scenarios.pages.size(); ++p) {
      const fs::path page = folder / l.exr[p];
      layer.maps.push_back(readExr(page));
      layer.maps.back().page = static_cast<int>(p);
      const Lightmap& m = layer.maps.back();
      const Lightmap& first = layers.empty() ? m : layers.front().maps[p];
      if (m.width != first.width || m.height != first.height)
        throw Error(ErrorCode::InvalidData, page.string(),
                    std::to_string(m.width) + "×" + std::to_string(m.height) + " texels, but " + (folder / scenarios.layers[0].exr[p]).string() +
                        " is " + std::to_string(first.width) + "×" + std::to_string(first.height) + ": not pages of one atlas");
      if (texels) *texels += m.size();
    }
    if (count > 0) {
      const std::vector<glm::vec3> c = vec3Accessor(doc, l.probes, count, kExt + " layer '" + l.name + "' probes", file);
      layer.probes.resize(count / kShCoefficients);
      std::memcpy(layer.probes.data(), c.data(), layer.probes.size() * sizeof(ShCoefficients));
    }
    layers.push_back(std::move(layer));
  }
  return layers;
}

std::vector<LightLayer> Relight::readLayers(RelightSummary& summary) const {
  return readScenarioLayers(doc_, scenarios_, folder_, options_.input.string(), &summary.texels);
}

// Per page: the MOZ_lightmap PNG encoded from the sum in place of the page's image, and the intensity of every
// material whose MOZ_lightmap names the page's texture.
void Relight::encodePages(const std::vector<Lightmap>& sums, RelightSummary& summary) {
  const MapEncoding& png = mapEncoding(MapEncodingKind::Png8);
  for (size_t p = 0; p < sums.size(); ++p) {
    const EncodedMap encoded = png.encode(sums[p], MapEncodeOptions{});
    const int texture = scenarios_.pages[p];
    json& t = doc_.root["textures"][texture];
    if (!t.contains("source") || !t["source"].is_number_integer() || t["source"].get<int>() < 0 ||
        t["source"].get<int>() >= static_cast<int>(doc_.root.value("images", json::array()).size()))
      throw Error(ErrorCode::InvalidData, options_.input.string(), "texture " + std::to_string(texture) + " of " + kExt + ".pages has no image");
    json& image = doc_.root["images"][t["source"].get<int>()];
    image["bufferView"] = doc_.addBufferView(encoded.bytes.data(), encoded.bytes.size());
    image["mimeType"] = "image/png";
    image.erase("uri");
    const double intensity = mozLightmapIntensity(encoded);
    for (json& m : doc_.root["materials"]) {
      if (!m.contains("extensions") || !m["extensions"].contains("MOZ_lightmap")) continue;
      json& moz = m["extensions"]["MOZ_lightmap"];
      if (moz.value("index", -1) == texture) moz["intensity"] = intensity;
    }
    summary.intensity.push_back(intensity);
  }
  summary.pages = static_cast<int>(sums.size());
}

// IRBAKE_light_probes: the coefficients the layers' sum, and the sun level's irradiance and SH the weight of the
// layer that holds the sun times that layer's.
void Relight::writeProbes(const std::vector<ShCoefficients>& sum, RelightSummary& summary) {
  if (sum.empty()) return;
  const std::string file = options_.input.string();
  json& probes = doc_.root["extensions"][kLightProbesExtension];
  const size_t emitters = probes.contains("emitters") && probes["emitters"].is_array() ? probes["emitters"].size() : 0;
  if (emitters > 0 && weights_ != scenarios_.scenarios[scenarios_.defaultScenario].weights)
    log::warn(file + ": IRBAKE_light_probes keeps its " + std::to_string(emitters) + " exact emitter(s) as baked: they are in no " +
              "layer, so the new weights do not reach them");
  const std::set<int> shared = layerAccessors(scenarios_);
  const int root = probes["coefficients"].get<int>();
  std::vector<glm::vec3> flat(sum.size() * kShCoefficients);
  std::memcpy(flat.data(), sum.data(), flat.size() * sizeof(glm::vec3));
  probes["coefficients"] = setVec3Accessor(doc_, root, flat, shared.count(root) > 0);
  summary.probes = sum.size();
  for (size_t l = 0; l < scenarios_.layers.size(); ++l) {
    const ScenarioLayer& layer = scenarios_.layers[l];
    if (!layer.hasSun) continue;
    if (!probes.contains("sun") || !probes["sun"].is_object() || !probes["sun"].contains("sh") || !probes["sun"]["sh"].is_number_integer())
      throw Error(ErrorCode::InvalidData, file, "layer '" + layer.name + "' holds the probes' sun, but IRBAKE_light_probes has no sun level");
    json& sun = probes["sun"];
    const glm::vec3 e = weights_[l] * layer.sunIrradiance;
    sun["irradiance"] = {e.x, e.y, e.z};
    std::vector<glm::vec3> sh = vec3Accessor(doc_, layer.sunSh, kShCoefficients, kExt + " layer '" + layer.name + "' sun.sh", file);
    for (glm::vec3& c : sh) c *= weights_[l];
    const int at = sun["sh"].get<int>();
    sun["sh"] = setVec3Accessor(doc_, at, sh, shared.count(at) > 0);
  }
}

RelightSummary Relight::write(const OutputGuard& guard) {
  RelightSummary summary;
  for (size_t l = 0; l < scenarios_.layers.size(); ++l) {
    summary.layers.push_back(scenarios_.layers[l].name);
    summary.weights.push_back(weights_[l]);
  }
  CombinedLayers sum = combineLayers(readLayers(summary), weights_);
  encodePages(sum.maps, summary);
  writeProbes(sum.probes, summary);
  json weights = json::object();
  for (size_t l = 0; l < weights_.size(); ++l) weights[scenarios_.layers[l].name] = {weights_[l].x, weights_[l].y, weights_[l].z};
  doc_.root["extensions"][kExt]["scenarios"][scenarios_.defaultScenario]["weights"] = weights;
  compactBufferViews(doc_);

  const fs::path& output = options_.output;
  const fs::path folder = folderOf(output);
  std::vector<PendingFile> files;
  const std::vector<std::string> exr = exrNames();
  if (!hasExtension(output, ".glb")) {  // images as files beside the .gltf, named as the bake's
    std::vector<std::string> taken = {output.filename().string(), output.stem().string() + ".bin"};
    taken.insert(taken.end(), exr.begin(), exr.end());
    for (auto& [name, bytes] : externalizeImages(doc_, taken)) files.push_back(pendingBytes(folder / name, std::move(bytes)));
    compactBufferViews(doc_);
  }
  if (doc_.root.contains("images"))
    for (json& image : doc_.root["images"]) image.erase(kSourceUriKey);
  const std::vector<PendingFile> docFiles = doc_.files(output);
  files.insert(files.begin(), docFiles.begin(), docFiles.end());
  const MapEncoding* exrEncoding = &mapEncoding(MapEncodingKind::Exr);
  auto summed = std::make_shared<std::vector<Lightmap>>(std::move(sum.maps));
  for (const std::string& name : exr) {
    const fs::path to = folder / name;
    size_t page = 0;
    while (page < pageExr_.size() && pageExr_[page] != name) ++page;
    if (page < pageExr_.size()) {
      files.push_back({to, [exrEncoding, summed, page, to](const fs::path& temp) { exrEncoding->writeFile((*summed)[page], {}, temp, to); }});
      continue;
    }
    const fs::path from = folder_ / name;  // a layer's page, an L1 or shadow-mask page: copied as it is
    files.push_back({to, [from, to](const fs::path& temp) {
                       std::error_code ec;
                       fs::copy_file(from, temp, fs::copy_options::overwrite_existing, ec);
                       if (ec) throw Error(ErrorCode::Io, from.string(), "cannot copy it to " + to.string() + " (" + ec.message() + ")");
                     }});
  }
  guard.write(files);
  return summary;
}

}  // namespace irbake
