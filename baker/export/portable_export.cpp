// The portable bake (portable_export.h): each page's texture planned as tiles, a copy of the scene split per
// tile whose materials read them through TEXCOORD_0 goes through our glTF writer and becomes unlit, then the
// tiles are rasterised in atlas space one at a time: once for the range, once into the PNGs.
#include "export/portable_export.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <tuple>

#include "common/error.h"
#include "common/file_paths.h"
#include "export/map_encoding.h"
#include "export/gltf_compact.h"
#include "post/post.h"
#include "scene/image_codec.h"

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

namespace {

// A triangle's box in the page texture's texels.
struct TexelBox {
  float x0, y0, x1, y1;
};

TexelBox boxOf(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  return {std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y})};
}

bool onPage(const Primitive& p, int page) { return p.lightmap.page == page && p.uv1.size() == p.positions.size(); }

// One grid of nx × ny cells over a w × h texture; false when a cell's tile is wider or higher than maxSize
// (wide / high say which).
bool tryGrid(const Scene& scene, int page, int w, int h, int nx, int ny, int maxSize, PortableTiling& out, bool& wide,
             bool& high) {
  constexpr int kMargin = 2;  // bilinear filtering and the dilation's first ring
  const glm::vec2 size(static_cast<float>(w), static_cast<float>(h));
  const float cw = static_cast<float>(w) / nx, ch = static_cast<float>(h) / ny;
  std::vector<TexelBox> cells(static_cast<size_t>(nx) * ny, TexelBox{1e30f, 1e30f, -1e30f, -1e30f});
  out.tileOfTriangle.assign(scene.primitives.size(), {});
  for (size_t pi = 0; pi < scene.primitives.size(); ++pi) {
    const Primitive& p = scene.primitives[pi];
    if (!onPage(p, page)) continue;
    std::vector<int>& tileOf = out.tileOfTriangle[pi];
    tileOf.assign(p.indices.size() / 3, 0);
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const TexelBox b = boxOf(p.uv1[p.indices[t]] * size, p.uv1[p.indices[t + 1]] * size, p.uv1[p.indices[t + 2]] * size);
      if (!std::isfinite(b.x0 + b.x1 + b.y0 + b.y1)) continue;
      const int cx = std::clamp(static_cast<int>(0.5f * (b.x0 + b.x1) / cw), 0, nx - 1);
      const int cy = std::clamp(static_cast<int>(0.5f * (b.y0 + b.y1) / ch), 0, ny - 1);
      const int cell = cy * nx + cx;
      TexelBox& c = cells[cell];
      c = {std::min(c.x0, b.x0), std::min(c.y0, b.y0), std::max(c.x1, b.x1), std::max(c.y1, b.y1)};
      tileOf[t / 3] = cell;
    }
  }
  // Cells become tiles (empty cells none); the triangles' cell numbers become tile numbers.
  std::vector<int> tileOfCell(cells.size(), -1);
  out.tiles.clear();
  wide = high = false;
  for (size_t i = 0; i < cells.size(); ++i) {
    const TexelBox& c = cells[i];
    if (c.x0 > c.x1) continue;
    PortableTile tile;
    tile.x = std::clamp(static_cast<int>(std::floor(c.x0)) - kMargin, 0, w - 1);
    tile.y = std::clamp(static_cast<int>(std::floor(c.y0)) - kMargin, 0, h - 1);
    tile.width = std::clamp(static_cast<int>(std::ceil(c.x1)) + kMargin, tile.x + 1, w) - tile.x;
    tile.height = std::clamp(static_cast<int>(std::ceil(c.y1)) + kMargin, tile.y + 1, h) - tile.y;
    wide = wide || tile.width > maxSize;
    high = high || tile.height > maxSize;
    tileOfCell[i] = static_cast<int>(out.tiles.size());
    out.tiles.push_back(tile);
  }
  for (std::vector<int>& tileOf : out.tileOfTriangle)
    for (int& t : tileOf) t = tileOfCell[t];
  return !wide && !high;
}

// What one tile's texels show, before the 8-bit encode: colour (and alpha where the page has a material that
// is not opaque), dilated.
struct TileTexels {
  Lightmap colour, alpha;  // alpha empty when every material on the page is opaque
};

// Calls visit(i, shown, alpha, emissive, primitive, triangle) for each texel of `tile` (i: its index in the
// tile) whose centre lies inside a triangle of the page, with the first such triangle (charts never overlap:
// a texel on a shared edge is the first triangle's, the same in every tile); shown = exposure × (base colour ×
// map + emission), finite.
template <typename Visit>
void forEachShownTexel(const Scene& scene, const Lightmap& map, int scale, const PortableTile& tile, float exposure,
                       Visit&& visit) {
  const int w = map.width * scale, h = map.height * scale;
  const glm::vec2 size(static_cast<float>(w), static_cast<float>(h));
  std::vector<bool> taken(static_cast<size_t>(tile.width) * tile.height, false);
  for (size_t pi = 0; pi < scene.primitives.size(); ++pi) {
    const Primitive& p = scene.primitives[pi];
    if (!onPage(p, map.page)) continue;
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const glm::vec2 a = p.uv1[p.indices[t]] * size, b = p.uv1[p.indices[t + 1]] * size, c = p.uv1[p.indices[t + 2]] * size;
      const float area = cross2(b - a, c - a);
      if (!(std::abs(area) > 1e-12f)) continue;
      const TexelBox box = boxOf(a, b, c);
      const int x0 = std::max(tile.x, static_cast<int>(std::floor(box.x0)));
      const int x1 = std::min(tile.x + tile.width - 1, static_cast<int>(std::ceil(box.x1)));
      const int y0 = std::max(tile.y, static_cast<int>(std::floor(box.y0)));
      const int y1 = std::min(tile.y + tile.height - 1, static_cast<int>(std::ceil(box.y1)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t i = static_cast<size_t>(y - tile.y) * tile.width + (x - tile.x);
          if (taken[i]) continue;
          const glm::vec2 centre(x + 0.5f, y + 0.5f);
          // Barycentrics as Scene::baseColorAt takes them: (weight of corner 1, weight of corner 2).
          const glm::vec2 bary(cross2(centre - a, c - a) / area, cross2(b - a, centre - a) / area);
          constexpr float kEdge = -1e-5f;
          if (bary.x < kEdge || bary.y < kEdge || 1.0f - bary.x - bary.y < kEdge) continue;
          const uint32_t tri = static_cast<uint32_t>(t / 3);
          const glm::vec4 base = scene.baseColorAt(p, tri, bary);
          const glm::vec3 light = sampleLightmap(map, centre / size);
          const glm::vec3 emission = scene.emissionAt(p, tri, bary);
          glm::vec3 shown = exposure * (glm::vec3(base) * light + emission);
          for (int k = 0; k < 3; ++k)
            if (!std::isfinite(shown[k])) shown[k] = 0.0f;
          taken[i] = true;
          visit(i, shown, base.a, emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f, pi, tri);
        }
    }
  }
}

float largest(glm::vec3 v) { return std::max(v.x, std::max(v.y, v.z)); }

bool pageHasAlpha(const Scene& scene, int page) {
  for (const Primitive& p : scene.primitives)
    if (onPage(p, page) && scene.materials.at(p.material).alphaMode != AlphaMode::Opaque) return true;
  return false;
}

// The tile's texels: exposure × shown / range, clipped to [0, 1], dilated; clipped and covered counted.
TileTexels bakeTile(const Scene& scene, const Lightmap& map, int scale, const PortableTile& tile,
                    const PortableOptions& options, double range, size_t& covered, size_t& clipped) {
  TileTexels out;
  const bool withAlpha = pageHasAlpha(scene, map.page);
  for (Lightmap* l : {&out.colour, &out.alpha}) {
    if (l == &out.alpha && !withAlpha) continue;
    l->page = map.page;
    l->width = tile.width;
    l->height = tile.height;
    l->texels.assign(l->size(), glm::vec3(0.0f));
    l->valid.assign(l->size(), 0);
  }
  const float toStored = static_cast<float>(1.0 / range);
  covered = clipped = 0;
  forEachShownTexel(scene, map, scale, tile, static_cast<float>(options.exposure),
                    [&](size_t i, glm::vec3 shown, float alpha, bool, size_t pi, uint32_t) {
                      const glm::vec3 stored = shown * toStored;
                      if (largest(stored) > 1.0f) ++clipped;
                      ++covered;
                      out.colour.texels[i] = glm::clamp(stored, 0.0f, 1.0f);
                      out.colour.valid[i] = 1;
                      if (withAlpha) {
                        const bool opaque = scene.materials.at(scene.primitives[pi].material).alphaMode == AlphaMode::Opaque;
                        out.alpha.texels[i] = glm::vec3(opaque ? 1.0f : std::clamp(alpha, 0.0f, 1.0f));
                        out.alpha.valid[i] = 1;
                      }
                    });
  if (covered > 0) {
    dilate(out.colour);
    if (withAlpha) dilate(out.alpha);
  }
  return out;
}

PortableTile wholeTexture(const Lightmap& map, int scale) { return {0, 0, map.width * scale, map.height * scale}; }

}  // namespace

PortableTiling portableTiles(const Scene& scene, int page, int width, int height, int maxSize) {
  PortableTiling out;
  maxSize = std::max(1, maxSize);
  if (width <= maxSize && height <= maxSize) {
    out.tiles.push_back({0, 0, width, height});
    out.tileOfTriangle.assign(scene.primitives.size(), {});
    for (size_t pi = 0; pi < scene.primitives.size(); ++pi)
      if (onPage(scene.primitives[pi], page)) out.tileOfTriangle[pi].assign(scene.primitives[pi].indices.size() / 3, 0);
    return out;
  }
  int nx = (width + maxSize - 1) / maxSize, ny = (height + maxSize - 1) / maxSize;
  constexpr int kMostCells = 64;  // per axis: beyond, a triangle is too large for maxSize
  while (nx <= kMostCells && ny <= kMostCells) {
    bool wide = false, high = false;
    if (tryGrid(scene, page, width, height, nx, ny, maxSize, out, wide, high)) return out;
    nx += wide ? 1 : 0;
    ny += high ? 1 : 0;
  }
  return {};
}

Texture bakePortableTexture(const Scene& scene, const Lightmap& map, int scale, const PortableOptions& options,
                            PortablePage* stats, double range, const PortableTile* tile) {
  const PortableTile area = tile ? *tile : wholeTexture(map, scale);
  size_t covered = 0, clipped = 0;
  const TileTexels texels = bakeTile(scene, map, scale, area, options, range, covered, clipped);
  Texture tex;
  tex.name = "portable_" + std::to_string(map.page);
  tex.width = area.width;
  tex.height = area.height;
  tex.wrapS = tex.wrapT = WrapMode::ClampToEdge;
  tex.texels.resize(texels.colour.size());
  for (size_t i = 0; i < tex.texels.size(); ++i)
    tex.texels[i] = glm::vec4(texels.colour.texels[i], texels.alpha.texels.empty() ? 1.0f : texels.alpha.texels[i].x);
  if (stats) {
    stats->page = map.page;
    stats->width = map.width * scale;
    stats->height = map.height * scale;
    stats->scale = scale;
    stats->clippedFraction = covered > 0 ? static_cast<double>(clipped) / covered : 0.0;
    stats->tiles = {area};
  }
  return tex;
}

namespace {

// A page's texture: its scale and tiles.
struct PagePlan {
  const Lightmap* map = nullptr;
  int scale = 1;
  PortableTiling tiling;
};

PagePlan planPage(const Scene& scene, const Lightmap& map, const PortableOptions& options) {
  PagePlan plan;
  plan.map = &map;
  // A coarser scale where no grid of tiles fits (a triangle wider than a texture at this scale).
  for (plan.scale = portableScale(scene, map.page, map.width, map.height, options); plan.scale >= 1; --plan.scale) {
    plan.tiling = portableTiles(scene, map.page, map.width * plan.scale, map.height * plan.scale, options.maxTextureSize);
    if (!plan.tiling.tiles.empty()) return plan;
  }
  throw Error(ErrorCode::Usage, "", "light-map page " + std::to_string(map.page) + " (" + std::to_string(map.width) +
                                        "x" + std::to_string(map.height) + ") has a triangle wider than --portable-max-size " +
                                        std::to_string(options.maxTextureSize) + " texels: give a larger size");
}

// The range: the percentile of the largest shown channel over every page's covered texels without emission
// (at least 1); each page's clipped fractions at that range.
double chooseRange(const Scene& scene, const std::vector<PagePlan>& plans, const PortableOptions& options,
                   std::vector<PortablePage>& pages) {
  std::vector<std::vector<float>> lit(plans.size()), emitting(plans.size());
  size_t litCount = 0;
  for (size_t k = 0; k < plans.size(); ++k) {
    const PagePlan& plan = plans[k];
    for (size_t t = 0; t < plan.tiling.tiles.size(); ++t)
      forEachShownTexel(scene, *plan.map, plan.scale, plan.tiling.tiles[t], static_cast<float>(options.exposure),
                        [&](size_t, glm::vec3 shown, float, bool emissive, size_t pi, uint32_t tri) {
                          if (plan.tiling.tileOfTriangle[pi][tri] != static_cast<int>(t)) return;  // another tile's
                          (emissive ? emitting[k] : lit[k]).push_back(largest(shown));
                        });
    litCount += lit[k].size();
  }
  std::vector<float> peaks;
  peaks.reserve(litCount);
  for (const std::vector<float>& l : lit)
    for (float v : l)
      if (v > 0.0f) peaks.push_back(v);
  const double range = std::max(1.0, static_cast<double>(rangeAtPercentile(peaks, options.percentile)));
  peaks = {};
  for (size_t k = 0; k < plans.size(); ++k) {
    auto above = [range](const std::vector<float>& v) {
      return static_cast<size_t>(std::count_if(v.begin(), v.end(), [range](float x) { return x > range; }));
    };
    const size_t litClipped = above(lit[k]), covered = lit[k].size() + emitting[k].size();
    pages[k].clippedFraction = covered ? static_cast<double>(litClipped + above(emitting[k])) / covered : 0.0;
    pages[k].litClippedFraction = lit[k].empty() ? 0.0 : static_cast<double>(litClipped) / lit[k].size();
  }
  return range;
}

// The tile as an sRGB 8-bit RGBA PNG.
std::vector<uint8_t> tilePng(const TileTexels& texels, const std::string& name) {
  const Lightmap& c = texels.colour;
  std::vector<uint8_t> px(c.size() * 4);
  auto quantise = [](float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  for (size_t i = 0; i < c.size(); ++i) {
    for (int k = 0; k < 3; ++k) px[i * 4 + k] = quantise(linearToSrgb(c.texels[i][k]));
    px[i * 4 + 3] = quantise(texels.alpha.texels.empty() ? 1.0f : texels.alpha.texels[i].x);
  }
  return encodePngRgba8(px, c.width, c.height, name);
}

// The copy's primitives for one source primitive on a page: one per tile it has triangles in, its vertices
// those its triangles use, TEXCOORD_0 the atlas UV in the tile's texture; materialOf(tile) is its material.
template <typename MaterialOf>
void splitByTile(const Primitive& source, const PagePlan& plan, size_t pi, MaterialOf&& materialOf,
                 std::vector<Primitive>& out) {
  const std::vector<int>& tileOf = plan.tiling.tileOfTriangle[pi];
  const glm::vec2 size(static_cast<float>(plan.map->width * plan.scale), static_cast<float>(plan.map->height * plan.scale));
  for (size_t t = 0; t < plan.tiling.tiles.size(); ++t) {
    const PortableTile& tile = plan.tiling.tiles[t];
    const bool whole = plan.tiling.tiles.size() == 1;  // the atlas UVs as they are
    Primitive p;
    p.name = source.name;
    std::vector<int> vertexOf(source.positions.size(), -1);
    for (size_t tri = 0; tri < tileOf.size(); ++tri) {
      if (tileOf[tri] != static_cast<int>(t)) continue;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = source.indices[tri * 3 + k];
        if (vertexOf[v] < 0) {
          vertexOf[v] = static_cast<int>(p.positions.size());
          p.positions.push_back(source.positions[v]);
          if (source.normals.size() == source.positions.size()) p.normals.push_back(source.normals[v]);
          const glm::vec2 uv = source.uv1[v];
          p.uv0.push_back(whole ? uv : (uv * size - glm::vec2(tile.x, tile.y)) / glm::vec2(tile.width, tile.height));
        }
        p.indices.push_back(static_cast<uint32_t>(vertexOf[v]));
      }
    }
    if (p.indices.empty()) continue;
    p.material = materialOf(static_cast<int>(t));
    out.push_back(std::move(p));
  }
}

}  // namespace

PortableBake buildPortable(const Scene& scene, const std::vector<Lightmap>& maps, const PortableOptions& options) {
  if (!(options.exposure > 0.0) || !std::isfinite(options.exposure))
    throw Error(ErrorCode::Usage, "", "the portable exposure must be a positive number");
  PortableBake out;
  std::vector<PagePlan> plans;
  std::map<int, size_t> planOfPage;
  for (const Lightmap& m : maps) {
    planOfPage[m.page] = plans.size();
    plans.push_back(planPage(scene, m, options));
    PortablePage stats;
    stats.page = m.page;
    stats.width = m.width * plans.back().scale;
    stats.height = m.height * plans.back().scale;
    stats.scale = plans.back().scale;
    stats.tiles = plans.back().tiling.tiles;
    out.pages.push_back(stats);
  }
  Scene copy;
  copy.cameras = scene.cameras;
  // Source textures a primitive without a page still shows (its base colour), copied on first use.
  std::map<int, int> copiedTexture;
  auto copyTexture = [&](int index) {
    if (index < 0 || index >= static_cast<int>(scene.textures.size())) return -1;
    auto it = copiedTexture.find(index);
    if (it != copiedTexture.end()) return it->second;
    copy.textures.push_back(scene.textures[index]);
    return copiedTexture[index] = static_cast<int>(copy.textures.size()) - 1;
  };
  std::map<std::tuple<int, int, int>, int> materialFor;  // (scene material, page or -1, tile) → copy material
  std::vector<std::pair<int, int>> tileOfMaterial;        // copy material → (plan, tile), (-1, -1) when unpaged
  auto materialOf = [&](int source, int page, int tile) {
    const auto key = std::make_tuple(source, page, tile);
    auto it = materialFor.find(key);
    if (it != materialFor.end()) return it->second;
    const Material& m = scene.materials.at(source);
    Material pm;
    pm.name = m.name;
    pm.alphaMode = m.alphaMode;
    pm.alphaCutoff = m.alphaCutoff;
    pm.doubleSided = m.doubleSided;
    if (page >= 0) {  // colour and alpha are in the page's texture, set below
      const bool named = std::any_of(materialFor.begin(), materialFor.end(),
                                     [&](const auto& e) { return std::get<0>(e.first) == source && std::get<1>(e.first) != page; });
      if (named) pm.name += "_page" + std::to_string(page);
      if (plans[planOfPage.at(page)].tiling.tiles.size() > 1) pm.name += "_tile" + std::to_string(tile);
      tileOfMaterial.push_back({static_cast<int>(planOfPage.at(page)), tile});
    } else {
      pm.baseColorFactor = m.baseColorFactor;
      pm.baseColorTexture = baseColorTextureOf(scene, m) ? copyTexture(m.baseColorTexture) : -1;
      tileOfMaterial.push_back({-1, -1});
    }
    copy.materials.push_back(pm);
    return materialFor[key] = static_cast<int>(copy.materials.size()) - 1;
  };
  for (size_t pi = 0; pi < scene.primitives.size(); ++pi) {
    const Primitive& source = scene.primitives[pi];
    const Material& m = scene.materials.at(source.material);
    if (onPage(source, source.lightmap.page) && planOfPage.count(source.lightmap.page)) {
      const PagePlan& plan = plans[planOfPage.at(source.lightmap.page)];
      splitByTile(source, plan, pi, [&](int tile) { return materialOf(source.material, source.lightmap.page, tile); },
                  copy.primitives);
      continue;
    }
    // Without a page: the base colour on its own UV set.
    Primitive p;
    p.name = source.name;
    p.positions = source.positions;
    p.normals = source.normals;
    p.indices = source.indices;
    // KHR_texture_transform is affine, so it goes into the vertex UVs exactly (the portable file has no extension).
    p.uv0 = m.baseColorTexCoord == 1 ? source.uv1 : source.uv0;
    for (glm::vec2& uv : p.uv0) uv = m.baseColorUvTransform.apply(uv);
    p.material = materialOf(source.material, -1, -1);
    copy.primitives.push_back(std::move(p));
  }
  out.document = gltfFromScene(copy);
  GltfDocument& doc = out.document;
  if (doc.root.contains("materials"))
    for (json& mat : doc.root["materials"]) mat["extensions"]["KHR_materials_unlit"] = json::object();
  if (!copy.materials.empty()) doc.useExtension("KHR_materials_unlit");

  // The textures, one tile at a time: the range over every page first, then each tile's PNG.
  out.range = chooseRange(scene, plans, options, out.pages);
  // Page textures: linear filtering without mip maps (mip levels would mix neighbouring charts), as the
  // light maps themselves.
  const int pageSampler = plans.empty() ? -1 : doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true);
  std::map<std::pair<int, int>, int> textureOfTile;
  for (size_t k = 0; k < plans.size(); ++k)
    for (size_t t = 0; t < plans[k].tiling.tiles.size(); ++t) {
      size_t covered = 0, clipped = 0;
      const TileTexels texels = bakeTile(scene, *plans[k].map, plans[k].scale, plans[k].tiling.tiles[t], options, out.range,
                                         covered, clipped);
      std::string name = "portable_" + std::to_string(plans[k].map->page);
      if (plans[k].tiling.tiles.size() > 1) name.append("_").append(std::to_string(t));  // append: GCC 12 warns falsely on "_" + string
      const int image = doc.addImage(tilePng(texels, name), name);
      textureOfTile[{static_cast<int>(k), static_cast<int>(t)}] = doc.addTexture(image, pageSampler);
    }
  for (size_t i = 0; i < tileOfMaterial.size(); ++i)
    if (tileOfMaterial[i].first >= 0)
      doc.root["materials"][i]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", textureOfTile.at(tileOfMaterial[i])}};
  doc.root["asset"]["extras"] = {{"irbakePortable", {{"exposure", options.exposure}, {"range", out.range}}}};
  compactDocument(doc);
  return out;
}

PendingFile portableGlbFile(const Scene& scene, const std::vector<Lightmap>& maps, const std::filesystem::path& path,
                            const PortableOptions& options, json* summary) {
  if (!hasExtension(path, ".glb")) throw Error(ErrorCode::Usage, path.string(), "--portable writes one GLB: give a .glb file name");
  auto bake = std::make_shared<PortableBake>(buildPortable(scene, maps, options));
  if (summary) {
    *summary = {{"file", path.string()}, {"exposure", options.exposure}, {"range", bake->range}, {"pages", json::array()}};
    for (const PortablePage& p : bake->pages) {
      json tiles = json::array();
      for (const PortableTile& t : p.tiles) tiles.push_back({{"x", t.x}, {"y", t.y}, {"width", t.width}, {"height", t.height}});
      (*summary)["pages"].push_back({{"page", p.page}, {"width", p.width}, {"height", p.height}, {"scale", p.scale},
                                     {"clippedFraction", p.clippedFraction}, {"litClippedFraction", p.litClippedFraction},
                                     {"tiles", tiles}});
    }
  }
  std::vector<PendingFile> files = bake->document.files(path);
  // A GLB is one file; its writer reads the document, which this file's writer keeps alive.
  PendingFile file = files.at(0);
  return {file.finalPath, [bake, writer = file.writer](const std::filesystem::path& temp) { writer(temp); }};
}

}  // namespace irbake
