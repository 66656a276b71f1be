#include "atlas/atlas_from_bake.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "atlas/atlas_stats.h"
#include "common/checksum.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "scene/gltf_loader.h"
#include "scene/gltf_source.h"

namespace irbake {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr uint32_t kUnset = std::numeric_limits<uint32_t>::max();

SourcePrimitiveKey keyOf(const Primitive& p) { return {p.node, p.gltfMesh, p.gltfPrimitive, p.instance}; }
SourcePrimitiveKey keyOf(const SourcePrimitiveRecord& r) { return {r.node, r.mesh, r.primitive, r.instance}; }

// mesh "name" (node N, mesh M, primitive P, instance I): the words every refusal names a primitive with.
std::string describe(const SourcePrimitiveRecord& r) {
  std::string text = "mesh \"" + r.name + "\" (node " + std::to_string(r.node) + ", mesh " + std::to_string(r.mesh) +
                     ", primitive " + std::to_string(r.primitive);
  if (r.instance >= 0) text += ", instance " + std::to_string(r.instance);
  return text + ")";
}

// A malformed record: the file and the field.
[[noreturn]] void malformed(const fs::path& file, const std::string& what) {
  throw Error(ErrorCode::InvalidData, file.string(), "--atlas-from: malformed " + std::string(kAtlasRecordKey) + ": " + what);
}

int intField(const json& j, const char* key, const fs::path& file, const std::string& where) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number_integer()) malformed(file, where + " has no integer \"" + key + "\"");
  return j[key].get<int>();
}

SourcePrimitiveRecord recordFromJson(const json& j, const fs::path& file, size_t index) {
  const std::string where = "primitives[" + std::to_string(index) + "]";
  SourcePrimitiveRecord r;
  r.node = intField(j, "node", file, where);
  r.mesh = intField(j, "mesh", file, where);
  r.primitive = intField(j, "primitive", file, where);
  r.instance = intField(j, "instance", file, where);
  r.vertices = size_t(std::max(0, intField(j, "vertices", file, where)));
  r.triangles = size_t(std::max(0, intField(j, "triangles", file, where)));
  if (!j.contains("positions") || !j["positions"].is_string()) malformed(file, where + " has no \"positions\" hash");
  r.positions = j["positions"].get<std::string>();
  r.name = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : std::string();
  return r;
}

// The record's pages, padding, density and primitives.
void readRecord(const json& record, BakedAtlas& baked) {
  const fs::path& file = baked.file;
  if (!record.contains("pages") || !record["pages"].is_array() || record["pages"].empty()) malformed(file, "no pages");
  for (size_t i = 0; i < record["pages"].size(); ++i) {
    const std::string where = "pages[" + std::to_string(i) + "]";
    AtlasPage page{intField(record["pages"][i], "width", file, where), intField(record["pages"][i], "height", file, where)};
    if (page.width <= 0 || page.height <= 0) malformed(file, where + " is not a positive size");
    baked.pages.push_back(page);
  }
  baked.padding = intField(record, "padding", file, "the record");
  if (!record.contains("texelsPerUnit") || !record["texelsPerUnit"].is_number()) malformed(file, "no texelsPerUnit");
  baked.texelsPerUnit = record["texelsPerUnit"].get<double>();
  if (!record.contains("primitives") || !record["primitives"].is_array()) malformed(file, "no primitives");
  for (size_t i = 0; i < record["primitives"].size(); ++i) baked.sources.push_back(recordFromJson(record["primitives"][i], file, i));
  baked.geometryHash = record.value("geometryHash", std::string());
}

// The source primitive of an exported primitive: its extras.lightmap.source, [node, mesh, primitive, instance].
SourcePrimitiveKey partSource(const json& doc, const Primitive& p, const fs::path& file) {
  const std::string where = "mesh " + std::to_string(p.gltfMesh) + " primitive " + std::to_string(p.gltfPrimitive);
  const json* source = nullptr;
  if (doc.contains("meshes") && doc["meshes"].is_array() && size_t(p.gltfMesh) < doc["meshes"].size()) {
    const json& mesh = doc["meshes"][size_t(p.gltfMesh)];
    if (mesh.is_object() && mesh.contains("primitives") && mesh["primitives"].is_array() &&
        size_t(p.gltfPrimitive) < mesh["primitives"].size()) {
      const json& prim = mesh["primitives"][size_t(p.gltfPrimitive)];
      if (prim.contains("extras") && prim["extras"].is_object() && prim["extras"].contains("lightmap") &&
          prim["extras"]["lightmap"].is_object() && prim["extras"]["lightmap"].contains("source"))
        source = &prim["extras"]["lightmap"]["source"];
    }
  }
  if (!source || !source->is_array() || source->size() != 4)
    throw Error(ErrorCode::InvalidData, file.string(), "--atlas-from: " + where + " has a light map but no extras.lightmap.source");
  SourcePrimitiveKey key{};
  for (size_t i = 0; i < 4; ++i) {
    if (!(*source)[i].is_number_integer()) throw Error(ErrorCode::InvalidData, file.string(), "--atlas-from: " + where + ": extras.lightmap.source is not 4 integers");
    key[i] = (*source)[i].get<int>();
  }
  return key;
}

// Each light-mapped primitive of the export, checked against the record's pages.
void readParts(const json& doc, BakedAtlas& baked) {
  LoadOptions load;
  load.decodeImages = false;
  load.computeMissingNormals = false;  // the vertices as written: no split for flat normals
  Scene scene = loadScene(baked.file, load);
  for (Primitive& p : scene.primitives) {
    if (p.lightmap.page < 0) continue;
    const std::string where = "mesh " + std::to_string(p.gltfMesh) + " primitive " + std::to_string(p.gltfPrimitive);
    if (size_t(p.lightmap.page) >= baked.pages.size() || p.lightmap.width != baked.pages[size_t(p.lightmap.page)].width ||
        p.lightmap.height != baked.pages[size_t(p.lightmap.page)].height)
      throw Error(ErrorCode::InvalidData, baked.file.string(), "--atlas-from: " + where + ": its extras.lightmap page is not one of the record's pages");
    if (p.uv1.size() != p.positions.size())
      throw Error(ErrorCode::InvalidData, baked.file.string(), "--atlas-from: " + where + " has a light map but no TEXCOORD_1");
    BakedPart part;
    part.source = partSource(doc, p, baked.file);
    part.primitive = std::move(p);
    baked.parts.push_back(std::move(part));
  }
}

// Refuses a scene whose light-mapped geometry is not the record's, naming the first primitive that differs.
void checkSameGeometry(const Scene& scene, const std::vector<SourcePrimitiveRecord>& current, const BakedAtlas& baked) {
  std::map<SourcePrimitiveKey, const SourcePrimitiveRecord*> earlier;
  for (const SourcePrimitiveRecord& r : baked.sources) earlier[keyOf(r)] = &r;
  const std::string lead = "the geometry differs from the bake " + baked.file.string() + " (--atlas-from): ";
  auto refuse = [&](const std::string& what) { throw Error(ErrorCode::InvalidData, scene.sourcePath, lead + what); };
  for (const SourcePrimitiveRecord& r : current) {
    const auto it = earlier.find(keyOf(r));
    if (it == earlier.end()) refuse(describe(r) + " is not in its atlas");
    const SourcePrimitiveRecord& e = *it->second;
    if (r.vertices != e.vertices)
      refuse(describe(r) + " has " + std::to_string(r.vertices) + " vertices, the bake's " + std::to_string(e.vertices));
    if (r.triangles != e.triangles)
      refuse(describe(r) + " has " + std::to_string(r.triangles) + " triangles, the bake's " + std::to_string(e.triangles));
    if (r.positions != e.positions)
      refuse(describe(r) + ": its positions differ (positions hash " + r.positions + ", the bake's " + e.positions + ")");
    earlier.erase(it);
  }
  if (!earlier.empty()) refuse(describe(*earlier.begin()->second) + " is in its atlas but gets no light map in this scene");
}

// The largest difference of one coordinate between triangle t of src and triangle j of part, corner by corner.
float triangleDistance(const Primitive& src, uint32_t t, const Primitive& part, size_t j) {
  float d = 0.0f;
  for (int c = 0; c < 3; ++c) {
    const glm::vec3 delta = glm::abs(src.positions[src.indices[3 * t + c]] - part.positions[part.indices[3 * j + c]]);
    d = std::max({d, delta.x, delta.y, delta.z});
  }
  return d;
}

// Which triangle of src each part's triangles are. The atlas emits a primitive's triangles in its order, each
// part (page) a subsequence, so each of src's triangles goes to the part whose next triangle lies on it.
std::vector<std::vector<uint32_t>> sourceTriangles(const Primitive& src, const std::vector<const Primitive*>& parts,
                                                   float tolerance, const std::string& file, const std::string& what) {
  std::vector<std::vector<uint32_t>> of(parts.size());
  std::vector<size_t> next(parts.size(), 0);
  for (uint32_t t = 0; t < src.triangleCount(); ++t) {
    size_t best = parts.size();
    float bestDistance = tolerance;
    for (size_t p = 0; p < parts.size(); ++p) {
      if (next[p] >= parts[p]->triangleCount()) continue;
      const float d = triangleDistance(src, t, *parts[p], next[p]);
      if (d <= bestDistance) best = p, bestDistance = d;
    }
    if (best == parts.size())
      throw Error(ErrorCode::InvalidData, file, what + ": triangle " + std::to_string(t) + " is on none of the bake's parts");
    of[best].push_back(t);
    ++next[best];
  }
  for (size_t p = 0; p < parts.size(); ++p)
    if (next[p] != parts[p]->triangleCount())
      throw Error(ErrorCode::InvalidData, file, what + ": the bake's part on page " + std::to_string(parts[p]->lightmap.page) +
                                                    " has triangles this scene does not");
  return of;
}

// One part of src as the earlier bake's atlas made it: its vertices (each the source vertex its corners name),
// its triangles and TEXCOORD_1.
Primitive rebuiltPart(const Primitive& src, const Primitive& part, const std::vector<uint32_t>& triangles, bool nameThePage,
                      const std::string& file, const std::string& what) {
  std::vector<uint32_t> at(part.positions.size(), kUnset);
  for (size_t j = 0; j < triangles.size(); ++j)
    for (int c = 0; c < 3; ++c) {
      uint32_t& v = at[part.indices[3 * j + c]];
      const uint32_t s = src.indices[3 * size_t(triangles[j]) + c];
      if (v != kUnset && v != s) throw Error(ErrorCode::InvalidData, file, what + ": the bake's vertices join corners this scene keeps apart");
      v = s;
    }
  if (std::find(at.begin(), at.end(), kUnset) != at.end())
    throw Error(ErrorCode::InvalidData, file, what + ": the bake's part on page " + std::to_string(part.lightmap.page) + " has unused vertices");
  Primitive dst = primitivePart(src, part.lightmap, nameThePage);
  const size_t n = src.positions.size();
  for (uint32_t v : at) {
    dst.positions.push_back(src.positions[v]);
    if (src.normals.size() == n) dst.normals.push_back(src.normals[v]);
    if (src.uv0.size() == n) dst.uv0.push_back(src.uv0[v]);
    if (src.tangents.size() == n) dst.tangents.push_back(src.tangents[v]);
    dst.sourceVertex.push_back(src.sourceVertex.empty() ? v : src.sourceVertex[v]);
  }
  dst.uv1 = part.uv1;
  dst.indices = part.indices;
  return dst;
}

// Refuses what would make an atlas of its own, warns where an object's lightmapScale is not followed.
void checkAtlasOptions(const Scene& scene, const AtlasOptions& options, const fs::path& file) {
  const std::string why = " would make an atlas of its own: --atlas-from " + file.string() + " keeps the bake's";
  if (options.texelsPerUnit > 0.0) throw Error(ErrorCode::Usage, "", "--texels-per-unit" + why);
  if (options.maxPageSize != 0) throw Error(ErrorCode::Usage, "", "--page-size" + why);
  if (options.keepUv1) throw Error(ErrorCode::Usage, "", "keeping the scene's TEXCOORD_1" + why);
  if (std::any_of(scene.primitives.begin(), scene.primitives.end(), [](const Primitive& p) { return p.lightmapScale != 1.0f; }))
    log::warn("atlas: --atlas-from keeps the bake's atlas: the objects' lightmapScale is not applied again");
}

}  // namespace

std::vector<SourcePrimitiveRecord> recordSourcePrimitives(const Scene& scene) {
  std::vector<SourcePrimitiveRecord> records;
  for (const Primitive& p : scene.primitives) {
    if (!p.getsLightmap() || p.triangleCount() == 0) continue;
    SourcePrimitiveRecord r;
    r.node = p.node, r.mesh = p.gltfMesh, r.primitive = p.gltfPrimitive, r.instance = p.instance;
    r.name = p.name;
    r.vertices = p.positions.size();
    r.triangles = p.triangleCount();
    Checksum64 hash;
    hash.add(p.positions.data(), p.positions.size() * sizeof(glm::vec3));
    hash.add(p.indices.data(), p.indices.size() * sizeof(uint32_t));
    r.positions = hash.hex();
    records.push_back(std::move(r));
  }
  return records;
}

std::string geometryHash(const std::vector<SourcePrimitiveRecord>& records) {
  Checksum64 hash;
  for (const SourcePrimitiveRecord& r : records) {
    const int64_t numbers[6] = {r.node, r.mesh, r.primitive, r.instance, int64_t(r.vertices), int64_t(r.triangles)};
    hash.add(numbers, sizeof(numbers));
    hash.add(r.positions);
  }
  return hash.hex();
}

json atlasRecordJson(const AtlasResult& atlas) {
  json pages = json::array();
  for (const AtlasPage& p : atlas.pages) pages.push_back({{"width", p.width}, {"height", p.height}});
  json primitives = json::array();
  for (const SourcePrimitiveRecord& r : atlas.sources)
    primitives.push_back({{"node", r.node}, {"mesh", r.mesh}, {"primitive", r.primitive}, {"instance", r.instance}, {"name", r.name},
                          {"vertices", r.vertices}, {"triangles", r.triangles}, {"positions", r.positions}});
  return {{"geometryHash", geometryHash(atlas.sources)}, {"pages", pages}, {"padding", atlas.padding},
          {"texelsPerUnit", atlas.stats.texelsPerUnit}, {"primitives", primitives}};
}

BakedAtlas readBakedAtlas(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw Error(ErrorCode::Io, file.string(), "--atlas-from: no such file");
  BakedAtlas baked;
  baked.file = file;
  const GltfSource source = readGltfSource(file);
  const json& doc = source.json;
  if (!doc.contains("extras") || !doc["extras"].is_object() || !doc["extras"].contains(kAtlasRecordKey) ||
      !doc["extras"][kAtlasRecordKey].is_object())
    throw Error(ErrorCode::InvalidData, file.string(),
                "--atlas-from: not an irbake bake (its root extras has no " + std::string(kAtlasRecordKey) +
                    " record; bake the scene with this irbake first)");
  readRecord(doc["extras"][kAtlasRecordKey], baked);
  readParts(doc, baked);
  return baked;
}

AtlasResult atlasFromBake(Scene& scene, const BakedAtlas& baked, const AtlasOptions& options) {
  const Stopwatch total;
  checkAtlasOptions(scene, options, baked.file);
  AtlasResult result;
  result.pages = baked.pages;
  result.padding = baked.padding;
  result.sources = recordSourcePrimitives(scene);
  checkSameGeometry(scene, result.sources, baked);
  std::map<SourcePrimitiveKey, std::vector<const Primitive*>> partsOf;
  for (const BakedPart& part : baked.parts) partsOf[part.source].push_back(&part.primitive);
  // The same float arithmetic gives the same world positions; GPU instances' nodes, written as a product of
  // their own, may differ in the last bits.
  const Bounds3 bounds = scene.bounds();
  const float tolerance = 1e-5f * std::max(1.0f, glm::length(bounds.max - bounds.min));
  std::vector<Primitive> out;
  for (const Primitive& src : scene.primitives) {
    if (!src.getsLightmap() || src.triangleCount() == 0) {
      out.push_back(src);
      out.back().uv1.clear();
      out.back().lightmap = LightmapRef{};
      continue;
    }
    const auto& parts = partsOf[keyOf(src)];
    const std::string what = "the bake " + baked.file.string() + " (--atlas-from), mesh \"" + src.name + "\" (node " + std::to_string(src.node) + ")";
    if (parts.empty()) throw Error(ErrorCode::InvalidData, scene.sourcePath, what + ": no light-mapped primitive");
    const auto triangles = sourceTriangles(src, parts, tolerance, scene.sourcePath, what);
    for (size_t p = 0; p < parts.size(); ++p)
      out.push_back(rebuiltPart(src, *parts[p], triangles[p], parts.size() > 1, scene.sourcePath, what));
  }
  scene.primitives = std::move(out);
  AtlasStats& stats = result.stats;
  stats.texelsPerUnit = baked.texelsPerUnit;
  for (const AtlasPage& p : result.pages) stats.pageSize = std::max({stats.pageSize, p.width, p.height});
  atlas::measureAtlas(scene, result.pages, stats);
  stats.secondsTotal = total.seconds();
  log::info("atlas: from " + baked.file.string() + ": " + std::to_string(result.pages.size()) + " page(s), " +
            std::to_string(stats.charts) + " charts, no unwrap");
  return result;
}

AtlasEstimate estimateBakedAtlas(const Scene& scene, const BakedAtlas& baked) {
  AtlasEstimate estimate;
  estimate.texelsPerUnit = baked.texelsPerUnit;
  estimate.texels = scaledLightmapArea(scene) * baked.texelsPerUnit * baked.texelsPerUnit;
  for (const AtlasPage& p : baked.pages) {
    estimate.pageTexels += double(p.width) * double(p.height);
    estimate.pageSize = std::max({estimate.pageSize, p.width, p.height});
  }
  estimate.pages = int(baked.pages.size());
  return estimate;
}

}  // namespace irbake
