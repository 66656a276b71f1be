// make_seed_corpus IN_FOLDER OUT_FOLDER: packs every IN_FOLDER/*.gltf (irbake samples output: JSON +
// .bin + images beside it) into two self-contained seeds the fuzzer can mutate as one input each:
// NAME.glb (buffer 0 in the BIN chunk, other files as data URIs) and NAME.gltf (every file as a
// base64 data URI). Our own scenes only: no third-party file enters the corpus.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

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
      std::vector<std::pair<std::string, json>> variants = {{name, doc}};
      if (name == "cornell_box") variants.emplace_back(name + "_spec_gloss", specularGlossiness(doc));
      for (auto& [variant, d] : variants) {
        writeFile(out / (variant + ".glb"), glb(d, in));
        embed(d, "buffers", in, -1);
        embed(d, "images", in, -1);
        writeFile(out / (variant + ".gltf"), d.dump());
        seeds += 2;
      }
    }
    std::cout << "make_seed_corpus: " << seeds << " seeds in " << out.string() << "\n";
    return seeds > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "make_seed_corpus: " << e.what() << "\n";
    return 1;
  }
}
