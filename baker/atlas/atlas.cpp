#include "atlas/atlas.h"
#include "atlas/atlas_estimate.h"
#include "atlas/atlas_from_bake.h"
#include "scene/triangle_area.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "atlas/atlas_mesh.h"
#include "atlas/atlas_stats.h"
#include "atlas/charts.h"
#include "atlas/pack.h"
#include "atlas/parameterize.h"
#include "common/error.h"
#include "common/log.h"

namespace irbake {
namespace {

using atlas::AtlasMesh;
using atlas::ChartUv;
using atlas::kNone;

struct PrimitiveCharts {
  AtlasMesh mesh;
  size_t firstChart = 0, chartCount = 0;  // range in the global chart list
};

// keepUv1: islands of the input TEXCOORD_1 (faces sharing a vertex index) keep their shape; they
// are only rescaled to the density and repacked.
std::vector<ChartUv> chartsFromUv1(const Primitive& prim, const AtlasMesh& mesh) {
  std::vector<uint32_t> parent(prim.positions.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (size_t t = 0; t < prim.triangleCount(); ++t)
    for (int k = 1; k < 3; ++k) parent[root(prim.indices[3 * t + k])] = root(prim.indices[3 * t]);
  std::unordered_map<uint32_t, size_t> chartOfRoot;
  std::vector<ChartUv> charts;
  std::vector<std::unordered_map<uint32_t, uint32_t>> localOf;
  for (uint32_t t = 0; t < prim.triangleCount(); ++t) {
    if (mesh.degenerate[t]) continue;
    auto [it, added] = chartOfRoot.try_emplace(root(prim.indices[3 * t]), charts.size());
    if (added) {
      charts.emplace_back();
      localOf.emplace_back();
    }
    ChartUv& c = charts[it->second];
    c.faces.push_back(t);
    c.area3d += mesh.faceArea[t];
    std::array<uint32_t, 3> corner{};
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = prim.indices[3 * t + k];
      auto [lit, ladded] = localOf[it->second].try_emplace(v, uint32_t(c.vertex.size()));
      if (ladded) {
        c.vertex.push_back(mesh.faceVertex[t][k]);
        c.uv.push_back(glm::dvec2(prim.uv1[v]));
      }
      corner[size_t(k)] = lit->second;
    }
    c.corner.push_back(corner);
  }
  for (ChartUv& c : charts) {
    double uvSum = 0.0;
    for (size_t i = 0; i < c.faces.size(); ++i) uvSum += atlas::uvArea(c, i);
    if (uvSum < 0.0) {  // islands authored mirrored keep their shape; flip them to the common winding
      for (glm::dvec2& uv : c.uv) uv.y = -uv.y;
      uvSum = -uvSum;
    }
    const double s = uvSum > 0.0 ? std::sqrt(c.area3d / uvSum) : 1.0;
    for (glm::dvec2& uv : c.uv) uv *= s;
  }
  return charts;
}

// The texel budget (options.maxTexels). Charts fill at least kWorstPageFill of the pages they are packed
// into (the density rule assumes the same figure), so N texels hold area × density² / kWorstPageFill.
constexpr double kTypicalFill = kWorstPageFill;

// A density a little under the one that fits, shown with 3 significant digits.
std::string densityThatFits(double density) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", density * 0.97);
  return text;
}

[[noreturn]] void overBudget(const Scene& scene, const AtlasOptions& options, double density, double texels,
                             double densityFits, const char* how) {
  char message[400];
  std::snprintf(message, sizeof(message),
                "at %.6g texels per unit the light-map atlas %s %.4g %stexels, over the budget of %.4g M "
                "(--max-texels %zu): use --texels-per-unit %s or less, or raise --max-texels",
                density, how, texels < 1e9 ? texels / 1e6 : texels, texels < 1e9 ? "M " : "", double(options.maxTexels) / 1e6,
                options.maxTexels,
                densityThatFits(densityFits).c_str());
  throw Error(ErrorCode::Usage, scene.sourcePath, message);
}

// Before any work: the surface area at the requested density.
void checkTexelEstimate(const Scene& scene, const AtlasOptions& options) {
  if (options.maxTexels == 0 || !(options.texelsPerUnit > 0.0f)) return;
  double area = 0.0;
  for (const Primitive& p : scene.primitives) {
    if (!p.getsLightmap()) continue;
    const double scale2 = double(p.lightmapScale) * p.lightmapScale;
    for (size_t t = 0; t < p.triangleCount(); ++t) area += triangleArea(p, t) * scale2;
  }
  const double density = options.texelsPerUnit;
  const double estimate = area * density * density / kTypicalFill;
  if (estimate > double(options.maxTexels))
    overBudget(scene, options, density, estimate, std::sqrt(double(options.maxTexels) * kTypicalFill / area),
               "would need about");
}

size_t pageTexels(const std::vector<AtlasPage>& pages) {
  size_t texels = 0;
  for (const AtlasPage& p : pages) texels += size_t(p.width) * p.height;
  return texels;
}

// After packing: the pages as they are. Padding does not shrink with the density, so the density
// named is one whose packing was tried and fits. `charts` are packed at `density` (in page texels), so a trial
// scales them by fits / density. Returns 0 within the budget; over it, the density rule's density gets the
// density that fits (buildAtlas packs again at it), and a given one is refused.
double fitTexelBudget(const Scene& scene, const AtlasOptions& options, const std::vector<ChartUv>& charts,
                      atlas::PackOptions packOptions, double density, const std::vector<AtlasPage>& pages) {
  const size_t texels = pageTexels(pages);
  if (options.maxTexels == 0 || texels <= options.maxTexels) return 0.0;
  double fits = density, used = double(texels);
  for (int attempt = 0; attempt < 12 && used > double(options.maxTexels); ++attempt) {
    fits *= std::sqrt(double(options.maxTexels) / used) * 0.97;
    packOptions.texelsPerUnit = fits / density;
    std::vector<ChartUv> trial = charts;  // packing places (and may scale) the charts it is given
    used = double(pageTexels(atlas::packCharts(trial, packOptions).pages));
  }
  if (!(options.texelsPerUnit > 0.0) && used <= double(options.maxTexels)) return fits;
  // overBudget names 0.97 × its argument: hand it the density that fitted, over 0.97.
  overBudget(scene, options, density, double(texels), fits / 0.97, "needs");
}

// Parameterises every chart of `work`; a chart that fails a check is bisected and both halves redone.
// Bounded: a chart bisected maxSplitDepth times and still failing falls back to one planar chart per face
// (a single triangle always projects validly). Appends to charts; returns the faces that fell back.
size_t parameterizeWithBisection(const AtlasMesh& mesh, std::vector<atlas::ChartFaces> work, const AtlasOptions& options,
                                 AtlasStats& stats, std::vector<ChartUv>& charts) {
  const atlas::ParamOptions paramOptions;
  std::vector<int> depth(work.size(), 0);
  size_t fallbackFaces = 0;
  while (!work.empty()) {
    std::vector<ChartUv> done(work.size());
    std::vector<atlas::ChartCheck> checks(work.size());
    tbb::parallel_for(size_t(0), work.size(), [&](size_t i) {
      if (work[i].faces.size() > 1 && !work[i].planarRegion &&
          atlas::absoluteCurvature(mesh, work[i].faces) > paramOptions.maxAbsCurvature) {
        checks[i] = atlas::ChartCheck::Stretched;  // hopeless: split without solving
        return;
      }
      checks[i] = atlas::parameterizeChart(mesh, work[i].faces, paramOptions, done[i]);
    });
    std::vector<atlas::ChartFaces> again;
    std::vector<int> againDepth;
    for (size_t i = 0; i < work.size(); ++i) {
      if (checks[i] == atlas::ChartCheck::Valid) {
        charts.push_back(std::move(done[i]));
        continue;
      }
      if (work[i].faces.size() > 1 && depth[i] >= std::max(0, options.maxSplitDepth)) {
        // Safe fallback: every face its own planar chart, solved right here (no further rounds).
        for (uint32_t f : work[i].faces) {
          ChartUv single;
          atlas::parameterizeChart(mesh, {f}, paramOptions, single);
          charts.push_back(std::move(single));
        }
        fallbackFaces += work[i].faces.size();
        continue;
      }
      auto halves = atlas::bisectChart(mesh, work[i]);
      if (halves.size() < 2) {  // a single face always projects validly; keep it whatever the check said
        charts.push_back(std::move(done[i]));
        continue;
      }
      ++stats.chartsSplit;
      for (auto& h : halves) {
        again.push_back(std::move(h));
        againDepth.push_back(depth[i] + 1);
      }
    }
    work = std::move(again);
    depth = std::move(againDepth);
  }
  return fallbackFaces;
}

// One primitive's share of the atlas: its half-edge mesh and charts, with the stats it adds. Primitives are
// unwrapped in parallel, each into its own slot, and joined in scene order so any thread count gives the same bytes.
struct PrimitiveWork {
  std::vector<ChartUv> charts;
  AtlasStats stats;  // the counts, seconds and warnings this primitive adds
};

// The charts of one primitive: its TEXCOORD_1 islands (keepUv1) or segmented and parameterised here.
void chartPrimitive(const Primitive& prim, const AtlasMesh& mesh, const AtlasOptions& options, PrimitiveWork& work) {
  AtlasStats& stats = work.stats;
  std::vector<ChartUv>& charts = work.charts;
  if (!prim.getsLightmap()) return;  // shadow-only, probe-lit or off: no charts, no texels
  Stopwatch clock;
  if (options.keepUv1 && prim.uv1.size() == prim.positions.size() && !prim.uv1.empty()) {
    charts = chartsFromUv1(prim, mesh);
    stats.secondsParam += clock.seconds();
    return;
  }
  std::vector<atlas::ChartFaces> faces = atlas::segmentCharts(mesh);
  stats.secondsCharts += clock.seconds();
  clock.reset();
  const size_t fallbackFaces = parameterizeWithBisection(mesh, std::move(faces), options, stats, charts);
  stats.secondsParam += clock.seconds();
  if (fallbackFaces)
    stats.warnings.push_back(std::to_string(fallbackFaces) + " faces of \"" + prim.name + "\" still failed the chart checks after " +
                             std::to_string(options.maxSplitDepth) + " bisections: mapped as one planar chart per face");
}

// Meshes and charts of every primitive (in parallel), joined in scene order into `charts`.
void chartAllPrimitives(const Scene& scene, const AtlasOptions& options, std::vector<PrimitiveCharts>& prims,
                        std::vector<ChartUv>& charts, AtlasStats& stats) {
  const size_t count = scene.primitives.size();
  std::vector<PrimitiveWork> work(count);
  std::mutex progressLock;
  size_t finished = 0;
  // Largest primitives first, so one big mesh does not start last and run alone.
  std::vector<size_t> order(count);
  for (size_t p = 0; p < count; ++p) order[p] = p;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return scene.primitives[a].triangleCount() > scene.primitives[b].triangleCount();
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const size_t p = order[i];
      Stopwatch clock;
      prims[p].mesh = atlas::buildAtlasMesh(scene.primitives[p]);
      work[p].stats.secondsMesh = clock.seconds();
      chartPrimitive(scene.primitives[p], prims[p].mesh, options, work[p]);
      if (options.progress) {
        std::lock_guard<std::mutex> lock(progressLock);
        options.progress("atlas", 0.6 * double(++finished) / double(count));
      }
    }
  }, tbb::simple_partitioner());
  for (size_t p = 0; p < count; ++p) {
    const AtlasMesh& mesh = prims[p].mesh;
    const AtlasStats& s = work[p].stats;
    stats.degenerateFaces += mesh.degenerateFaces;
    stats.nonManifoldFaces += mesh.nonManifoldFaces;
    stats.secondsMesh += s.secondsMesh;
    stats.secondsCharts += s.secondsCharts;
    stats.secondsParam += s.secondsParam;
    stats.chartsSplit += s.chartsSplit;
    for (const std::string& w : s.warnings) {
      log::warn("atlas: " + w);
      stats.warnings.push_back(w);
    }
    prims[p].firstChart = charts.size();
    prims[p].chartCount = work[p].charts.size();
    for (ChartUv& c : work[p].charts) charts.push_back(std::move(c));
  }
}

// Each primitive's charts weighed by its lightmapScale²: the area the density rule maps (m²).
double scaledChartArea(const Scene& scene, const std::vector<PrimitiveCharts>& prims, const std::vector<ChartUv>& charts) {
  double area = 0.0;
  for (size_t p = 0; p < prims.size(); ++p) {
    const double s = scene.primitives[p].lightmapScale;
    for (size_t c = prims[p].firstChart; c < prims[p].firstChart + prims[p].chartCount; ++c) area += charts[c].area3d * s * s;
  }
  return area;
}

// Charts of a primitive with a lightmapScale other than 1 grow by it (their uv are in metres until packing).
void applyLightmapScales(const Scene& scene, const std::vector<PrimitiveCharts>& prims, std::vector<ChartUv>& charts) {
  for (size_t p = 0; p < prims.size(); ++p) {
    const double s = scene.primitives[p].lightmapScale;
    if (s == 1.0) continue;
    for (size_t c = prims[p].firstChart; c < prims[p].firstChart + prims[p].chartCount; ++c)
      for (glm::dvec2& uv : charts[c].uv) uv *= s;
  }
}

// The objects (primitives of one node instance) with the fewest packed texels per square metre, fewest first.
std::vector<ObjectDensity> sparsestObjects(const Scene& scene, const std::vector<PrimitiveCharts>& prims,
                                           const std::vector<ChartUv>& charts, size_t count) {
  std::vector<ObjectDensity> objects;
  std::vector<double> area;
  std::unordered_map<uint64_t, size_t> objectOf;  // (node, instance) -> index in objects
  for (size_t p = 0; p < prims.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    if (!prim.getsLightmap()) continue;  // no map: no texels to count
    const uint64_t key = (uint64_t(uint32_t(prim.node)) << 32) | uint32_t(prim.instance);
    auto [it, added] = objectOf.try_emplace(key, objects.size());
    if (added) {
      objects.push_back({prim.name, prim.node, prim.instance, 0.0});
      area.push_back(0.0);
    }
    for (size_t c = prims[p].firstChart; c < prims[p].firstChart + prims[p].chartCount; ++c) {
      for (size_t f = 0; f < charts[c].faces.size(); ++f) objects[it->second].texelsPerSquareMetre += std::abs(atlas::uvArea(charts[c], f));
      area[it->second] += charts[c].area3d;
    }
  }
  std::vector<ObjectDensity> mapped;
  for (size_t i = 0; i < objects.size(); ++i)
    if (area[i] > 0.0) {
      objects[i].texelsPerSquareMetre /= area[i];
      mapped.push_back(objects[i]);
    }
  std::stable_sort(mapped.begin(), mapped.end(),
                   [](const ObjectDensity& a, const ObjectDensity& b) { return a.texelsPerSquareMetre < b.texelsPerSquareMetre; });
  if (mapped.size() > count) mapped.resize(count);
  return mapped;
}

// The density rule (atlas_estimate.h) on the charts' area: the density used, with its warning.
double chooseDensity(const Scene& scene, const std::vector<PrimitiveCharts>& prims, const std::vector<ChartUv>& charts,
                     const AtlasOptions& options, AtlasStats& stats) {
  const double area = scaledChartArea(scene, prims, charts);
  const DensityChoice choice = chooseTexelsPerUnit(area, scene.triangleCount(), options);
  const double density = choice.texelsPerUnit;
  if (!std::isfinite(density) || density <= 0.0) throw Error(ErrorCode::InvalidData, scene.sourcePath, "atlas: no surface area to unwrap");
  if (choice.lowered) {
    log::warn("atlas: " + choice.warning);
    stats.warnings.push_back(choice.warning);
  }
  stats.pageSize = choosePageSize(area, density, options);
  return density;
}

// Which chart holds each face of a primitive, and where faces no chart holds (degenerate ones) sit.
struct FaceCharts {
  std::vector<uint32_t> chartOfFace, localFace;  // kNone where no chart holds the face
  // A degenerate face sits on a point of a chart that holds one of its corners (zero UV area): (chart, local vertex).
  std::vector<std::pair<uint32_t, uint32_t>> degenerateAnchor;
  uint32_t chartOf(uint32_t t) const { return chartOfFace[t] != kNone ? chartOfFace[t] : degenerateAnchor[t].first; }
};

FaceCharts faceChartsOf(const Primitive& src, const PrimitiveCharts& range, const std::vector<ChartUv>& charts) {
  const AtlasMesh& mesh = range.mesh;
  const size_t first = range.firstChart, count = range.chartCount;
  FaceCharts fc;
  fc.chartOfFace.assign(src.triangleCount(), kNone);
  fc.localFace.assign(src.triangleCount(), kNone);
  std::unordered_map<uint32_t, std::pair<uint32_t, uint32_t>> anchorOfVertex;  // welded vertex -> (chart, local)
  for (size_t c = first; c < first + count; ++c)
    for (size_t i = 0; i < charts[c].faces.size(); ++i) {
      fc.chartOfFace[charts[c].faces[i]] = uint32_t(c);
      fc.localFace[charts[c].faces[i]] = uint32_t(i);
      for (int k = 0; k < 3; ++k) anchorOfVertex.try_emplace(mesh.faceVertex[charts[c].faces[i]][k], uint32_t(c), charts[c].corner[i][k]);
    }
  fc.degenerateAnchor.assign(src.triangleCount(), {kNone, kNone});
  for (uint32_t t = 0; t < src.triangleCount(); ++t) {
    if (fc.chartOfFace[t] != kNone) continue;
    for (int k = 0; k < 3 && fc.degenerateAnchor[t].first == kNone; ++k) {
      auto it = anchorOfVertex.find(mesh.faceVertex[t][k]);
      if (it != anchorOfVertex.end()) fc.degenerateAnchor[t] = it->second;
    }
    if (fc.degenerateAnchor[t].first == kNone && count > 0) fc.degenerateAnchor[t] = {uint32_t(first), 0};
  }
  return fc;
}

}  // namespace

Primitive primitivePart(const Primitive& src, LightmapRef lightmap, bool nameThePage) {
  Primitive dst;
  dst.name = nameThePage ? src.name + "#page" + std::to_string(lightmap.page) : src.name;
  dst.material = src.material;
  dst.node = src.node;
  dst.instance = src.instance;
  dst.instanceToNode = src.instanceToNode;
  dst.gltfMesh = src.gltfMesh;
  dst.gltfPrimitive = src.gltfPrimitive;
  dst.nodeToWorld = src.nodeToWorld;
  dst.normalsComputed = src.normalsComputed;
  dst.lightmap = lightmap;
  dst.lightmapScale = src.lightmapScale;
  dst.mode = src.mode;
  return dst;
}

namespace {

// The part of src whose charts landed on `page`: a vertex per (chart, input vertex), TEXCOORD_1 in [0, 1].
Primitive primitiveOnPage(const Primitive& src, const std::vector<ChartUv>& charts, const FaceCharts& fc,
                          const atlas::PackResult& packed, int page, const AtlasPage& pg, bool nameThePage) {
  Primitive dst = primitivePart(src, {page, pg.width, pg.height}, nameThePage);
  const glm::dvec2 toUnit(1.0 / pg.width, 1.0 / pg.height);
  std::unordered_map<uint64_t, uint32_t> vertexOf;
  auto emit = [&](uint32_t inputVertex, glm::dvec2 texelUv) {
    dst.positions.push_back(src.positions[inputVertex]);
    if (src.normals.size() == src.positions.size()) dst.normals.push_back(src.normals[inputVertex]);
    if (src.uv0.size() == src.positions.size()) dst.uv0.push_back(src.uv0[inputVertex]);
    if (src.tangents.size() == src.positions.size()) dst.tangents.push_back(src.tangents[inputVertex]);
    dst.uv1.push_back(glm::vec2(texelUv * toUnit));
    dst.sourceVertex.push_back(src.sourceVertex.empty() ? inputVertex : src.sourceVertex[inputVertex]);
    return uint32_t(dst.positions.size() - 1);
  };
  for (uint32_t t = 0; t < src.triangleCount(); ++t) {
    const bool mapped = fc.chartOfFace[t] != kNone;
    const uint32_t c = fc.chartOf(t);
    if (c == kNone || packed.chartPage[c] != page) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = src.indices[3 * t + k];
      if (!mapped) {
        dst.indices.push_back(emit(v, charts[c].uv[fc.degenerateAnchor[t].second]));
        continue;
      }
      const uint64_t key = (uint64_t(c) << 32) | v;
      auto [it, added] = vertexOf.try_emplace(key, 0u);
      if (added) it->second = emit(v, charts[c].uv[charts[c].corner[fc.localFace[t]][k]]);
      dst.indices.push_back(it->second);
    }
  }
  return dst;
}

// Output: a primitive per page its charts landed on (src itself when it has no faces to map).
void emitOnPages(const Primitive& src, const PrimitiveCharts& range, const std::vector<ChartUv>& charts,
                 const atlas::PackResult& packed, const std::vector<AtlasPage>& pages, std::vector<Primitive>& out) {
  const FaceCharts fc = faceChartsOf(src, range, charts);
  std::vector<int> pagesUsed;
  for (uint32_t t = 0; t < src.triangleCount(); ++t) {
    const uint32_t c = fc.chartOf(t);
    if (c != kNone) pagesUsed.push_back(packed.chartPage[c]);
  }
  std::sort(pagesUsed.begin(), pagesUsed.end());
  pagesUsed.erase(std::unique(pagesUsed.begin(), pagesUsed.end()), pagesUsed.end());
  if (pagesUsed.empty()) {  // nothing to map (no faces at all, or an object that gets no map)
    out.push_back(src);
    if (!src.getsLightmap()) {  // no map UVs, not even an input TEXCOORD_1's
      out.back().uv1.clear();
      out.back().lightmap = LightmapRef{};
    }
    return;
  }
  for (int page : pagesUsed)
    out.push_back(primitiveOnPage(src, charts, fc, packed, page, pages[size_t(page)], pagesUsed.size() > 1));
}

// The log's line: density, pages and the objects with the fewest texels per square metre.
std::string atlasSummary(const AtlasResult& result) {
  const AtlasStats& s = result.stats;
  char text[160];
  std::snprintf(text, sizeof(text), "%.4g texels per metre, %zu page%s (edge at most %d)", s.texelsPerUnit, result.pages.size(),
                result.pages.size() == 1 ? "" : "s", s.pageSize);
  std::string line = text;
  if (!s.sparsest.empty()) line += "; fewest texels per m²:";
  for (size_t i = 0; i < s.sparsest.size(); ++i) {
    std::snprintf(text, sizeof(text), "%s %s (node %d) %.4g", i ? "," : "", s.sparsest[i].name.c_str(), s.sparsest[i].node,
                  s.sparsest[i].texelsPerSquareMetre);
    line += text;
  }
  return line;
}

}  // namespace

AtlasResult buildAtlas(Scene& scene, const AtlasOptions& options) {
  if (options.padding < 0) throw Error(ErrorCode::Usage, "", "atlas padding must be ≥ 0");
  if (options.maxSplitDepth < 0) throw Error(ErrorCode::Usage, "", "atlas split depth must be ≥ 0");
  if (options.maxPageSize != 0 && options.maxPageSize < 16) throw Error(ErrorCode::Usage, "", "atlas page size must be ≥ 16");
  for (const Primitive& p : scene.primitives)
    if (!(p.lightmapScale > 0.0f) || !std::isfinite(p.lightmapScale))
      throw Error(ErrorCode::InvalidData, scene.sourcePath,
                  "primitive \"" + p.name + "\": lightmapScale " + std::to_string(p.lightmapScale) + " is not a positive number");
  checkTexelEstimate(scene, options);
  const Stopwatch total;
  AtlasResult result;
  result.padding = options.padding;
  result.sources = recordSourcePrimitives(scene);
  AtlasStats& stats = result.stats;
  auto progress = [&](double f) {
    if (options.progress) options.progress("atlas", f);
  };
  Stopwatch clock;
  std::vector<PrimitiveCharts> prims(scene.primitives.size());
  std::vector<ChartUv> charts;
  chartAllPrimitives(scene, options, prims, charts, stats);
  if (charts.empty() && !scene.primitives.empty() && !scene.primitives.front().getsLightmap() &&
      std::none_of(scene.primitives.begin(), scene.primitives.end(), [](const Primitive& p) { return p.getsLightmap(); }))
    throw Error(ErrorCode::EmptyScene, scene.sourcePath,
                "every object's extras.irbake.mode leaves it without a light map: nothing to bake");
  for (const ChartUv& c : charts) (c.planar ? stats.planarCharts : stats.lscmCharts) += 1;
  stats.texelsPerUnit = chooseDensity(scene, prims, charts, options, stats);
  applyLightmapScales(scene, prims, charts);

  clock.reset();
  atlas::PackOptions packOptions;
  packOptions.texelsPerUnit = stats.texelsPerUnit;
  packOptions.padding = options.padding;
  packOptions.maxPageSize = stats.pageSize;
  atlas::PackResult packed = atlas::packCharts(charts, packOptions);
  for (const std::string& w : packed.warnings) {
    log::warn("atlas: " + w);
    stats.warnings.push_back(w);
  }
  result.pages = packed.pages;
  if (const double fits = fitTexelBudget(scene, options, charts, packOptions, stats.texelsPerUnit, result.pages); fits > 0.0) {
    char text[200];
    std::snprintf(text, sizeof(text), "the packed atlas was over the budget of %.4g M texels (--max-texels): lowered from %.4g to %.4g "
                  "texels per metre for every object", double(options.maxTexels) / 1e6, stats.texelsPerUnit, fits);
    log::warn(std::string("atlas: ") + text);
    stats.warnings.push_back(text);
    packOptions.texelsPerUnit = fits / stats.texelsPerUnit;
    packed = atlas::packCharts(charts, packOptions);
    result.pages = packed.pages;
    stats.texelsPerUnit = fits;
  }
  stats.sparsest = sparsestObjects(scene, prims, charts, 5);
  stats.secondsPack = clock.seconds();
  progress(0.85);

  clock.reset();
  std::vector<std::vector<Primitive>> split(scene.primitives.size());
  tbb::parallel_for(size_t(0), scene.primitives.size(),
                    [&](size_t p) { emitOnPages(scene.primitives[p], prims[p], charts, packed, result.pages, split[p]); });
  std::vector<Primitive> out;
  out.reserve(scene.primitives.size());
  for (std::vector<Primitive>& pieces : split)
    for (Primitive& piece : pieces) out.push_back(std::move(piece));
  scene.primitives = std::move(out);
  stats.secondsOutput = clock.seconds();
  progress(0.95);

  clock.reset();
  const size_t chartsMade = charts.size();
  atlas::measureAtlas(scene, result.pages, stats);
  stats.charts = chartsMade;  // islands measured may differ only when a chart's faces touch by a vertex alone
  stats.secondsStats = clock.seconds();
  if (stats.degenerateFaces) stats.warnings.push_back(std::to_string(stats.degenerateFaces) + " degenerate faces mapped to a point");
  if (stats.nonManifoldFaces) stats.warnings.push_back(std::to_string(stats.nonManifoldFaces) + " non-manifold faces split off");
  stats.secondsTotal = total.seconds();
  log::info("atlas: " + atlasSummary(result));
  progress(1.0);
  return result;
}

}  // namespace irbake
