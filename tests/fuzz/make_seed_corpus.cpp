// make_seed_corpus IN_FOLDER OUT_FOLDER: packs every IN_FOLDER/*.gltf (irbake samples output: JSON +
// .bin + images beside it) into two self-contained seeds the fuzzer can mutate as one input each:
// NAME.glb (buffer 0 in the BIN chunk, other files as data URIs) and NAME.gltf (every file as a
// base64 data URI). Also a small EXT_meshopt_compression and a small KHR_draco_mesh_compression GLB, made
// by our own code (testing/compressed_gltf.h). Our own scenes only: no third-party file enters the corpus.
// Each scene also gives .gltf variants with the inputs the samples do not use: EXT_mesh_gpu_instancing on
// every node with a mesh, KHR_texture_transform on every texture reference and EXT_texture_webp (a 2×2 WebP
// made with OpenImageIO's writer, the core source kept as its fallback) on every texture.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "testing/compressed_gltf.h"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

std::vector<uint8_t> readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error(p.string() + ": cannot read");
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeFile(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error(p.string() + ": cannot write");
}

std::string base64(const std::vector<uint8_t>& b) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < b.size(); i += 3) {
    uint32_t v = uint32_t(b[i]) << 16 | (i + 1 < b.size() ? uint32_t(b[i + 1]) << 8 : 0) | (i + 2 < b.size() ? b[i + 2] : 0);
    out += digits[v >> 18 & 63];
    out += digits[v >> 12 & 63];
    out += i + 1 < b.size() ? digits[v >> 6 & 63] : '=';
    out += i + 2 < b.size() ? digits[v & 63] : '=';
  }
  return out;
}

// Replaces the file URI of every element of doc[key] by a data URI (all but `skip`).
void embed(json& doc, const char* key, const fs::path& folder, int skip) {
  if (!doc.contains(key)) return;
  for (size_t i = 0; i < doc[key].size(); ++i) {
    json& e = doc[key][i];
    if (static_cast<int>(i) == skip || !e.contains("uri")) continue;
    std::string uri = e["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) continue;
    e["uri"] = "data:application/octet-stream;base64," + base64(readFile(folder / uri));
  }
}

// A 2×2 lossy WebP of one colour, written by `oiiotool --pattern constant:color=0.8,0.4,0.2 2x2 3 -d uint8`.
const std::vector<uint8_t> kWebp = {
    0x52, 0x49, 0x46, 0x46, 0x42, 0x00, 0x00, 0x00, 0x57, 0x45, 0x42, 0x50, 0x56, 0x50, 0x38, 0x20, 0x36, 0x00, 0x00,
    0x00, 0x50, 0x02, 0x00, 0x9d, 0x01, 0x2a, 0x02, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00, 0x25, 0xa0, 0x02, 0x74, 0xba,
    0x01, 0xf8, 0x01, 0xfa, 0x01, 0xfc, 0x00, 0x09, 0xd0, 0x00, 0xfe, 0xdf, 0x80, 0x3f, 0xfc, 0xb0, 0xfc, 0x7f, 0x52,
    0x79, 0xff, 0xcb, 0x10, 0xff, 0xfb, 0x52, 0x7e, 0xbc, 0xc1, 0xca, 0xff, 0xed, 0x32, 0x00, 0x00, 0x00};

void useExtension(json& doc, const char* name) {
  if (!doc.contains("extensionsUsed")) doc["extensionsUsed"] = json::array();
  doc["extensionsUsed"].push_back(name);
}

// Three instances (translations, rotations, scales of their own) of every node with a mesh, in a buffer of
// their own (a data URI). False when no node has a mesh.
bool addGpuInstancing(json& doc) {
  const float h = 0.70710678f;
  const std::vector<float> values = {0, 0, 0, 1, 0, 0, 0, 0, 1,               // TRANSLATION
                                     0, 0, 0, 1, 0, h, 0, h, h, 0, 0, h,       // ROTATION
                                     1, 1, 1, 0.5f, 0.5f, 0.5f, 2, 1, 1};      // SCALE
  std::vector<uint8_t> bytes(values.size() * 4);
  std::memcpy(bytes.data(), values.data(), bytes.size());
  const size_t buffer = doc["buffers"].size();
  doc["buffers"].push_back({{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}});
  json attributes = json::object();
  const std::pair<const char*, int> parts[] = {{"TRANSLATION", 0}, {"ROTATION", 36}, {"SCALE", 84}};
  for (const auto& [name, offset] : parts) {
    const bool rotation = std::string(name) == "ROTATION";
    doc["bufferViews"].push_back({{"buffer", buffer}, {"byteOffset", offset}, {"byteLength", rotation ? 48 : 36}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5126}, {"count", 3},
                                {"type", rotation ? "VEC4" : "VEC3"}});
    attributes[name] = doc["accessors"].size() - 1;
  }
  bool any = false;
  for (json& node : doc["nodes"])
    if (node.contains("mesh")) {
      node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = attributes;
      any = true;
    }
  useExtension(doc, "EXT_mesh_gpu_instancing");
  return any;
}

// KHR_texture_transform on every texture reference of every material. False when there is none.
bool addTextureTransforms(json& doc) {
  bool any = false;
  auto transform = [&](json* info) {
    if (!info || !info->is_object() || !info->contains("index")) return;
    (*info)["extensions"]["KHR_texture_transform"] = {{"offset", {0.25, 0}}, {"rotation", 0.5}, {"scale", {2, 1}}, {"texCoord", 0}};
    any = true;
  };
  if (!doc.contains("materials")) return false;
  for (json& m : doc["materials"]) {
    if (m.contains("pbrMetallicRoughness") && m["pbrMetallicRoughness"].contains("baseColorTexture"))
      transform(&m["pbrMetallicRoughness"]["baseColorTexture"]);
    for (const char* key : {"emissiveTexture", "normalTexture"})
      if (m.contains(key)) transform(&m[key]);
  }
  if (any) useExtension(doc, "KHR_texture_transform");
  return any;
}

// EXT_texture_webp on every texture: a WebP image of its own, the core source kept as the fallback.
bool addWebpSources(json& doc) {
  if (!doc.contains("textures") || doc["textures"].empty()) return false;
  for (json& t : doc["textures"]) {
    doc["images"].push_back({{"mimeType", "image/webp"}, {"uri", "data:application/octet-stream;base64," + base64(kWebp)}});
    t["extensions"]["EXT_texture_webp"]["source"] = doc["images"].size() - 1;
  }
  useExtension(doc, "EXT_texture_webp");
  return true;
}

void appendU32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

std::string glb(json doc, const fs::path& folder) {
  std::vector<uint8_t> bin;
  if (doc.contains("buffers") && !doc["buffers"].empty() && doc["buffers"][0].contains("uri")) {
    bin = readFile(folder / doc["buffers"][0]["uri"].get<std::string>());
    doc["buffers"][0].erase("uri");
  }
  embed(doc, "buffers", folder, 0);
  embed(doc, "images", folder, -1);
  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::string out = "glTF";
  appendU32(out, 2);
  appendU32(out, static_cast<uint32_t>(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  appendU32(out, static_cast<uint32_t>(text.size()));
  appendU32(out, 0x4E4F534Au);  // "JSON"
  out += text;
  if (!bin.empty()) {
    appendU32(out, static_cast<uint32_t>(bin.size()));
    appendU32(out, 0x004E4942u);  // "BIN\0"
    out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
  }
  return out;
}

// Per-object settings (extras.irbake on nodes and meshes): every mode and a texel scale on the nodes in turn,
// a scale and a mode on the first mesh, and a parent node whose setting its children inherit.
bool addObjectSettings(json& doc) {
  if (!doc.contains("nodes") || !doc["nodes"].is_array() || doc["nodes"].empty()) return false;
  const char* const modes[] = {"baked", "shadow-only", "probes", "off"};
  size_t i = 0;
  for (json& node : doc["nodes"])
    if (node.contains("mesh")) {
      node["extras"]["irbake"] = {{"mode", modes[i % 4]}, {"lightmapScale", 0.5 * double(1 + i % 4)}};
      ++i;
    }
  if (doc.contains("meshes") && doc["meshes"].is_array() && !doc["meshes"].empty())
    doc["meshes"][0]["extras"]["irbake"] = {{"mode", "shadow-only"}, {"lightmapScale", 2.0}};
  json parent = {{"name", "settings parent"}, {"extras", {{"irbake", {{"mode", "probes"}, {"lightmapScale", 0.25}}}}},
                 {"children", json::array()}};
  const int scene = doc.value("scene", 0);
  if (!doc.contains("scenes") || !doc["scenes"].is_array() || int(doc["scenes"].size()) <= scene) return i > 0;
  json& roots = doc["scenes"][scene]["nodes"];
  if (!roots.is_array() || roots.empty()) return i > 0;
  parent["children"].push_back(roots.back());
  doc["nodes"].push_back(parent);
  roots.back() = doc["nodes"].size() - 1;
  return true;
}

// A small LM-63 profile (type C, quadrant symmetry, TILT=INCLUDE) for the EXT_lights_ies seeds.
const char kIesProfile[] =
    "IESNA:LM-63-2002\n[TEST] seed\nTILT=INCLUDE\n1\n2\n0 90\n1 1\n"
    "1 -1 1.5 4 2 1 2 0.1 0.1 0\n1 1 20\n0 30 60 90\n0 90\n100 90 50 0\n80 70 40 0\n";

// The scene with an EXT_lights_ies light above its centre: its profile as a data URI, its node tilted, with a
// multiplier and a colour.
json withIesLight(json doc) {
  const std::string text = kIesProfile;
  doc["extensions"]["EXT_lights_ies"]["lights"] = json::array(
      {{{"name", "seed lamp"}, {"uri", "data:application/x-ies-lm-63;base64," + base64({text.begin(), text.end()})}}});
  json node = {{"name", "ies lamp"},
               {"translation", {0.1, 1.5, 0.2}},
               {"rotation", {0.2588190, 0.0, 0.0, 0.9659258}},
               {"extensions", {{"EXT_lights_ies", {{"light", 0}, {"multiplier", 2.0}, {"color", {1.0, 0.9, 0.8}}}}}}};
  doc["nodes"].push_back(node);
  doc["scenes"][doc.value("scene", 0)]["nodes"].push_back(doc["nodes"].size() - 1);
  doc["extensionsUsed"].push_back("EXT_lights_ies");
  return doc;
}

// The document with every material written as KHR_materials_pbrSpecularGlossiness (its base colour as the
// diffuse factor, no metal-rough fallback), as older exporters write them.
json specularGlossiness(json doc) {
  if (!doc.contains("materials")) return doc;
  for (json& m : doc["materials"]) {
    json pbr = m.value("pbrMetallicRoughness", json::object());
    json sg = {{"diffuseFactor", pbr.value("baseColorFactor", json::array({1.0, 1.0, 1.0, 1.0}))},
               {"specularFactor", {0.04, 0.04, 0.04}}, {"glossinessFactor", 0.2}};
    if (pbr.contains("baseColorTexture")) sg["diffuseTexture"] = pbr["baseColorTexture"];
    m.erase("pbrMetallicRoughness");
    m["extensions"]["KHR_materials_pbrSpecularGlossiness"] = std::move(sg);
  }
  doc["extensionsUsed"].push_back("KHR_materials_pbrSpecularGlossiness");
  return doc;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_seed_corpus IN_FOLDER OUT_FOLDER\n";
    return 2;
  }
  try {
    fs::path in = argv[1], out = argv[2];
    fs::create_directories(out);
    int seeds = 0;
    for (const auto& entry : fs::directory_iterator(in)) {
      if (entry.path().extension() != ".gltf") continue;
      std::ifstream f(entry.path());
      json doc = json::parse(f);
      std::string name = entry.path().stem().string();
      writeFile(out / (name + ".glb"), glb(doc, in));
      embed(doc, "buffers", in, -1);
      embed(doc, "images", in, -1);
      writeFile(out / (name + ".gltf"), doc.dump());
      seeds += 2;
      if (seeds == 2) {  // one scene also with an IES light
        writeFile(out / (name + "_ies.gltf"), withIesLight(doc).dump());
        writeFile(out / (name + "_ies.glb"), glb(withIesLight(json::parse(std::ifstream(entry.path()))), in));
        seeds += 2;
      }
      if (name == "cornell_box") {  // also as an older exporter's specular-glossiness materials
        json sg = specularGlossiness(json::parse(std::ifstream(entry.path())));
        writeFile(out / (name + "_spec_gloss.glb"), glb(sg, in));
        embed(sg, "buffers", in, -1);
        embed(sg, "images", in, -1);
        writeFile(out / (name + "_spec_gloss.gltf"), sg.dump());
        seeds += 2;
      }
      const std::pair<const char*, bool (*)(json&)> variants[] = {
          {"_gpu_instancing", addGpuInstancing}, {"_texture_transform", addTextureTransforms}, {"_webp", addWebpSources},
          {"_object_settings", addObjectSettings}};
      for (const auto& [suffix, add] : variants) {
        json variant = doc;
        if (!add(variant)) continue;
        writeFile(out / (name + suffix + ".gltf"), variant.dump());
        ++seeds;
      }
    }
    const std::vector<glm::vec3> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
    for (const auto& [name, parts] : {std::pair{"meshopt_square.glb", irbake::testing::meshoptParts(square, indices)},
                                      std::pair{"draco_square.glb", irbake::testing::dracoParts(square, indices)}}) {
      const std::vector<uint8_t> bytes = irbake::testing::glbBytes(parts);
      writeFile(out / name, std::string(bytes.begin(), bytes.end()));
      ++seeds;
    }
    std::cout << "make_seed_corpus: " << seeds << " seeds in " << out.string() << "\n";
    return seeds > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "make_seed_corpus: " << e.what() << "\n";
    return 1;
  }
}
