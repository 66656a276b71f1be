// Speed against error: both VPL backends (GL on EGL, Embree) at N = 64 … 4096
// light paths on the same atlas, texel samples and VPL sets, scored against a converged reference
// bake (path tracer) of that atlas; time per stage. Plus the per-VPL cost of the GL backend's two
// stages (shadow cube, accumulation) on a synthetic ~100k-triangle scene and a 1M-texel page. Each backend
// runs as the bake's backend stage runs it (testing/backend_stage.h: the punctual lights, then the VPLs by class).
//
//   speed_error_bench scene GLTF [--add GLB:scale:x,y,z]... [--page 256] [--ns 64,256,1024,4096]
//                     [--spp 256] [--name NAME] [--csv OUT.csv] [--clamp-k 16] [--compensate]
//                     [--backends gl,embree] [--ref-cache FILE] [--interleave N|auto]
//   speed_error_bench scene --room DIV [--room-grids] ...   the generated furnished room (atlas, or grids)
//     --clamp-k: k of deriveClampBound (larger = tighter clamp); --compensate: add the clamp residual
//     (stages/compensation) after each backend, its time in compensation_s; --ref-cache: keep the
//     reference maps in FILE (raw floats) and reuse them when FILE matches the texel layout.
//   speed_error_bench stages [--tris-div 91] [--texels 1024] [--vpls 64] [--k 1,4,16,64]
//                     [--variants default] [--repeat 1] [--covered 1.0] [--csv OUT.csv]
//
// Rows are appended to the CSV (header written when the file is new). Times are wall-clock seconds
// on whatever machine runs it, plus process CPU seconds for the GL stages (load-independent).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "stages/compensation/clamp_compensation.h"
#include "evaluators/embree/embree_backend.h"
#include "stages/interleave/interleaved_sampling.h"
#include "transport/geometry_term.h"
#include "evaluators/gl/gl_backend.h"
#include "glcontext/gl_context.h"
#include "evaluators/reference/reference_integrator.h"
#include "common/error.h"
#include "common/progress.h"
#include "pipeline/diff.h"
#include "raytrace/ray_tracer.h"
#include "scene/gltf_loader.h"
#include "texels/texel_area.h"
#include "texels/texel_samples.h"
#include "vpl/vpl.h"
#include "testing/backend_stage.h"
#include "testing/scenes.h"

using namespace irbake;

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, sep);) out.push_back(item);
  return out;
}

std::ofstream openCsv(const std::string& path, const std::string& header) {
  const bool fresh = !std::filesystem::exists(path);
  std::ofstream f(path, std::ios::app);
  if (!f) throw Error(ErrorCode::Io, path, "cannot open CSV for appending");
  if (fresh) f << header << "\n";
  return f;
}

// Appends `extra` (a glTF/GLB, uniformly scaled then translated) to `scene`: materials and textures
// are re-indexed, positions moved (normals are unchanged by a uniform scale and a translation).
void addModel(Scene& scene, const std::string& spec) {
  const auto parts = split(spec, ':');
  if (parts.size() != 3) throw Error(ErrorCode::Usage, spec, "--add wants FILE:scale:x,y,z");
  Scene extra = loadScene(parts[0]);
  const float scale = std::stof(parts[1]);
  const auto t = split(parts[2], ',');
  if (t.size() != 3) throw Error(ErrorCode::Usage, spec, "--add offset wants x,y,z");
  const glm::vec3 offset(std::stof(t[0]), std::stof(t[1]), std::stof(t[2]));
  // Stand the model on y = offset.y: its lowest point goes there.
  const Bounds3 b = extra.bounds();
  const int materialBase = static_cast<int>(scene.materials.size());
  const int textureBase = static_cast<int>(scene.textures.size());
  for (Material m : extra.materials) {
    if (m.baseColorTexture >= 0) m.baseColorTexture += textureBase;
    if (m.emissiveTexture >= 0) m.emissiveTexture += textureBase;
    if (m.lightmapTexture >= 0) m.lightmapTexture = -1;
    scene.materials.push_back(m);
  }
  for (Texture& tex : extra.textures) scene.textures.push_back(std::move(tex));
  for (Primitive p : extra.primitives) {
    for (glm::vec3& v : p.positions) {
      v = (v - glm::vec3(0.5f * (b.min.x + b.max.x), b.min.y, 0.5f * (b.min.z + b.max.z))) * scale + offset;
    }
    p.material += materialBase;
    p.node = p.gltfMesh = p.gltfPrimitive = -1;
    p.uv1.clear();
    p.lightmap = {};
    scene.primitives.push_back(std::move(p));
  }
  for (const Light& l : extra.lights) scene.lights.push_back(l);
}

// A furnished room (≥ 50k triangles) built here: 4 × 3 × 4 m room of div×div-cell walls, a
// checker-textured floor, three boxes as furniture, an emissive ceiling panel and a point light. By
// default it goes through the atlas like any scene; --room-grids scores hand-made texel grids on the
// floor and the back wall instead (bench/results/speed_error_fixed_clamp_k16.csv).
Scene furnishedRoom(int div, std::vector<TexelSamples>& texels, int grid) {
  using namespace irbake::testing;
  Scene s;
  const int white = addMaterial(s, glm::vec3(0.75f));
  const int red = addMaterial(s, glm::vec3(0.7f, 0.15f, 0.1f));
  const int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(12.0f));
  Texture checker;
  checker.name = "checker";
  checker.width = checker.height = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float a = ((x / 8 + y / 8) % 2 == 0) ? 0.8f : 0.2f;
      checker.texels.push_back(glm::vec4(a, a, a, 1.0f));
    }
  s.textures.push_back(checker);
  const int floorMaterial = addMaterial(s, glm::vec3(1.0f));
  s.materials[floorMaterial].baseColorTexture = 0;
  const float X = 4, Y = 3, Z = 4;
  addQuad(s, floorMaterial, {-2, 0, 2}, {X, 0, 0}, {0, 0, -Z}, div);  // floor, normal +Y
  addQuad(s, white, {-2, Y, -2}, {X, 0, 0}, {0, 0, Z}, div);          // ceiling, normal −Y
  addQuad(s, white, {-2, 0, -2}, {X, 0, 0}, {0, Y, 0}, div);          // back wall z = −2, normal +Z
  addQuad(s, white, {-2, 0, 2}, {0, Y, 0}, {X, 0, 0}, div);           // front wall z = 2, normal −Z
  addQuad(s, red, {-2, 0, -2}, {0, Y, 0}, {0, 0, Z}, div);            // left wall x = −2, normal +X
  addQuad(s, white, {2, 0, -2}, {0, 0, Z}, {0, Y, 0}, div);           // right wall x = 2, normal −X
  const int boxDiv = std::max(1, div / 4);
  addBox(s, white, {-1.5f, 0, -1.5f}, {-0.5f, 0.8f, -0.9f}, false, boxDiv);  // sideboard
  addBox(s, red, {0.3f, 0, -0.3f}, {1.1f, 0.45f, 0.5f}, false, boxDiv);      // table
  addBox(s, white, {1.3f, 0, -1.8f}, {1.8f, 1.9f, -1.3f}, false, boxDiv);    // cupboard
  addQuad(s, lamp, {-0.4f, Y - 0.01f, -0.4f}, {0.8f, 0, 0}, {0, 0, 0.8f});   // ceiling panel, normal −Y
  s.lights.push_back(pointLight({-1.2f, 2.2f, 1.0f}, 3.0f));
  texels.push_back(gridSamples({-2, 0, 2}, {X, 0, 0}, {0, 0, -Z}, grid, grid));
  // Floor samples under the furniture are inside closed boxes: invalid, as the texel stage's leak
  // control would make them (a shadow map cannot tell the inside of a box from its surface).
  const glm::vec4 footprints[3] = {{-1.5f, -1.5f, -0.5f, -0.9f}, {0.3f, -0.3f, 1.1f, 0.5f}, {1.3f, -1.8f, 1.8f, -1.3f}};
  for (size_t i = 0; i < texels[0].layerSize(); ++i) {
    const glm::vec4 p = texels[0].positionWeight[i];
    for (const glm::vec4& f : footprints)
      if (p.x > f.x && p.x < f.z && p.z > f.y && p.z < f.w) texels[0].positionWeight[i].w = 0.0f, texels[0].valid[i] = 0;
  }
  texels.push_back(gridSamples({-2, 0, -2}, {X, 0, 0}, {0, Y, 0}, grid, grid * 3 / 4));
  texels[1].page = 1;
  return s;
}

// Reference cache: spp, page count, then per page width, height, valid[], value[], error[] (raw floats).
void writeReferenceCache(const std::string& path, int spp, const std::vector<Lightmap>& ref,
                         const std::vector<Lightmap>& err) {
  std::ofstream f(path, std::ios::binary);
  const int pages = static_cast<int>(ref.size());
  f.write(reinterpret_cast<const char*>(&spp), sizeof spp);
  f.write(reinterpret_cast<const char*>(&pages), sizeof pages);
  for (int p = 0; p < pages; ++p) {
    f.write(reinterpret_cast<const char*>(&ref[p].width), sizeof(int));
    f.write(reinterpret_cast<const char*>(&ref[p].height), sizeof(int));
    f.write(reinterpret_cast<const char*>(ref[p].valid.data()), ref[p].valid.size());
    f.write(reinterpret_cast<const char*>(ref[p].texels.data()), ref[p].texels.size() * sizeof(glm::vec3));
    f.write(reinterpret_cast<const char*>(err[p].texels.data()), err[p].texels.size() * sizeof(glm::vec3));
  }
}

bool readReferenceCache(const std::string& path, const std::vector<TexelSamples>& texels, int spp,
                        std::vector<Lightmap>& ref, std::vector<Lightmap>& err) {
  std::ifstream f(path, std::ios::binary);
  int fileSpp = 0, pages = 0;
  if (!f.read(reinterpret_cast<char*>(&fileSpp), sizeof fileSpp) || !f.read(reinterpret_cast<char*>(&pages), sizeof pages))
    return false;
  if (fileSpp != spp || pages != static_cast<int>(texels.size())) return false;
  ref.assign(pages, {});
  err.assign(pages, {});
  for (int p = 0; p < pages; ++p) {
    int w = 0, h = 0;
    f.read(reinterpret_cast<char*>(&w), sizeof w);
    f.read(reinterpret_cast<char*>(&h), sizeof h);
    if (w != texels[p].width || h != texels[p].height) return false;
    for (Lightmap* m : {&ref[p], &err[p]}) m->page = p, m->width = w, m->height = h;
    ref[p].valid.resize(static_cast<size_t>(w) * h);
    ref[p].texels.resize(ref[p].valid.size());
    err[p].texels.resize(ref[p].valid.size());
    f.read(reinterpret_cast<char*>(ref[p].valid.data()), ref[p].valid.size());
    f.read(reinterpret_cast<char*>(ref[p].texels.data()), ref[p].texels.size() * sizeof(glm::vec3));
    f.read(reinterpret_cast<char*>(err[p].texels.data()), err[p].texels.size() * sizeof(glm::vec3));
    err[p].valid = ref[p].valid;
  }
  return static_cast<bool>(f);
}

int sceneBench(const std::vector<std::string>& args) {
  std::string gltf, name, csv = "speed_error.csv";
  std::vector<std::string> adds;
  int page = 256, spp = 256;
  std::vector<int> ns{64, 256, 1024, 4096};
  int roomDiv = 0;  // > 0: the furnished room instead of a glTF
  bool roomGrids = false;  // the room scored on hand-made grids (floor, back wall) instead of its atlas
  double clampK = kClampVplsPerMean;
  bool compensate = false;
  std::vector<std::string> backends{"gl", "embree"};
  std::string refCache;
  std::optional<int> interleave = 1;  // unset: automatic (chooseInterleave)
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto next = [&] {
      if (i + 1 >= args.size()) throw Error(ErrorCode::Usage, "", a + " needs a value");
      return args[++i];
    };
    if (a == "--add") adds.push_back(next());
    else if (a == "--page") page = std::stoi(next());
    else if (a == "--spp") spp = std::stoi(next());
    else if (a == "--name") name = next();
    else if (a == "--room") roomDiv = std::stoi(next());
    else if (a == "--room-grids") roomGrids = true;
    else if (a == "--csv") csv = next();
    else if (a == "--clamp-k") clampK = std::stod(next());
    else if (a == "--compensate") compensate = true;
    else if (a == "--backends") backends = split(next(), ',');
    else if (a == "--ref-cache") refCache = next();
    else if (a == "--interleave") {
      const std::string v = next();
      interleave = v == "auto" ? std::nullopt : std::optional<int>(std::stoi(v));
    }
    else if (a == "--ns") {
      ns.clear();
      for (const auto& n : split(next(), ',')) ns.push_back(std::stoi(n));
    } else gltf = a;
  }
  if (gltf.empty() && roomDiv <= 0) throw Error(ErrorCode::Usage, "", "scene: no glTF given");
  if (name.empty()) name = roomDiv > 0 ? "furnished_room" : std::filesystem::path(gltf).stem().string();

  Stopwatch sw;
  std::vector<TexelSamples> gridTexels;
  Scene scene = roomDiv > 0 ? furnishedRoom(roomDiv, gridTexels, page) : loadScene(gltf);
  for (const auto& spec : adds) addModel(scene, spec);
  const double loadSeconds = sw.seconds();
  sw.reset();
  const bool grids = roomDiv > 0 && roomGrids;
  if (!grids) {
    AtlasOptions atlas;
    atlas.targetPageSize = page;
    atlas.maxPageSize = std::max(page, 1024);
    buildAtlas(scene, atlas);
  }
  const double atlasSeconds = sw.seconds();
  sw.reset();
  RayTracer rt(scene);
  const double bvhSeconds = sw.seconds();
  sw.reset();
  const std::vector<TexelSamples> texels = grids ? gridTexels : buildTexelSamples(scene, rt, {});
  const double texelSeconds = sw.seconds();
  size_t validTexels = 0;
  for (const auto& t : texels)
    for (uint8_t v : t.valid) validTexels += v;
  // Area weights from the atlas; the room's grids are uniform (equal weights).
  const auto areas = grids ? std::vector<std::vector<float>>{} : texelWorldAreas(scene);
  std::printf("%s: %zu triangles, %zu pages, %zu valid texels; load %.2f s, atlas %.2f s, bvh %.2f s, texels %.2f s\n",
              name.c_str(), scene.triangleCount(), texels.size(), validTexels, loadSeconds, atlasSeconds, bvhSeconds,
              texelSeconds);

  // The yardstick: the path tracer on the same texel samples.
  sw.reset();
  const VplSet none;
  std::vector<Lightmap> refError;
  BakeInputs refInputs{scene, rt, texels, none, {}, {}};
  ReferenceOptions ro;
  ro.spp = spp;
  if (const char* e = std::getenv("REF_DEPTH")) ro.maxDepth = std::atoi(e);  // diagnostics: truncated transport
  // --spp 0: timings only (no reference, error columns empty), for texel counts a reference cannot reach here.
  std::vector<Lightmap> reference;
  if (spp > 0 && !refCache.empty() && readReferenceCache(refCache, texels, spp, reference, refError)) {
    std::printf("reference read from %s\n", refCache.c_str());
  } else if (spp > 0) {
    reference = bakeReference(refInputs, ro, &refError);
    if (!refCache.empty()) writeReferenceCache(refCache, spp, reference, refError);
  }
  const double refSeconds = sw.seconds();
  // Relative standard error of the reference itself (RMS of per-texel SE over RMS of the map).
  double se2 = 0, v2 = 0;
  for (size_t p = 0; p < reference.size(); ++p)
    for (size_t i = 0; i < reference[p].size(); ++i)
      if (reference[p].valid[i])
        for (int c = 0; c < 3; ++c) se2 += refError[p].texels[i][c] * refError[p].texels[i][c],
                                    v2 += reference[p].texels[i][c] * reference[p].texels[i][c];
  const double refRelSe = std::sqrt(se2 / std::max(v2, 1e-300));
  std::printf("reference: %d spp in %.1f s, relative standard error %.3f%%\n", spp, refSeconds, 100 * refRelSe);

  std::ofstream out = openCsv(csv,
                              "scene,triangles,texels,backend,paths,vpls,relative_rmse,relative_rmse_corrected,relative_bias,walk_s,backend_s,"
                              "gl_vs_embree,gl_setup_s,gl_shadow_s,gl_accumulate_s,gl_shadow_cpu_s,gl_accumulate_cpu_s,"
                              "atlas_s,texels_s,reference_spp,reference_s,reference_rel_se,renderer,clamp_k,compensation_s,interleave,"
                              "gl_cube_face");
  for (int n : ns) {
    sw.reset();
    WalkOptions walk;
    walk.paths = n;
    if (const char* e = std::getenv("WALK_BOUNCES"); e && std::atoi(e) >= 0) walk.maxBounces = std::atoi(e);  // diagnostics
    walk.seed = std::getenv("WALK_SEED") ? static_cast<uint32_t>(std::atoi(std::getenv("WALK_SEED"))) : 1u;
    const VplSet vpls = generateVpls(scene, rt, walk);
    const double walkSeconds = sw.seconds();
    VplEvalOptions eval;
    eval.clampBound = deriveClampBound(scene, vpls, clampK);
    BakeInputs in{scene, rt, texels, vpls, eval, {}};
    const int classes = interleave ? *interleave : chooseInterleave(texels, eval.clampBound);
    std::vector<Lightmap> glMaps;  // kept to score GL against Embree on the same VPLs
    for (const std::string& backendName : backends) {
      const char* backend = backendName.c_str();
      GlBakeStats glStats;
      sw.reset();
      std::vector<Lightmap> maps;
      if (std::string(backend) == "gl") {
        GlContext context;  // one per bake, as the pipeline does (its programs are reused by every call)
        GlBackendOptions glOptions;
        glOptions.context = &context;
        glOptions.stats = &glStats;  // every call's figures added
        glOptions.stageTimings = !std::getenv("NO_STAGE_TIMINGS");  // diagnostics: glFinish between stages serialises llvmpipe
        if (const char* e = std::getenv("CUBE_FACE"); e && std::atoi(e) > 0) glOptions.cubeFaceSize = std::atoi(e);  // diagnostics
        if (const char* e = std::getenv("VPLS_PER_PASS")) glOptions.vplsPerPass = std::atoi(e);  // diagnostics
        if (const char* e = std::getenv("SHADOW_PCF")) glOptions.shadowPcf = std::atoi(e) != 0;  // diagnostics
        if (const char* e = std::getenv("SLOPE_BIAS")) glOptions.slopeBias = std::atof(e);  // diagnostics
        if (const char* e = std::getenv("NORMAL_OFFSET")) glOptions.normalOffset = std::atof(e);  // diagnostics
        const EmbreeEvaluator contacts;
        const GlEvaluator gl(glOptions, &contacts);
        maps = irbake::testing::bakeBackendStage(in, classes, gl);
      } else {
        maps = irbake::testing::bakeBackendStage(in, classes, EmbreeEvaluator());
      }
      double compensationSeconds = 0.0;
      if (compensate) {
        Stopwatch cw;
        ClampCompensationOptions compensationOptions;
        compensationOptions.seed = 1;
        if (const char* e = std::getenv("COMP_RAYS")) compensationOptions.rays = std::atoi(e);
        if (const char* e = std::getenv("COMP_REFINE")) compensationOptions.refineRays = std::atoi(e);
        if (const char* e = std::getenv("COMP_FILTER"); e && std::atoi(e) >= 0) compensationOptions.filterRadius = std::atoi(e);
        if (const char* e = std::getenv("COMP_FRACTION")) compensationOptions.refineFraction = std::atof(e);
        if (const char* e = std::getenv("COMP_SWEEPS")) compensationOptions.sweeps = std::atoi(e);
        if (const char* e = std::getenv("COMP_TOL")) compensationOptions.sweepTolerance = std::atof(e);
        ClampCompensationStats cst;
        ClampGather(in, compensationOptions).apply(maps, &cst);
        if (std::getenv("GL_VERBOSE") && glStats.facesRendered > 0)
          std::printf("  gl: %zu faces, %.0f triangles drawn per face (of %zu)\n", glStats.facesRendered,
                      double(glStats.trianglesDrawn) / glStats.facesRendered, scene.triangleCount());
        if (std::getenv("COMP_VERBOSE")) std::printf("  compensation: %d sweeps, %zu hits kept, added %.2f%%\n", cst.sweeps, cst.hitsKept, 100 * cst.addedFraction);
        compensationSeconds = cw.seconds();
      }
      const double backendSeconds = sw.seconds();
      double glVsEmbree = 0.0;
      if (std::string(backend) == "gl") glMaps = maps;
      else if (!glMaps.empty()) glVsEmbree = compareMaps(glMaps, maps, areas).relativeRmse;
      if (reference.empty()) {
        std::printf("  %-6s N=%5d (%6zu VPLs): backend %.2f s (shadow %.2f, accumulate %.2f), GL vs Embree %.4f\n", backend,
                    n, vpls.vpls.size(), backendSeconds, glStats.shadowSeconds, glStats.accumulateSeconds, glVsEmbree);
        std::fflush(stdout);
        out << name << "," << scene.triangleCount() << "," << validTexels << "," << backend << "," << n << ","
            << vpls.vpls.size() << ",,,," << walkSeconds << "," << backendSeconds << "," << glVsEmbree << ","
            << glStats.setupSeconds << "," << glStats.shadowSeconds << "," << glStats.accumulateSeconds << "," << glStats.shadowCpuSeconds
            << "," << glStats.accumulateCpuSeconds << "," << atlasSeconds << "," << texelSeconds << ",0,0,0,\"" << glStats.renderer
            << "\"," << clampK << "," << compensationSeconds << "," << classes << "," << glStats.cubeFaceSize << "\n";
        continue;
      }
      const MapDifference d = compareMaps(maps, reference, areas);
      if (std::getenv("DIAG_PRIM")) {  // diagnostics: squared error by primitive (first weighted sample's)
        struct Acc { double se = 0, diff = 0, ref = 0, w = 0; size_t n = 0; };
        std::map<uint32_t, Acc> acc;
        double total = 0;
        for (size_t p = 0; p < reference.size(); ++p)
          for (size_t i = 0; i < reference[p].size(); ++i) {
            if (!maps[p].valid[i] || !reference[p].valid[i]) continue;
            const double a = areas.empty() ? 1.0 : areas[p][i];
            const glm::vec3 e = maps[p].texels[i] - reference[p].texels[i], r = reference[p].texels[i];
            const glm::vec3 re = refError[p].texels[i];
            const uint32_t prim = i < texels[p].primitive.size() ? texels[p].primitive[i] : UINT32_MAX;
            Acc& q = acc[prim];
            const double se = a * (glm::dot(e, e) - glm::dot(re, re)) / 3.0;
            q.se += se; total += se;
            q.diff += a * (e.x + e.y + e.z) / 3.0;
            q.ref += a * (r.x + r.y + r.z) / 3.0;
            q.w += a; ++q.n;
          }
        std::vector<std::pair<double, uint32_t>> order;
        for (auto& [k, q] : acc) order.push_back({-q.se, k});
        std::sort(order.begin(), order.end());
        for (size_t j = 0; j < order.size() && j < 12; ++j) {
          const Acc& q = acc[order[j].second];
          std::printf("    prim %u (%s): %zu texels, area %.3f, share of corrected SE %.1f%%, bias %+.2f%%, mean ref %.4f\n",
                      order[j].second, order[j].second < scene.primitives.size() ? scene.primitives[order[j].second].name.c_str() : "?",
                      q.n, q.w, 100 * q.se / total, 100 * q.diff / std::max(q.ref, 1e-30), q.ref / std::max(q.w, 1e-30));
        }
      }
      // The reference's own noise adds its variance to the squared error: remove it (area-weighted
      // mean of SE², same weights as compareMaps) so the figure estimates the error against the truth.
      double wse = 0, w = 0, wref = 0;
      for (size_t p = 0; p < reference.size(); ++p)
        for (size_t i = 0; i < reference[p].size(); ++i) {
          if (!maps[p].valid[i] || !reference[p].valid[i]) continue;
          const double a = areas.empty() ? 1.0 : areas[p][i];
          if (!(a > 0)) continue;
          const glm::vec3 e = refError[p].texels[i], r = reference[p].texels[i];
          wse += a * glm::dot(e, e) / 3.0;
          wref += a * glm::dot(r, r) / 3.0;
          w += a;
        }
      const double rms = std::sqrt(wref / std::max(w, 1e-300));
      const double mse = d.rmse * d.rmse - wse / std::max(w, 1e-300);
      const double corrected = mse > 0 ? std::sqrt(mse) / rms : 0.0;
      if (glVsEmbree > 0) std::printf("  GL vs Embree on these VPLs: relative RMSE %.4f\n", glVsEmbree);
      std::printf("  %-6s N=%5d (%6zu VPLs): rel RMSE %.4f (noise-corrected %.4f), bias %+.4f, walk %.2f s, backend %.2f s (setup %.2f, shadow %.2f, accumulate %.2f, compensation %.2f; faces %d²)\n",
                  backend, n, vpls.vpls.size(), d.relativeRmse, corrected, d.relativeBias, walkSeconds, backendSeconds,
                  glStats.setupSeconds, glStats.shadowSeconds, glStats.accumulateSeconds, compensationSeconds, glStats.cubeFaceSize);
      std::fflush(stdout);
      out << name << "," << scene.triangleCount() << "," << validTexels << "," << backend << "," << n << ","
          << vpls.vpls.size() << "," << d.relativeRmse << "," << corrected << "," << d.relativeBias << "," << walkSeconds << ","
          << backendSeconds << "," << glVsEmbree << "," << glStats.setupSeconds << "," << glStats.shadowSeconds << "," << glStats.accumulateSeconds << ","
          << glStats.shadowCpuSeconds << "," << glStats.accumulateCpuSeconds << "," << atlasSeconds << "," << texelSeconds << ","
          << spp << "," << refSeconds << "," << refRelSe << ",\"" << glStats.renderer << "\"," << clampK << ","
          << compensationSeconds << "," << classes << "," << glStats.cubeFaceSize << "\n";
      out.flush();
    }
  }
  return 0;
}

// One-minute load average (other processes on the same cores inflate wall-clock times), or -1.
double loadAverage() {
  double load[1] = {-1.0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

// A closed room of `div`×`div`-cell walls (12 div² triangles) and one page of texels×texels samples on
// its floor; VPLs on the ceiling facing down: every VPL sees the whole floor.
int stagesBench(const std::vector<std::string>& args) {
  int div = 91, tex = 1024, nv = 64, repeat = 1;
  float coveredFraction = 1.0f;
  std::string csv = "gl_stages.csv";
  std::vector<int> ks{1, 4, 16, 64};
  std::vector<std::string> variants{"default"};
  for (size_t i = 1; i + 1 < args.size(); i += 2) {
    if (args[i] == "--tris-div") div = std::stoi(args[i + 1]);
    else if (args[i] == "--texels") tex = std::stoi(args[i + 1]);
    else if (args[i] == "--vpls") nv = std::stoi(args[i + 1]);
    else if (args[i] == "--repeat") repeat = std::stoi(args[i + 1]);
    else if (args[i] == "--covered") coveredFraction = std::stof(args[i + 1]);
    else if (args[i] == "--csv") csv = args[i + 1];
    else if (args[i] == "--k") {
      ks.clear();
      for (const auto& k : split(args[i + 1], ',')) ks.push_back(std::stoi(k));
    } else if (args[i] == "--variants") variants = split(args[i + 1], ',');
    else throw Error(ErrorCode::Usage, "", "unknown option " + args[i]);
  }
  Scene s;
  Material white;
  white.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials.push_back(white);
  const glm::vec3 lo(-1, -1, 0), hi(1, 1, 2);
  const glm::vec3 d = hi - lo, X(d.x, 0, 0), Y(0, d.y, 0), Z(0, 0, d.z);
  struct Face { glm::vec3 p0, e1, e2; };
  const Face faces[6] = {{lo, X, Y}, {lo + Z, Y, X}, {lo, Z, X}, {lo + Y, X, Z}, {lo, Y, Z}, {lo + X, Z, Y}};
  for (const Face& f : faces) {  // inward-facing walls
    Primitive p;
    const glm::vec3 n = glm::normalize(glm::cross(f.e1, f.e2));
    for (int j = 0; j <= div; ++j)
      for (int i = 0; i <= div; ++i) {
        p.positions.push_back(f.p0 + f.e1 * (float(i) / div) + f.e2 * (float(j) / div));
        p.normals.push_back(n);
      }
    for (int j = 0; j < div; ++j)
      for (int i = 0; i < div; ++i) {
        uint32_t a = j * (div + 1) + i, b = a + 1, c = a + div + 2, e = a + div + 1;
        p.indices.insert(p.indices.end(), {a, b, c, a, c, e});
      }
    s.primitives.push_back(std::move(p));
  }
  RayTracer rt(s);
  TexelSamples t;
  t.width = t.height = tex;
  for (int y = 0; y < tex; ++y)
    for (int x = 0; x < tex; ++x) {
      t.positionWeight.push_back(glm::vec4(-1 + 2 * (x + 0.5f) / tex, -1 + 2 * (y + 0.5f) / tex, 0, 1));
      t.normal.push_back(glm::vec4(0, 0, 1, 0));
    }
  t.primitive.assign(t.slotCount(), 0);
  t.triangle.assign(t.slotCount(), 0);
  // --covered f < 1: only a disc of that fraction of the page is valid (atlas pages are partly covered).
  t.covered.assign(t.layerSize(), 1);
  t.valid.assign(t.layerSize(), 1);
  if (coveredFraction < 1.0f) {
    const float r2 = coveredFraction * 4.0f / 3.14159265f;  // disc of that area in [-1,1]²
    for (size_t i = 0; i < t.layerSize(); ++i) {
      const glm::vec4 p = t.positionWeight[i];
      if (p.x * p.x + p.y * p.y > r2) t.valid[i] = t.covered[i] = 0, t.positionWeight[i].w = 0.0f;
    }
  }
  const std::vector<TexelSamples> pages{t};
  VplSet vs;
  for (int i = 0; i < nv; ++i) {
    Vpl v;
    v.position = glm::vec3(-0.9f + 1.8f * ((i * 37) % 101) / 101.0f, -0.9f + 1.8f * ((i * 53) % 97) / 97.0f, 1.999f);
    v.normal = {0, 0, -1};
    v.power = glm::vec3(0.01f);
    vs.vpls.push_back(v);
  }
  std::ofstream out = openCsv(csv, "triangles,texels,vpls,k,face,shadow_ms_per_vpl,accumulate_ms_per_vpl,"
                                   "shadow_cpu_ms_per_vpl,accumulate_cpu_ms_per_vpl,triangles_drawn_per_vpl,renderer,"
                                   "variant,valid_texels,load1");
  size_t validTexels = 0;
  for (uint8_t v : t.valid) validTexels += v;
  // Variants, for back-to-back A/B: default (the shipped options), fetch4 (PCF by 4 texelFetch and
  // compares in the shader), nomask (invalid texels shaded too), cluster128/cluster256 (culling clusters).
  for (int rep = 0; rep < repeat; ++rep)
    for (const std::string& variant : variants)
      for (int k : ks) {
        GlBakeStats glStats;
        GlBackendOptions o;
        o.stats = &glStats;
        o.stageTimings = true;
        o.vplsPerPass = k;
        o.cubeFaceSize = 256;  // the per-VPL targets are stated at 256² faces
        if (const char* e = std::getenv("CUBE_FACE"))  // diagnostics; 0: automatic
          o.cubeFaceSize = std::atoi(e) > 0 ? std::optional<int>(std::atoi(e)) : std::nullopt;
        if (variant == "fetch4") o.shadowCompare = false;
        else if (variant == "nomask") o.skipInvalidTexels = false;
        else if (variant == "cluster256") o.clusterTriangles = 256;
        else if (variant == "cluster128") o.clusterTriangles = 128;
        else if (variant != "default") throw Error(ErrorCode::Usage, "", "unknown variant " + variant);
        BakeInputs in{s, rt, pages, vs, {}, {}};
        const EmbreeEvaluator contacts;
        GlEvaluator(o, &contacts).evaluate(in);
        const double sv = 1e3 * glStats.shadowSeconds / nv, av = 1e3 * glStats.accumulateSeconds / nv;
        const double sc = 1e3 * glStats.shadowCpuSeconds / nv, ac = 1e3 * glStats.accumulateCpuSeconds / nv;
        std::printf("%-10s %zu triangles, %zu/%d texels, K=%d, %d² faces: shadow %.2f ms/VPL (CPU %.2f), accumulate "
                    "%.2f ms/VPL (CPU %.2f), %zu triangles drawn per VPL\n",
                    variant.c_str(), s.triangleCount(), validTexels, tex * tex, k, glStats.cubeFaceSize, sv, sc, av, ac,
                    glStats.trianglesDrawn / nv);
        std::fflush(stdout);
        out << s.triangleCount() << "," << tex * tex << "," << nv << "," << k << "," << glStats.cubeFaceSize << "," << sv
            << "," << av << "," << sc << "," << ac << "," << glStats.trianglesDrawn / nv << ",\"" << glStats.renderer << "\","
            << variant << "," << validTexels << "," << loadAverage() << "\n";
      }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (!args.empty() && args[0] == "scene") return sceneBench(args);
    if (!args.empty() && args[0] == "stages") return stagesBench(args);
    std::fprintf(stderr, "usage: speed_error_bench scene GLTF [...] | stages [...]\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "speed_error_bench: error: %s\n", e.what());
    return 1;
  }
}
