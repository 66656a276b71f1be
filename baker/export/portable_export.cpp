// The portable bake (portable_export.h): page textures rasterised in atlas space, then a copy of the scene
// whose materials read them through TEXCOORD_0 goes through our glTF writer, and the materials become unlit.
#include "export/portable_export.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>

#include "common/error.h"
#include "common/file_paths.h"
#include "export/gltf_compact.h"
#include "post/post.h"

namespace irbake {

using json = nlohmann::json;

namespace {

float cross2(glm::vec2 a, glm::vec2 b) { return a.x * b.y - a.y * b.x; }


// The base-colour texture of a material when it has texels, else null.
const Texture* baseColorTextureOf(const Scene& scene, const Material& m) {
  if (m.baseColorTexture < 0 || m.baseColorTexture >= static_cast<int>(scene.textures.size())) return nullptr;
  const Texture& t = scene.textures[m.baseColorTexture];
  return t.texels.empty() ? nullptr : &t;
}

}  // namespace

int portableScale(const Scene& scene, int page, int pageWidth, int pageHeight, const PortableOptions& options) {
  double weighted = 0.0, weight = 0.0;
  for (const Primitive& p : scene.primitives) {
    if (p.lightmap.page != page || p.uv1.size() != p.positions.size()) continue;
    const Material& m = scene.materials.at(p.material);
    const Texture* albedo = baseColorTextureOf(scene, m);
    const std::vector<glm::vec2>& uv = m.baseColorTexCoord == 1 ? p.uv1 : p.uv0;
    if (!albedo || uv.size() != p.positions.size()) continue;
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const uint32_t a = p.indices[t], b = p.indices[t + 1], c = p.indices[t + 2];
      const double mapTexels = 0.5 * std::abs(cross2(p.uv1[b] - p.uv1[a], p.uv1[c] - p.uv1[a])) * pageWidth * pageHeight;
      const double albedoTexels = 0.5 * std::abs(cross2(uv[b] - uv[a], uv[c] - uv[a])) * m.baseColorUvTransform.areaScale() *
                                  albedo->width * albedo->height;
      if (!(mapTexels > 0.0) || !std::isfinite(albedoTexels)) continue;
      weighted += mapTexels * std::sqrt(albedoTexels / mapTexels);
      weight += mapTexels;
    }
  }
  // Rounded up, with a 5% allowance so a density of 1.02 (padding, rounding of the packer) stays at 1.
  int scale = weight > 0.0 ? static_cast<int>(std::ceil(weighted / weight - 0.05)) : 1;
  scale = std::clamp(scale, 1, std::max(1, options.maxScale));
  while (scale > 1 && (static_cast<long long>(pageWidth) * scale > options.maxSize ||
                       static_cast<long long>(pageHeight) * scale > options.maxSize))
    --scale;
  return scale;
}

Texture bakePortableTexture(const Scene& scene, const Lightmap& map, int scale, const PortableOptions& options,
                            PortablePage* stats) {
  const int w = map.width * scale, h = map.height * scale;
  const float exposure = static_cast<float>(options.exposure);
  // Colour and alpha as two pages, so the post module's dilation fills both from the same covered texels.
  Lightmap colour, alpha;
  for (Lightmap* l : {&colour, &alpha}) {
    l->page = map.page;
    l->width = w;
    l->height = h;
    l->texels.assign(static_cast<size_t>(w) * h, glm::vec3(0.0f));
    l->valid.assign(static_cast<size_t>(w) * h, 0);
  }
  size_t covered = 0, clipped = 0;
  const glm::vec2 size(static_cast<float>(w), static_cast<float>(h));
  for (const Primitive& p : scene.primitives) {
    if (p.lightmap.page != map.page || p.uv1.size() != p.positions.size()) continue;
    const Material& m = scene.materials.at(p.material);
    const bool opaque = m.alphaMode == AlphaMode::Opaque;
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const glm::vec2 a = p.uv1[p.indices[t]] * size, b = p.uv1[p.indices[t + 1]] * size, c = p.uv1[p.indices[t + 2]] * size;
      const float area = cross2(b - a, c - a);
      if (!(std::abs(area) > 1e-12f)) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
      const int x1 = std::min(w - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
      const int y1 = std::min(h - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t i = static_cast<size_t>(y) * w + x;
          if (colour.valid[i]) continue;  // charts never overlap: a texel on a shared edge is the first triangle's
          const glm::vec2 centre(x + 0.5f, y + 0.5f);
          // Barycentrics as Scene::baseColorAt takes them: (weight of corner 1, weight of corner 2).
          const glm::vec2 bary(cross2(centre - a, c - a) / area, cross2(b - a, centre - a) / area);
          constexpr float kEdge = -1e-5f;
          if (bary.x < kEdge || bary.y < kEdge || 1.0f - bary.x - bary.y < kEdge) continue;
          const uint32_t tri = static_cast<uint32_t>(t / 3);
          const glm::vec4 base = scene.baseColorAt(p, tri, bary);
          const glm::vec3 light = sampleLightmap(map, centre / size);
          glm::vec3 shown = exposure * (glm::vec3(base) * light + scene.emissionAt(p, tri, bary));
          for (int k = 0; k < 3; ++k)
            if (!std::isfinite(shown[k])) shown[k] = 0.0f;
          if (shown.x > 1.0f || shown.y > 1.0f || shown.z > 1.0f) ++clipped;
          colour.texels[i] = glm::clamp(shown, 0.0f, 1.0f);
          alpha.texels[i] = glm::vec3(opaque ? 1.0f : std::clamp(base.a, 0.0f, 1.0f));
          colour.valid[i] = alpha.valid[i] = 1;
          ++covered;
        }
    }
  }
  if (covered > 0) {
    dilate(colour);
    dilate(alpha);
  }
  Texture tex;
  tex.name = "portable_" + std::to_string(map.page);
  tex.width = w;
  tex.height = h;
  tex.wrapS = tex.wrapT = WrapMode::ClampToEdge;
  tex.texels.resize(static_cast<size_t>(w) * h);
  for (size_t i = 0; i < tex.texels.size(); ++i) tex.texels[i] = glm::vec4(colour.texels[i], covered > 0 ? alpha.texels[i].x : 1.0f);
  if (stats) {
    stats->page = map.page;
    stats->width = w;
    stats->height = h;
    stats->scale = scale;
    stats->clippedFraction = covered > 0 ? static_cast<double>(clipped) / covered : 0.0;
  }
  return tex;
}

PortableBake buildPortable(const Scene& scene, const std::vector<Lightmap>& maps, const PortableOptions& options) {
  if (!(options.exposure > 0.0) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::Usage, "", "the portable exposure must be a positive number");
  PortableBake out;
  Scene copy;
  copy.cameras = scene.cameras;
  std::map<int, const Lightmap*> mapOfPage;
  for (const Lightmap& m : maps) mapOfPage[m.page] = &m;
  std::map<int, int> textureOfPage;  // page → texture in copy
  for (const Lightmap& m : maps) {
    PortablePage stats;
    const int scale = portableScale(scene, m.page, m.width, m.height, options);
    textureOfPage[m.page] = static_cast<int>(copy.textures.size());
    copy.textures.push_back(bakePortableTexture(scene, m, scale, options, &stats));
    out.pages.push_back(stats);
  }
  // Source textures a primitive without a page still shows (its base colour), copied on first use.
  std::map<int, int> copiedTexture;
  auto copyTexture = [&](int index) {
    if (index < 0 || index >= static_cast<int>(scene.textures.size())) return -1;
    auto it = copiedTexture.find(index);
    if (it != copiedTexture.end()) return it->second;
    copy.textures.push_back(scene.textures[index]);
    return copiedTexture[index] = static_cast<int>(copy.textures.size()) - 1;
  };
  std::map<std::pair<int, int>, int> materialFor;  // (scene material, page or -1) → copy material
  std::vector<bool> baked;                         // copy material reads a page texture
  for (const Primitive& source : scene.primitives) {
    Primitive p;
    p.name = source.name;
    p.positions = source.positions;
    p.normals = source.normals;
    p.indices = source.indices;
    const bool onPage = mapOfPage.count(source.lightmap.page) && source.uv1.size() == source.positions.size();
    const Material& m = scene.materials.at(source.material);
    const int page = onPage ? source.lightmap.page : -1;
    auto key = std::make_pair(source.material, page);
    if (!materialFor.count(key)) {
      Material pm;
      pm.name = m.name;
      pm.alphaMode = m.alphaMode;
      pm.alphaCutoff = m.alphaCutoff;
      pm.doubleSided = m.doubleSided;
      if (onPage) {
        pm.baseColorTexture = textureOfPage.at(page);  // colour and alpha are in the texture
        if (std::count_if(materialFor.begin(), materialFor.end(), [&](const auto& e) { return e.first.first == source.material; }))
          pm.name += "_page" + std::to_string(page);
      } else {
        pm.baseColorFactor = m.baseColorFactor;
        pm.baseColorTexture = baseColorTextureOf(scene, m) ? copyTexture(m.baseColorTexture) : -1;
      }
      materialFor[key] = static_cast<int>(copy.materials.size());
      copy.materials.push_back(pm);
      baked.push_back(onPage);
    }
    p.material = materialFor[key];
    // The page texture reads the atlas UVs as set 0; a primitive without a page keeps its base colour's set.
    if (onPage) p.uv0 = source.uv1;
    else {
      // KHR_texture_transform is affine, so it goes into the vertex UVs exactly (the portable file has no extension).
      p.uv0 = m.baseColorTexCoord == 1 ? source.uv1 : source.uv0;
      for (glm::vec2& uv : p.uv0) uv = m.baseColorUvTransform.apply(uv);
    }
    copy.primitives.push_back(std::move(p));
  }
  out.document = gltfFromScene(copy);
  GltfDocument& doc = out.document;
  // Page textures: linear filtering without mip maps (mip levels would mix neighbouring charts), as the
  // light maps themselves.
  const int pageSampler = doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true);
  if (doc.root.contains("materials"))
    for (size_t i = 0; i < doc.root["materials"].size(); ++i) {
      json& mat = doc.root["materials"][i];
      mat["extensions"]["KHR_materials_unlit"] = json::object();
      if (baked[i] && mat["pbrMetallicRoughness"].contains("baseColorTexture"))
        doc.root["textures"][mat["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<int>()]["sampler"] = pageSampler;
    }
  if (!copy.materials.empty()) doc.useExtension("KHR_materials_unlit");
  doc.root["asset"]["extras"] = {{"irbakePortable", {{"exposure", options.exposure}}}};
  compactDocument(doc);
  return out;
}

PendingFile portableGlbFile(const Scene& scene, const std::vector<Lightmap>& maps, const std::filesystem::path& path,
                            const PortableOptions& options, json* summary) {
  if (!hasExtension(path, ".glb")) throw Error(ErrorCode::Usage, path.string(), "--portable writes one GLB: give a .glb file name");
  auto bake = std::make_shared<PortableBake>(buildPortable(scene, maps, options));
  if (summary) {
    *summary = {{"file", path.string()}, {"exposure", options.exposure}, {"pages", json::array()}};
    for (const PortablePage& p : bake->pages)
      (*summary)["pages"].push_back({{"page", p.page}, {"width", p.width}, {"height", p.height}, {"scale", p.scale},
                                     {"clippedFraction", p.clippedFraction}});
  }
  std::vector<PendingFile> files = bake->document.files(path);
  // A GLB is one file; its writer reads the document, which this file's writer keeps alive.
  PendingFile file = files.at(0);
  return {file.finalPath, [bake, writer = file.writer](const std::filesystem::path& temp) { writer(temp); }};
}

}  // namespace irbake
