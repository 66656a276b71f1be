#include "viewer_scene.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <map>
#include <numeric>
#include <unordered_map>

#include "common/error.h"
#include "common/log.h"
#include "export/map_encoding.h"
#include "scene/gltf_loader.h"
#include "scene/gltf_source.h"
#include "scene/scene_files.h"

namespace irbake::view {

LightmapSource lightmapSourceOf(const ViewerScene& v, const Primitive& p) {
  if (p.uv1.size() == p.positions.size() && !p.uv1.empty()) {
    if (p.lightmap.page >= 0 && p.lightmap.page < static_cast<int>(v.pages.size()) &&
        v.pages[p.lightmap.page].size() > 0)
      return LightmapSource::Page;
    const Material& m = v.scene.materials.at(p.material);
    if (m.lightmapTexture >= 0 && m.lightmapTexture < static_cast<int>(v.scene.textures.size()))
      return LightmapSource::MaterialTexture;
  }
  return LightmapSource::None;
}

DirectionalSource directionalSourceOf(const ViewerScene& v, const Primitive& p) {
  const LightmapSource l0 = lightmapSourceOf(v, p);
  if (l0 == LightmapSource::None) return DirectionalSource::None;
  bool pages = p.lightmap.page >= 0;
  for (const auto& axis : v.directionalPages)
    pages = pages && p.lightmap.page < static_cast<int>(axis.size()) && axis[p.lightmap.page].size() > 0 &&
            axis[p.lightmap.page].texels.size() == axis[p.lightmap.page].size();
  if (pages) return DirectionalSource::Pages;
  const Material& m = v.scene.materials.at(p.material);
  if (!m.hasDirectionalTextures()) return DirectionalSource::None;
  for (int t : m.directionalTextures)
    if (t >= static_cast<int>(v.scene.textures.size()) || v.scene.textures[t].texels.empty()) return DirectionalSource::None;
  return DirectionalSource::MaterialTextures;
}

ViewerScene makeViewerScene(Scene scene, std::vector<Lightmap> pages, std::array<std::vector<Lightmap>, 3> directionalPages) {
  ViewerScene v;
  v.scene = std::move(scene);
  v.pages = std::move(pages);
  v.directionalPages = std::move(directionalPages);
  size_t unlit = 0;
  for (const auto& p : v.scene.primitives)
    if (lightmapSourceOf(v, p) == LightmapSource::None && p.mode != ObjectMode::Probes) ++unlit;  // probe-lit: lit
  const std::string where = v.scene.sourcePath.empty() ? std::string("scene") : v.scene.sourcePath;
  if (!v.scene.primitives.empty() && unlit == v.scene.primitives.size())
    v.warnings.push_back(where + ": no light map: showing albedo only");
  else if (unlit > 0)
    v.warnings.push_back(where + ": " + std::to_string(unlit) + " primitive(s) without a light map show albedo only");
  return v;
}

namespace {

// glTF 2.0's rules for a perspective camera (camera.perspective): yfov > 0 (and < π, or there is no projection),
// znear > 0, zfar (when present) > znear, aspectRatio (when present) > 0, each a finite 32-bit float. The loader
// puts a default in place of a yfov or znear ≤ 0; the viewer refuses them, as any view from such a camera would be
// a guess or black. Orthographic cameras are skipped by the loader, so their fields are not read.
void checkCameras(const nlohmann::json& root, const std::string& file) {
  const auto cameras = root.find("cameras");
  if (cameras == root.end() || !cameras->is_array()) return;
  for (size_t i = 0; i < cameras->size(); ++i) {
    const nlohmann::json& c = (*cameras)[i];
    if (!c.is_object() || c.value("type", std::string()) != "perspective") continue;
    const std::string name = c.contains("name") && c["name"].is_string() ? c["name"].get<std::string>() : "";
    const std::string camera = "camera " + std::to_string(i) + (name.empty() ? "" : " ('" + name + "')");
    const std::string what = camera + ": perspective.";
    const auto p = c.find("perspective");
    if (p == c.end() || !p->is_object())
      throw Error(ErrorCode::InvalidData, file, camera + ": type perspective without a perspective object");
    // Reads `key` into v: false when it is absent and optional; throws when it is absent and required, not a
    // number or not finite (as a 32-bit float too).
    auto number = [&](const char* key, bool required, double& v) {
      const auto it = p->find(key);
      if (it == p->end()) {
        if (required) throw Error(ErrorCode::InvalidData, file, what + key + " is missing (glTF requires it)");
        return false;
      }
      v = it->is_number() ? it->get<double>() : std::nan("");
      if (!std::isfinite(v) || !std::isfinite(static_cast<float>(v)))
        throw Error(ErrorCode::InvalidData, file, what + key + " " + it->dump() + " is not a finite number");
      return true;
    };
    double yfov = 0.0, znear = 0.0, zfar = 0.0, aspect = 0.0;
    number("yfov", true, yfov);
    if (!(yfov > 0.0 && static_cast<float>(yfov) < 3.14159265f))
      throw Error(ErrorCode::InvalidData, file,
                  what + "yfov " + (*p)["yfov"].dump() + " rad: a perspective view needs 0 < yfov < π");
    number("znear", true, znear);
    if (!(znear > 0.0 && static_cast<float>(znear) > 0.0f))
      throw Error(ErrorCode::InvalidData, file, what + "znear " + (*p)["znear"].dump() + " must be greater than 0");
    if (number("zfar", false, zfar) && !(static_cast<float>(zfar) > static_cast<float>(znear)))
      throw Error(ErrorCode::InvalidData, file,
                  what + "zfar " + (*p)["zfar"].dump() + " must be greater than znear " + (*p)["znear"].dump());
    if (number("aspectRatio", false, aspect) && !(aspect > 0.0 && static_cast<float>(aspect) > 0.0f))
      throw Error(ErrorCode::InvalidData, file, what + "aspectRatio " + (*p)["aspectRatio"].dump() + " must be greater than 0");
  }
}

}  // namespace

ViewerScene loadViewerScene(const std::filesystem::path& path) {
  LoadOptions options;
  options.shadingMaps = true;  // the normal maps, tangents and directional maps a bake does not read
  GltfSource source = readGltfSource(path);
  checkCameras(source.json, path.string());
  Scene scene = loadSceneFromBytes(std::move(source.bytes), path, options);
  // The viewer reads every light map through TEXCOORD_1 (docs/export.md); a map meant for another set would
  // show garbage, so it is refused.
  for (const Material& m : scene.materials)
    if (m.lightmapTexture >= 0 && m.lightmapTexCoord != 1)
      throw Error(ErrorCode::InvalidData, path.string(),
                  "material " + std::to_string(m.gltfMaterial) + " ('" + m.name + "'): MOZ_lightmap texCoord " +
                      std::to_string(m.lightmapTexCoord) + ", but light maps use TEXCOORD_1");
  std::vector<Lightmap> pages;
  std::vector<std::string> warnings;
  // The float pages carry the full range; if one cannot be read the PNG × intensity still shows.
  const MapEncoding& exr = mapEncoding(MapEncodingKind::Exr);
  for (size_t i = 0; i < scene.lightmapExrPaths.size(); ++i) {
    try {
      Lightmap m = exr.readFile(scene.lightmapExrPaths[i], {}).map;
      m.page = static_cast<int>(i);
      pages.push_back(std::move(m));
    } catch (const Error& e) {
      warnings.push_back(std::string(e.what()) + ": using the MOZ_lightmap textures instead");
      pages.clear();
      break;
    }
  }
  // The L1 pages named by each page's materials (the same three files for every material of a page).
  std::array<std::vector<Lightmap>, 3> directional;
  std::map<int, const Material*> materialOfPage;
  for (const Primitive& p : scene.primitives) {
    const Material& m = scene.materials.at(p.material);
    if (p.lightmap.page >= 0 && !m.directionalExrPaths[0].empty()) materialOfPage.emplace(p.lightmap.page, &m);
  }
  try {
    for (const auto& [page, m] : materialOfPage)
      for (int k = 0; k < 3; ++k) {
        if (directional[k].size() <= static_cast<size_t>(page)) directional[k].resize(page + 1);
        directional[k][page] = exr.readFile(m->directionalExrPaths[k], {}).map;
        directional[k][page].page = page;
      }
  } catch (const Error& e) {
    warnings.push_back(std::string(e.what()) + ": using the IRBAKE_lightmap_directional PNGs instead");
    directional = {};
  }
  std::vector<std::filesystem::path> inputFiles = sceneInputFiles(path);
  inputFiles.insert(inputFiles.end(), scene.lightmapExrPaths.begin(), scene.lightmapExrPaths.end());
  for (const auto& [page, m] : materialOfPage)
    for (int k = 0; k < 3; ++k) inputFiles.push_back(m->directionalExrPaths[k]);
  ViewerScene v = makeViewerScene(std::move(scene), std::move(pages), std::move(directional));
  v.inputFiles = std::move(inputFiles);
  v.warnings.insert(v.warnings.begin(), warnings.begin(), warnings.end());
  for (const auto& w : v.scene.stats.warnings) v.warnings.push_back(w);
  return v;
}

namespace {

// The orientation of triangle t in UV space: +1 counter-clockwise, -1 mirrored, 0 no UV area.
int uvOrientation(const Primitive& p, const std::vector<glm::vec2>& uv, size_t t) {
  const uint32_t a = p.indices[t], b = p.indices[t + 1], c = p.indices[t + 2];
  if (a >= uv.size() || b >= uv.size() || c >= uv.size()) return 0;
  const glm::dvec2 d1 = glm::dvec2(uv[b]) - glm::dvec2(uv[a]), d2 = glm::dvec2(uv[c]) - glm::dvec2(uv[a]);
  const double det = d1.x * d2.y - d2.x * d1.y;
  return det > 1e-20 ? 1 : det < -1e-20 ? -1 : 0;
}

// Per vertex: which UV orientations its triangles have (bit 0: +1, bit 1: -1; 0: none with UV area).
std::vector<uint8_t> orientationBits(const Primitive& p, const std::vector<glm::vec2>& uv) {
  std::vector<uint8_t> bits(p.positions.size(), 0);
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    const int s = uvOrientation(p, uv, t);
    if (s == 0) continue;
    for (int k = 0; k < 3; ++k)
      if (p.indices[t + k] < bits.size()) bits[p.indices[t + k]] |= s > 0 ? 1 : 2;
  }
  return bits;
}

}  // namespace

Primitive splitMirroredUvVertices(const Primitive& p, int uvSet) {
  const std::vector<glm::vec2>& uv = uvSet == 1 ? p.uv1 : p.uv0;
  Primitive out = p;
  const size_t n = p.positions.size();
  if (uv.size() != n) return out;
  const std::vector<uint8_t> seen = orientationBits(p, uv);
  // A vertex used by both orientations gets a copy (appended, every per-vertex array with it) that the
  // mirrored triangles use.
  std::vector<uint32_t> copyOf(n, UINT32_MAX);
  auto append = [&](auto& to, const auto& from, size_t i) {  // arrays that are per vertex in `p`
    if (from.size() == n) to.push_back(from[i]);
  };
  for (size_t i = 0; i < n; ++i) {
    if (seen[i] != 3) continue;
    copyOf[i] = static_cast<uint32_t>(out.positions.size());
    out.positions.push_back(p.positions[i]);
    append(out.normals, p.normals, i);
    append(out.uv0, p.uv0, i);
    append(out.uv1, p.uv1, i);
    append(out.tangents, p.tangents, i);
    append(out.sourceVertex, p.sourceVertex, i);
  }
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3)
    if (uvOrientation(p, uv, t) < 0)
      for (int k = 0; k < 3; ++k)
        if (p.indices[t + k] < n && copyOf[p.indices[t + k]] != UINT32_MAX)
          out.indices[t + k] = copyOf[p.indices[t + k]];
  return out;
}

std::vector<glm::vec4> generateTangents(const Primitive& p, const std::vector<glm::vec2>& uv) {
  const size_t n = p.positions.size();
  auto normalOf = [&](size_t i) { return i < p.normals.size() ? glm::dvec3(p.normals[i]) : glm::dvec3(0, 1, 0); };
  // MikkTSpace first welds vertices whose position, normal and UV are the same bits: an irbake export
  // splits vertices along light-map chart seams (TEXCOORD_1 differs there), which must not split the frame.
  // It keeps the two sides of a UV mirror apart: a vertex's orientation (the sign of its triangles' UV area)
  // is part of the key, so a mirrored half never cancels the other's dP/du.
  std::vector<int> orientation(n, 0);  // the one orientation of a vertex's triangles; 0: none or both
  if (uv.size() == n) {
    const std::vector<uint8_t> bits = orientationBits(p, uv);
    for (size_t i = 0; i < n; ++i) orientation[i] = bits[i] == 1 ? 1 : bits[i] == 2 ? -1 : 0;
  }
  std::vector<uint32_t> weld(n);
  {
    std::map<std::array<float, 9>, uint32_t> first;
    for (size_t i = 0; i < n; ++i) {
      const glm::vec3 q = p.positions[i], m = glm::vec3(normalOf(i));
      const glm::vec2 t = uv.size() == n ? uv[i] : glm::vec2(0.0f);
      weld[i] = first.emplace(std::array<float, 9>{q.x, q.y, q.z, m.x, m.y, m.z, t.x, t.y,
                                                   static_cast<float>(orientation[i])},
                              static_cast<uint32_t>(i))
                    .first->second;
    }
  }
  // Per corner: the triangle's dP/du and dP/dv projected on the vertex's tangent plane, normalised, weighted
  // by the corner's angle in that plane (MikkTSpace's weighting), summed on the welded vertex. A vertex
  // shared by both orientations (not split by splitMirroredUvVertices) sums only the triangles of the
  // orientation it was given (0: all of them).
  std::vector<glm::dvec3> dPdu(n, glm::dvec3(0.0)), dPdv(n, glm::dvec3(0.0));
  auto inPlane = [](const glm::dvec3& v, const glm::dvec3& nrm) {
    const glm::dvec3 w = v - nrm * glm::dot(nrm, v);
    const double len = glm::length(w);
    return len > 1e-20 ? w / len : glm::dvec3(0.0);
  };
  if (uv.size() == n) {
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const uint32_t idx[3] = {p.indices[t], p.indices[t + 1], p.indices[t + 2]};
      if (idx[0] >= n || idx[1] >= n || idx[2] >= n) continue;
      const glm::dvec3 e1 = glm::dvec3(p.positions[idx[1]]) - glm::dvec3(p.positions[idx[0]]);
      const glm::dvec3 e2 = glm::dvec3(p.positions[idx[2]]) - glm::dvec3(p.positions[idx[0]]);
      const glm::dvec2 d1 = glm::dvec2(uv[idx[1]]) - glm::dvec2(uv[idx[0]]), d2 = glm::dvec2(uv[idx[2]]) - glm::dvec2(uv[idx[0]]);
      const double det = d1.x * d2.y - d2.x * d1.y;  // e1 = dPdu d1.x + dPdv d1.y, e2 likewise: solve
      if (!(std::abs(det) > 1e-20)) continue;
      const int side = det > 0.0 ? 1 : -1;
      const glm::dvec3 su = (e1 * d2.y - e2 * d1.y) / det, sv = (e2 * d1.x - e1 * d2.x) / det;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = idx[k];
        if (orientation[v] != 0 && orientation[v] != side) continue;
        const glm::dvec3 nrm = normalOf(v), here(p.positions[v]);
        const glm::dvec3 a = inPlane(glm::dvec3(p.positions[idx[(k + 1) % 3]]) - here, nrm);
        const glm::dvec3 b = inPlane(glm::dvec3(p.positions[idx[(k + 2) % 3]]) - here, nrm);
        const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        dPdu[weld[v]] += angle * inPlane(su, nrm);
        dPdv[weld[v]] += angle * inPlane(sv, nrm);
      }
    }
  }
  std::vector<glm::vec4> out(n);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 nrm = normalOf(i);
    const glm::dvec3 du = dPdu[weld[i]], dv = dPdv[weld[i]];
    glm::dvec3 t = du - nrm * glm::dot(nrm, du);
    if (!(glm::length(t) > 1e-12)) {  // no UV gradient here: any unit vector orthogonal to the normal
      t = std::abs(nrm.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
      t -= nrm * glm::dot(nrm, t);
    }
    t = glm::normalize(t);
    // cross(n, t)·w must point where v decreases.
    const double w = glm::dot(glm::cross(nrm, t), dv) > 0.0 ? -1.0 : 1.0;
    out[i] = glm::vec4(glm::vec3(t), static_cast<float>(w));
  }
  return out;
}

std::vector<uint32_t> chartIds(const Primitive& p) {
  const size_t n = p.positions.size();
  std::vector<uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    uint32_t a = find(p.indices[t]);
    for (int k = 1; k < 3; ++k) {
      uint32_t b = find(p.indices[t + k]);
      if (a != b) parent[b] = a;
    }
  }
  // Dense ids in order of first appearance, so colours are stable between runs.
  std::vector<uint32_t> id(n, UINT32_MAX), out(n);
  uint32_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    uint32_t r = find(static_cast<uint32_t>(i));
    if (id[r] == UINT32_MAX) id[r] = next++;
    out[i] = id[r];
  }
  return out;
}

bool isClosedOutward(const Primitive& p) {
  if (p.indices.size() < 12 || p.indices.size() % 3 != 0) return false;  // a closed solid has ≥ 4 triangles
  // Weld by exact position.
  std::map<std::array<float, 3>, uint32_t> ids;
  std::vector<uint32_t> weld(p.positions.size());
  for (size_t i = 0; i < p.positions.size(); ++i) {
    const glm::vec3& q = p.positions[i];
    weld[i] = ids.emplace(std::array<float, 3>{q.x, q.y, q.z}, static_cast<uint32_t>(ids.size())).first->second;
  }
  std::unordered_map<uint64_t, int> directed;  // edge a→b (a << 32 | b) → uses
  double volume6 = 0.0;                                   // 6 × signed volume
  for (size_t t = 0; t < p.indices.size(); t += 3) {
    if (p.indices[t] >= weld.size() || p.indices[t + 1] >= weld.size() || p.indices[t + 2] >= weld.size())
      return false;
    const uint32_t v[3] = {weld[p.indices[t]], weld[p.indices[t + 1]], weld[p.indices[t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;  // degenerate (e.g. a sphere's pole): no edges
    for (int k = 0; k < 3; ++k)
      if (++directed[uint64_t{v[k]} << 32 | v[(k + 1) % 3]] > 1) return false;
    const glm::dvec3 a(p.positions[p.indices[t]]), b(p.positions[p.indices[t + 1]]);
    volume6 += glm::dot(a, glm::cross(b, glm::dvec3(p.positions[p.indices[t + 2]])));
  }
  for (const auto& [edge, uses] : directed)
    if (!directed.count((edge & 0xffffffffu) << 32 | edge >> 32)) return false;
  return !directed.empty() && volume6 > 0.0;
}

}  // namespace irbake::view
