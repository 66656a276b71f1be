// irview frame time on this machine's GL (llvmpipe in CI): one frame = clear + one textured draw per
// primitive into a 1280×720 RGBA8 framebuffer with the display shading (exposure + sRGB), then
// glFinish, as the window does before a swap (the shader encodes sRGB, as in the window). Scenes:
// the baked Cornell box (Embree backend) and a generated ~100k-triangle height field with a 1024²
// light-map page, untextured and with a 512² base colour texture repeated 8 × 8; the DamagedHelmet from
// ../shared/scenes (skipped when absent) baked with directional maps, shaded with them (SH, normal map) and
// with L0 only.
// Run: viewer_bench --benchmark_repetitions=9 --benchmark_report_aggregates_only=true (quote medians).
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>
#include <epoxy/gl.h>

#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "scene/light_additions.h"
#include "samples/sample_scenes.h"
#include "scene/gltf_loader.h"
#include "view_renderer.h"

using namespace irbake;
using namespace irbake::view;

namespace {

constexpr int kWidth = 1280, kHeight = 720;

// CPU seconds of the whole process (llvmpipe's rasteriser threads included): on a shared machine the
// wall time follows the load, the CPU time per frame much less so.
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

GlContext& context() {
  static GlContext gl;
  return gl;
}

// A square light-map page of smooth values 0.5 ± 0.4 (sin(fx·x) cos(fy·y)), every texel valid.
Lightmap smoothPage(int pageSize, float fx, float fy) {
  Lightmap page;
  page.width = page.height = pageSize;
  for (int y = 0; y < pageSize; ++y)
    for (int x = 0; x < pageSize; ++x) page.texels.emplace_back(0.5f + 0.4f * std::sin(fx * x) * std::cos(fy * y));
  page.valid.assign(page.size(), 1);
  return page;
}

// A textured brick-like 512² colour texture (tint × grain; mortar lines).
Texture brickTexture(glm::vec3 tint) {
  Texture t;
  t.width = t.height = 512;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const bool mortar = y % 32 < 2 || (x + (y / 32 % 2) * 32) % 64 < 2;
      const float grain = 0.85f + 0.15f * std::sin(0.37f * x + 0.11f * y) * std::cos(0.23f * y);
      t.texels.push_back(mortar ? glm::vec4(0.55f, 0.55f, 0.5f, 1.0f) : glm::vec4(tint * grain, 1.0f));
    }
  return t;
}

// A wavy n×n height field over 10 × 10 m: 2n² triangles, uv1 over one page with a smooth map;
// textured: a 512² base colour texture (a coloured brick-like pattern) repeated 8 × 8 over uv0.
ViewerScene heightField(int n, int pageSize, bool textured = false) {
  Scene s;
  s.materials.emplace_back();
  s.materials[0].baseColorFactor = glm::vec4(0.7f, 0.7f, 0.7f, 1.0f);
  Primitive p;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
      float x = 10 * u - 5, z = 10 * v - 5;
      p.positions.emplace_back(x, 0.3f * std::sin(3 * x) * std::cos(2 * z), z);
      p.normals.emplace_back(0, 1, 0);
      p.uv0.emplace_back(8 * u, 8 * v);
      p.uv1.emplace_back(u, v);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      p.indices.insert(p.indices.end(), {a, c, b, b, c, d});
    }
  p.lightmap = {0, pageSize, pageSize};
  s.primitives.push_back(std::move(p));
  if (textured) {
    s.textures.push_back(brickTexture({0.6f, 0.25f, 0.15f}));
    s.materials[0].baseColorFactor = glm::vec4(1.0f);
    s.materials[0].baseColorTexture = 0;
  }
  return makeViewerScene(std::move(s), {smoothPage(pageSize, 0.05f, 0.03f)});
}

// A furnished room, ~100k triangles in 67 primitives: a 6 × 3 × 5 m box (textured floor), 24 boxes
// (tables, cabinets; 12 triangles each) and 42 UV spheres (vases, lamps, cushions; 2,400 triangles
// each), four materials of which two textured. Each primitive owns a cell of one 2048² light-map page.
ViewerScene furnishedRoom() {
  Scene s;
  s.textures.push_back(brickTexture({0.55f, 0.35f, 0.2f}));   // wood-ish floor
  s.textures.push_back(brickTexture({0.25f, 0.3f, 0.55f}));   // fabric
  s.materials.resize(4);
  s.materials[0].baseColorFactor = glm::vec4(0.8f, 0.78f, 0.75f, 1.0f);  // plaster
  s.materials[1].baseColorTexture = 0;
  s.materials[2].baseColorTexture = 1;
  s.materials[3].baseColorFactor = glm::vec4(0.6f, 0.6f, 0.62f, 1.0f);   // metal
  const int pageSize = 2048, cells = 9;  // 9 × 9 cells of the page, one per primitive
  int nextCell = 0;
  auto finish = [&](Primitive& p, int material) {
    const int cell = nextCell++;
    const glm::vec2 origin(cell % cells, cell / cells);
    for (auto& uv : p.uv0) {
      const glm::vec2 local = glm::clamp(uv - glm::floor(uv * 0.999f), 0.0f, 1.0f);  // 0..1 in the cell
      p.uv1.push_back((origin + 0.05f + 0.9f * local) / float(cells));
    }
    p.material = material;
    p.lightmap = {0, pageSize, pageSize};
    s.primitives.push_back(std::move(p));
  };
  // Axis-aligned box from lo to hi, faces outward (inward: the room), uv0 = metres / 2 on each face.
  auto box = [&](glm::vec3 lo, glm::vec3 hi, bool inward, int material) {
    Primitive p;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        glm::vec3 n(0.0f);
        n[axis] = (side ? 1.0f : -1.0f) * (inward ? -1.0f : 1.0f);
        const uint32_t base = static_cast<uint32_t>(p.positions.size());
        for (int k = 0; k < 4; ++k) {
          glm::vec3 q;
          q[axis] = side ? hi[axis] : lo[axis];
          q[a] = (k == 1 || k == 2) ? hi[a] : lo[a];
          q[b] = (k >= 2) ? hi[b] : lo[b];
          p.positions.push_back(q);
          p.normals.push_back(n);
          p.uv0.emplace_back(q[a] / 2, q[b] / 2);
        }
        const glm::vec3 e1 = p.positions[base + 1] - p.positions[base];
        const glm::vec3 e2 = p.positions[base + 2] - p.positions[base];
        const bool flip = glm::dot(glm::cross(e1, e2), n) < 0;
        if (flip) p.indices.insert(p.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
        else p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      }
    finish(p, material);
  };
  auto sphere = [&](glm::vec3 c, float r, int material) {
    Primitive p;
    const int rings = 30, segments = 40;  // 2 · 30 · 40 = 2,400 triangles (with degenerate pole slivers)
    for (int i = 0; i <= rings; ++i)
      for (int j = 0; j <= segments; ++j) {
        const float th = 3.14159265f * i / rings, ph = 6.2831853f * j / segments;
        const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        p.positions.push_back(c + r * n);
        p.normals.push_back(n);
        p.uv0.emplace_back(float(j) / segments, float(i) / rings);
      }
    for (int i = 0; i < rings; ++i)
      for (int j = 0; j < segments; ++j) {
        const uint32_t a = i * (segments + 1) + j, b = a + 1, cc = a + segments + 1, d = cc + 1;
        p.indices.insert(p.indices.end(), {a, b, cc, b, d, cc});
      }
    finish(p, material);
  };
  box({0, -0.05f, 0}, {6, 3, 5}, true, 0);  // its floor just below the textured slab
  box({0, -0.01f, 0}, {6, 0.0f, 5}, false, 1);  // floor slab (its top face is the textured floor)
  for (int i = 0; i < 24; ++i) {
    const float x = 0.5f + (i % 6) * 0.9f, z = 0.6f + (i / 6) * 1.1f, h = 0.4f + 0.1f * (i % 5);
    box({x, 0, z}, {x + 0.5f, h, z + 0.4f}, false, i % 2 ? 3 : 2);
  }
  for (int i = 0; i < 42; ++i) {
    const float x = 0.4f + (i % 7) * 0.85f, z = 0.5f + (i / 7) * 0.75f, r = 0.12f + 0.04f * (i % 4);
    sphere({x, 0.9f + 0.5f * (i % 3), z}, r, i % 3 == 0 ? 2 : 3);
  }
  s.cameras.clear();
  return makeViewerScene(std::move(s), {smoothPage(pageSize, 0.01f, 0.013f)});
}

ViewerScene bakedCornell() {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.walk.paths = 1024;
  o.atlas.texelsPerUnit = 100.0f;  // 1 cm texels: a 56 × 56 texel wall
  BakeResult r = bake(samples::makeCornellBox(), o);
  return makeViewerScene(std::move(r.scene), std::move(r.maps));
}

// The shared DamagedHelmet (source folder's ../shared/scenes, found from the working directory upwards), baked
// as bench/directional_bench.sh does (Embree, the sun 0.3,−1,−0.4 at 3 W/m², --directional); null when absent.
const ViewerScene* bakedHelmet() {
  static std::unique_ptr<ViewerScene> v = []() -> std::unique_ptr<ViewerScene> {
    for (std::filesystem::path dir = std::filesystem::current_path(); !dir.empty(); dir = dir.parent_path()) {
      const std::filesystem::path gltf = dir / "shared/scenes/damaged_helmet/DamagedHelmet.gltf";
      if (std::filesystem::exists(gltf)) {
        LoadOptions load;
        load.shadingMaps = true;
        Scene s = loadScene(gltf, load);
        s.lights.push_back(directionalLight(glm::vec3(0.3f, -1.0f, -0.4f), 3.0f));
        BakeOptions o;
        o.backend = BackendKind::Embree;
        o.directional = true;
        BakeResult r = bake(std::move(s), o);
        return std::make_unique<ViewerScene>(makeViewerScene(std::move(r.scene), std::move(r.maps), std::move(r.directional)));
      }
      if (dir == dir.parent_path()) break;
    }
    return nullptr;
  }();
  return v.get();
}

void frameLoop(benchmark::State& state, const ViewerScene& v, const ViewCamera& cam, LightmapMode mode = LightmapMode::Sh) {
  context();
  ViewRenderer renderer(v);
  RenderTarget target(kWidth, kHeight, GL_RGBA8);
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
  DrawSettings settings;
  settings.encodeSrgb = true;
  settings.lightmapMode = mode;
  renderer.draw(cam, kWidth, kHeight, settings);  // warm-up: shader compile, texture residency
  glFinish();
  const double cpu0 = processCpuSeconds();
  for (auto _ : state) {
    renderer.draw(cam, kWidth, kHeight, settings);
    glFinish();
  }
  state.counters["cpu_ms_per_frame"] =
      benchmark::Counter(1000.0 * (processCpuSeconds() - cpu0), benchmark::Counter::kAvgIterations);
  state.counters["triangles"] = static_cast<double>(renderer.triangleCount());
  // Fragments that pass the depth test in one frame (visible pixels plus overdraw drawn front-most so far).
  GLuint query = 0;
  glGenQueries(1, &query);
  glBeginQuery(GL_SAMPLES_PASSED, query);
  renderer.draw(cam, kWidth, kHeight, settings);
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint samples = 0;
  glGetQueryObjectuiv(query, GL_QUERY_RESULT, &samples);
  glDeleteQueries(1, &query);
  state.counters["fragments"] = static_cast<double>(samples);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void BM_FrameCornellBox(benchmark::State& state) {
  static ViewerScene v = bakedCornell();
  frameLoop(state, v, fromGltfCamera(v.scene.cameras.at(0), v.scene.bounds()));
}

void BM_Frame100kTriangles(benchmark::State& state) {
  static ViewerScene v = heightField(224, 1024);  // 2·224² = 100,352 triangles
  frameLoop(state, v, lookAt({0, 4, 8}, {0, 0, 0}, 50.0f, v.scene.bounds()));
}

void BM_Frame100kTrianglesTextured(benchmark::State& state) {
  static ViewerScene v = heightField(224, 1024, true);
  frameLoop(state, v, lookAt({0, 4, 8}, {0, 0, 0}, 50.0f, v.scene.bounds()));
}

void BM_Frame100kFurnishedRoom(benchmark::State& state) {
  static ViewerScene v = furnishedRoom();  // 12 + 12 + 24·12 + 42·2,400 = 101,112 triangles
  frameLoop(state, v, lookAt({5.8f, 2.6f, 4.8f}, {1.5f, 0.4f, 0.8f}, 60.0f, v.scene.bounds()));
}

void helmetFrame(benchmark::State& state, LightmapMode mode) {
  const ViewerScene* v = bakedHelmet();
  if (!v) {
    state.SkipWithError("../shared/scenes/damaged_helmet absent");
    return;
  }
  frameLoop(state, *v, lookAt({0.9f, 0.35f, 2.6f}, {0, 0, 0}, 40.0f, v->scene.bounds()), mode);
}
void BM_FrameHelmetDirectionalSh(benchmark::State& state) { helmetFrame(state, LightmapMode::Sh); }
void BM_FrameHelmetDirectionalL0(benchmark::State& state) { helmetFrame(state, LightmapMode::L0); }

}  // namespace

BENCHMARK(BM_FrameCornellBox)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_Frame100kTriangles)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_Frame100kTrianglesTextured)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_Frame100kFurnishedRoom)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_FrameHelmetDirectionalSh)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_FrameHelmetDirectionalL0)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK_MAIN();
