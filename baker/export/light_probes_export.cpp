#include "export/light_probes_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "common/error.h"
#include "export/gltf_compact.h"
#include "export/gltf_export.h"
#include "scene/scene_limits.h"

namespace irbake {
namespace {

using json = nlohmann::json;
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kMaxSunSubdivisions = 16;

int addAccessor(GltfDocument& doc, const void* data, size_t bytes, int componentType, size_t count, const char* type) {
  const int view = doc.addBufferView(data, bytes);
  return doc.append("accessors", {{"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}});
}

// Accessor `key` of the extension as tightly packed bytes, checked against the type and count the grid needs.
AccessorBytes probeAccessor(const GltfDocument& doc, const json& ext, const char* key, int componentType,
                            const char* type, size_t count, const std::string& file,
                            const std::string& prefix = kLightProbesExtension) {
  const std::string what = prefix + "." + key;
  if (!ext.contains(key) || !ext[key].is_number_integer()) throw Error(ErrorCode::InvalidData, file, what + ": no accessor index");
  AccessorBytes a = readAccessor(doc, ext[key].get<int>(), file);
  if (a.componentType != componentType || a.type != type)
    throw Error(ErrorCode::InvalidData, file, what + ": accessor of componentType " + std::to_string(a.componentType) +
                                                  " " + a.type + ", expected " + std::to_string(componentType) + " " + type);
  if (a.count != count)
    throw Error(ErrorCode::InvalidData, file, what + ": " + std::to_string(a.count) + " elements, the grid needs " +
                                                  std::to_string(count));
  return a;
}

glm::vec3 vec3Of(const json& ext, const char* key, const std::string& file, const std::string& prefix = kLightProbesExtension) {
  const json* v = ext.contains(key) ? &ext[key] : nullptr;
  if (!v || !v->is_array() || v->size() != 3 || !(*v)[0].is_number() || !(*v)[1].is_number() || !(*v)[2].is_number())
    throw Error(ErrorCode::InvalidData, file, prefix + "." + key + ": needs 3 numbers");
  const glm::vec3 r((*v)[0].get<float>(), (*v)[1].get<float>(), (*v)[2].get<float>());
  if (!std::isfinite(r.x) || !std::isfinite(r.y) || !std::isfinite(r.z))
    throw Error(ErrorCode::InvalidData, file, prefix + "." + key + ": not finite");
  return r;
}

// A length in short notation for messages: "3e+38", "0.01".
std::string shortLength(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// The grid's place as a bake can write it: a spacing from kMinProbeSpacing to kMaxSceneCoordinate, and every grid
// point within kMaxSceneCoordinate of the origin (the bake's volume lies in the scene's coordinates). Beyond it the
// readers' visibility rays would start where Embree aborts, and a spacing of 1e-30 puts every point outside the
// grid.
void checkGridPlace(const LightProbeGrid& g, const std::string& file) {
  const std::string ext = kLightProbesExtension;
  if (!(g.spacing >= kMinProbeSpacing) || !(g.spacing <= kMaxSceneCoordinate))
    throw Error(ErrorCode::InvalidData, file, ext + ".spacing: " + shortLength(g.spacing) + " m is outside the " +
                                                  "0.01 … 1e9 m a bake writes");
  const double limit = kMaxSceneCoordinate * (1.0 + kSceneLimitSlack);
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(static_cast<double>(g.origin[a])) <= limit))
      throw Error(ErrorCode::InvalidData, file, ext + ".origin: " + shortLength(g.origin[a]) +
                                                    " m is beyond the supported 1e9 m");
    const double far = static_cast<double>(g.origin[a]) + static_cast<double>(g.spacing) * (g.counts[a] - 1);
    if (!(std::abs(far) <= limit))
      throw Error(ErrorCode::InvalidData, file, ext + ".counts: the grid reaches " + shortLength(far) +
                                                    " m, beyond the supported 1e9 m (origin + spacing × (counts − 1))");
  }
}

// The sun level (ProbeSunLevel) as the extension's optional `sun` object: its SH as floats; the probes'
// visibilities as bytes (k/255), the refined cells and the lattice's bits in 32-bit unsigned integers (packed: 1-byte
// accessors came back scrambled through meshopt, and floats would be 4× the size); `cells` and `fine` omitted when
// no cell is refined (glTF has no empty accessor).
json sunLevelJson(GltfDocument& doc, const ProbeSunLevel& sun) {
  const glm::vec3 d = sun.direction, e = sun.irradiance;
  std::vector<uint32_t> visibility((sun.visibility.size() + 3) / 4, 0u);
  for (size_t i = 0; i < sun.visibility.size(); ++i)
    visibility[i / 4] |= static_cast<uint32_t>(std::lround(std::clamp(sun.visibility[i], 0.0f, 1.0f) * 255.0f)) << (8 * (i % 4));
  json out = {{"direction", {d.x, d.y, d.z}},
              {"irradiance", {e.x, e.y, e.z}},
              {"sh", addAccessor(doc, sun.sh.data(), sizeof(ShCoefficients), kFloat, kShCoefficients, "VEC3")},
              {"visibility", addAccessor(doc, visibility.data(), visibility.size() * sizeof(uint32_t), kUnsignedInt,
                                         visibility.size(), "SCALAR")},
              {"subdivisions", sun.subdivisions}};
  if (!sun.cells.empty()) {
    out["cells"] = addAccessor(doc, sun.cells.data(), sun.cells.size() * sizeof(uint32_t), kUnsignedInt, sun.cells.size(), "SCALAR");
    out["fine"] = addAccessor(doc, sun.fine.data(), sun.fine.size() * sizeof(uint32_t), kUnsignedInt, sun.fine.size(), "SCALAR");
  }
  return out;
}

// The extension's `sun` object, checked against the grid: every field present and of its type (`cells` and
// `fine` together or neither), the SH finite, the irradiance finite and not negative, the cells ascending and each
// the base probe of a cell, the bits as many as the cells need. Throws Error(InvalidData, file) naming the field.
ProbeSunLevel readSunLevel(const GltfDocument& doc, const json& ext, const LightProbeGrid& g, const std::string& file) {
  const json& sun = ext["sun"];
  const std::string what = std::string(kLightProbesExtension) + ".sun";
  if (!sun.is_object()) throw Error(ErrorCode::InvalidData, file, what + ": not an object");
  ProbeSunLevel out;
  if (!sun.contains("subdivisions") || !sun["subdivisions"].is_number_integer() || sun["subdivisions"].get<int>() < 1 ||
      sun["subdivisions"].get<int>() > kMaxSunSubdivisions)
    throw Error(ErrorCode::InvalidData, file, what + ".subdivisions: needs a whole number from 1 to " + std::to_string(kMaxSunSubdivisions));
  out.subdivisions = sun["subdivisions"].get<int>();
  out.direction = vec3Of(sun, "direction", file, what);
  if (std::abs(glm::length(out.direction) - 1.0f) > 1e-3f) throw Error(ErrorCode::InvalidData, file, what + ".direction: not a unit vector");
  out.irradiance = vec3Of(sun, "irradiance", file, what);
  if (out.irradiance.x < 0.0f || out.irradiance.y < 0.0f || out.irradiance.z < 0.0f)
    throw Error(ErrorCode::InvalidData, file, what + ".irradiance: negative");
  const AccessorBytes sh = probeAccessor(doc, sun, "sh", kFloat, "VEC3", kShCoefficients, file, what);
  std::memcpy(out.sh.data(), sh.bytes.data(), sizeof(ShCoefficients));
  for (const glm::vec3& c : out.sh)
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z))
      throw Error(ErrorCode::InvalidData, file, what + ".sh: a non-finite coefficient");
  const size_t n = g.size();
  const AccessorBytes v = probeAccessor(doc, sun, "visibility", kUnsignedInt, "SCALAR", (n + 3) / 4, file, what);
  std::vector<uint32_t> packed((n + 3) / 4);
  std::memcpy(packed.data(), v.bytes.data(), packed.size() * sizeof(uint32_t));
  out.visibility.resize(n);
  for (size_t i = 0; i < n; ++i) out.visibility[i] = static_cast<float>((packed[i / 4] >> (8 * (i % 4))) & 255u) / 255.0f;
  if (!sun.contains("cells") && !sun.contains("fine")) return out;  // no refined cell
  if (!sun.contains("cells") || !sun["cells"].is_number_integer())
    throw Error(ErrorCode::InvalidData, file, what + ".cells: no accessor index");
  const AccessorBytes cells = readAccessor(doc, sun["cells"].get<int>(), file);
  if (cells.componentType != kUnsignedInt || cells.type != "SCALAR")
    throw Error(ErrorCode::InvalidData, file, what + ".cells: accessor of componentType " + std::to_string(cells.componentType) +
                                                  " " + cells.type + ", expected 5125 SCALAR");
  out.cells.resize(cells.count);
  std::memcpy(out.cells.data(), cells.bytes.data(), cells.count * sizeof(uint32_t));
  for (size_t c = 0; c < out.cells.size(); ++c) {
    const uint32_t i = out.cells[c];
    bool base = i < n;
    if (base) {
      const glm::ivec3 q = g.cell(i);
      for (int a = 0; a < 3; ++a) base = base && q[a] < std::max(1, g.counts[a] - 1);
    }
    if (!base) throw Error(ErrorCode::InvalidData, file, what + ".cells: " + std::to_string(i) + " is not a cell of the grid");
    if (c > 0 && i <= out.cells[c - 1])
      throw Error(ErrorCode::InvalidData, file, what + ".cells: not in ascending order at element " + std::to_string(c));
  }
  const AccessorBytes fine = probeAccessor(doc, sun, "fine", kUnsignedInt, "SCALAR",
                                           out.cells.size() * static_cast<size_t>(out.wordsPerCell()), file, what);
  out.fine.resize(fine.count);
  std::memcpy(out.fine.data(), fine.bytes.data(), fine.count * sizeof(uint32_t));
  return out;
}

// The exact emitters (ProbeEmitter) as the extension's optional `emitters` array: each a world-space triangle list
// (FLOAT VEC3), its radiance over π, and the probes' visibilities as bytes packed 4 to a 32-bit word (as `sun`'s).
json emittersJson(GltfDocument& doc, const std::vector<ProbeEmitter>& emitters) {
  json out = json::array();
  for (const ProbeEmitter& e : emitters) {
    std::vector<uint32_t> visibility((e.visibility.size() + 3) / 4, 0u);
    for (size_t i = 0; i < e.visibility.size(); ++i)
      visibility[i / 4] |= static_cast<uint32_t>(std::lround(std::clamp(e.visibility[i], 0.0f, 1.0f) * 255.0f)) << (8 * (i % 4));
    out.push_back({{"positions", addAccessor(doc, e.positions.data(), e.positions.size() * sizeof(glm::vec3), kFloat,
                                             e.positions.size(), "VEC3")},
                   {"radiance", {e.radiance.x, e.radiance.y, e.radiance.z}},
                   {"visibility", addAccessor(doc, visibility.data(), visibility.size() * sizeof(uint32_t), kUnsignedInt,
                                              visibility.size(), "SCALAR")}});
  }
  return out;
}

// The extension's `emitters` array, checked: each an object with a FLOAT VEC3 triangle list of finite positions
// (a whole number of triangles, at most kMaxExactEmitterTriangles in all), a finite non-negative radiance, and a
// visibility word per 4 probes. Throws Error(InvalidData, file) naming the field.
std::vector<ProbeEmitter> readEmitters(const GltfDocument& doc, const json& ext, const LightProbeGrid& g, const std::string& file) {
  const json& list = ext["emitters"];
  const std::string what = std::string(kLightProbesExtension) + ".emitters";
  if (!list.is_array()) throw Error(ErrorCode::InvalidData, file, what + ": not an array");
  std::vector<ProbeEmitter> out;
  size_t triangles = 0;
  const size_t n = g.size();
  for (size_t k = 0; k < list.size(); ++k) {
    const std::string at = what + "[" + std::to_string(k) + "]";
    if (!list[k].is_object()) throw Error(ErrorCode::InvalidData, file, at + ": not an object");
    ProbeEmitter e;
    if (!list[k].contains("positions") || !list[k]["positions"].is_number_integer())
      throw Error(ErrorCode::InvalidData, file, at + ".positions: no accessor index");
    const AccessorBytes pos = readAccessor(doc, list[k]["positions"].get<int>(), file);
    if (pos.componentType != kFloat || pos.type != "VEC3")
      throw Error(ErrorCode::InvalidData, file, at + ".positions: accessor of componentType " + std::to_string(pos.componentType) +
                                                    " " + pos.type + ", expected 5126 VEC3");
    if (pos.count == 0 || pos.count % 3 != 0)
      throw Error(ErrorCode::InvalidData, file, at + ".positions: " + std::to_string(pos.count) + " elements, not a whole number of triangles");
    triangles += pos.count / 3;
    if (triangles > static_cast<size_t>(kMaxExactEmitterTriangles))
      throw Error(ErrorCode::InvalidData, file, what + ": more than " + std::to_string(kMaxExactEmitterTriangles) + " triangles");
    e.positions.resize(pos.count);
    std::memcpy(e.positions.data(), pos.bytes.data(), pos.count * sizeof(glm::vec3));
    for (const glm::vec3& x : e.positions)
      if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
        throw Error(ErrorCode::InvalidData, file, at + ".positions: a non-finite position");
    e.radiance = vec3Of(list[k], "radiance", file, at);
    if (e.radiance.x < 0.0f || e.radiance.y < 0.0f || e.radiance.z < 0.0f)
      throw Error(ErrorCode::InvalidData, file, at + ".radiance: negative");
    const AccessorBytes v = probeAccessor(doc, list[k], "visibility", kUnsignedInt, "SCALAR", (n + 3) / 4, file, at);
    std::vector<uint32_t> packed((n + 3) / 4);
    std::memcpy(packed.data(), v.bytes.data(), packed.size() * sizeof(uint32_t));
    e.visibility.resize(n);
    for (size_t i = 0; i < n; ++i) e.visibility[i] = static_cast<float>((packed[i / 4] >> (8 * (i % 4))) & 255u) / 255.0f;
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace

void addLightProbesExtension(GltfDocument& doc, const LightProbeGrid& grid) {
  const size_t n = grid.size();
  std::vector<glm::vec3> coefficients;
  coefficients.reserve(n * kShCoefficients);
  for (const ShCoefficients& c : grid.coefficients) coefficients.insert(coefficients.end(), c.begin(), c.end());
  // Validity as float 0/1: an UNSIGNED_BYTE accessor came back scrambled through gltf-transform optimize (its
  // meshopt compression pads such streams to 4-byte elements), floats come back bit for bit.
  std::vector<float> valid(grid.valid.begin(), grid.valid.end());
  json ext = {{"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
              {"spacing", grid.spacing},
              {"counts", {grid.counts.x, grid.counts.y, grid.counts.z}},
              {"coefficients", addAccessor(doc, coefficients.data(), coefficients.size() * sizeof(glm::vec3), kFloat,
                                           coefficients.size(), "VEC3")},
              {"offsets", addAccessor(doc, grid.offsets.data(), n * sizeof(glm::vec3), kFloat, n, "VEC3")},
              {"valid", addAccessor(doc, valid.data(), n * sizeof(float), kFloat, n, "SCALAR")},
              {"units", "irradiance/pi"},
              {"convention", "three.js SphericalHarmonics3"}};
  if (grid.sun.present() && grid.sun.visibility.size() == n) ext["sun"] = sunLevelJson(doc, grid.sun);
  if (!grid.emitters.empty()) ext["emitters"] = emittersJson(doc, grid.emitters);
  doc.root["extensions"][kLightProbesExtension] = std::move(ext);
  doc.useExtension(kLightProbesExtension);
}

void removeLightProbesExtension(json& root) { removeRootExtension(root, kLightProbesExtension); }

LightProbeGrid readLightProbes(const std::filesystem::path& path) { return readLightProbes(documentFromSource(path), path.string()); }

LightProbeGrid readLightProbes(const GltfDocument& doc, const std::string& file) {
  const json* ext = nullptr;
  if (doc.root.contains("extensions") && doc.root["extensions"].is_object() && doc.root["extensions"].contains(kLightProbesExtension))
    ext = &doc.root["extensions"][kLightProbesExtension];
  if (!ext || !ext->is_object())
    throw Error(ErrorCode::InvalidData, file, std::string("no ") + kLightProbesExtension + " extension (baked with --probes off?)");
  LightProbeGrid g;
  g.origin = vec3Of(*ext, "origin", file);
  const glm::vec3 counts = vec3Of(*ext, "counts", file);
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    if (!(counts[a] >= 1.0f) || counts[a] != std::floor(counts[a]) || counts[a] > 1e6f)
      throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ".counts: " + std::to_string(counts[a]) +
                                                    " is not a whole number from 1 to 10^6");
    g.counts[a] = static_cast<int>(counts[a]);
    total *= counts[a];
  }
  if (total > 1e8) throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ".counts: more than 10^8 probes");
  if (!ext->contains("spacing") || !(*ext)["spacing"].is_number() || !((*ext)["spacing"].get<float>() > 0.0f) ||
      !std::isfinite((*ext)["spacing"].get<float>()))
    throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ".spacing: needs a positive finite number");
  g.spacing = (*ext)["spacing"].get<float>();
  checkGridPlace(g, file);
  const size_t n = g.size();
  const AccessorBytes c = probeAccessor(doc, *ext, "coefficients", kFloat, "VEC3", n * kShCoefficients, file);
  const AccessorBytes o = probeAccessor(doc, *ext, "offsets", kFloat, "VEC3", n, file);
  const AccessorBytes v = probeAccessor(doc, *ext, "valid", kFloat, "SCALAR", n, file);
  g.coefficients.resize(n);
  g.offsets.resize(n);
  std::memcpy(g.coefficients.data(), c.bytes.data(), n * sizeof(ShCoefficients));
  std::memcpy(g.offsets.data(), o.bytes.data(), n * sizeof(glm::vec3));
  std::vector<float> valid(n);
  std::memcpy(valid.data(), v.bytes.data(), n * sizeof(float));
  g.valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    bool finite = std::isfinite(g.offsets[i].x) && std::isfinite(g.offsets[i].y) && std::isfinite(g.offsets[i].z);
    for (const glm::vec3& k : g.coefficients[i]) finite = finite && std::isfinite(k.x) && std::isfinite(k.y) && std::isfinite(k.z);
    if (!finite)
      throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ": probe " + std::to_string(i) +
                                                    " has a non-finite coefficient or offset");
    const glm::vec3 away = glm::abs(g.offsets[i]);
    if (std::max({away.x, away.y, away.z}) > g.spacing)
      throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ".offsets: probe " + std::to_string(i) +
                                                    " is moved " + shortLength(std::max({away.x, away.y, away.z})) +
                                                    " m from its grid point, more than a spacing (a bake moves it at most half)");
    if (valid[i] != 0.0f && valid[i] != 1.0f)
      throw Error(ErrorCode::InvalidData, file, std::string(kLightProbesExtension) + ".valid: probe " + std::to_string(i) +
                                                    " holds " + std::to_string(valid[i]) + " (0 or 1)");
    g.valid[i] = valid[i] == 1.0f;
  }
  if (ext->contains("sun")) g.sun = readSunLevel(doc, *ext, g, file);
  if (ext->contains("emitters")) g.emitters = readEmitters(doc, *ext, g, file);
  return g;
}

}  // namespace irbake
