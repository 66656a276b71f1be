// GL backend against closed forms and CPU ray-traced visibility on hand-made scenes (small pages,
// small shadow maps: each test runs in well under a second on llvmpipe).
#include "evaluators/gl/gl_backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/gl/shadow_views.h"
#include "evaluators/embree/embree_backend.h"  // the contact evaluator the pipeline hands the GL one
#include "common/error.h"
#include "glcontext/gl_context.h"
#include "glcontext/gl_program.h"
#include "lights/light_kind.h"
#include "raytrace/ray_tracer.h"
#include "testing/ies_profiles.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using testing::addMaterial;
using testing::addQuad;
using testing::addBox;
using testing::gridSamples;

constexpr double kPi = 3.14159265358979323846;

// CPU value of one VPL at a sample: Φ cosθx cosθy / (π² r²) (clamped), visibility from Embree.
glm::dvec3 cpuVpl(const Vpl& v, glm::vec3 x, glm::vec3 n, float clampBound, const RayTracer* rt) {
  glm::dvec3 d = glm::dvec3(v.position) - glm::dvec3(x);
  double r2 = glm::dot(d, d);
  double cx = glm::dot(glm::dvec3(n), d), cy = -glm::dot(glm::dvec3(v.normal), d);
  if (cx <= 0 || cy <= 0) return glm::dvec3(0.0);
  double g = cx * cy / (r2 * r2);
  if (clampBound > 0) g = std::min(g, double(clampBound));
  if (rt && !rt->visible(x, n, v.position, v.normal)) return glm::dvec3(0.0);
  return glm::dvec3(v.power) * g / (kPi * kPi);
}

struct Fixture {
  Scene scene;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> pages;
  VplSet vpls;
  // The GL evaluator with the Embree evaluator for its contact texels, as the pipeline builds it.
  std::vector<Lightmap> bake(VplEvalOptions eval = {}, GlBackendOptions opt = {},
                             const EvaluationRequest& request = {}) {
    if (!rt) rt = std::make_unique<RayTracer>(scene);
    BakeInputs in{scene, *rt, pages, vpls, eval, {}};
    const EmbreeEvaluator contacts;
    return GlEvaluator(opt, &contacts).evaluate(in, request);
  }
};

// One downward VPL and one point light above the floor scene: a VPL pass and a direct pass.
void addVplAndPointLight(Fixture& f) {
  f.vpls.vpls.push_back(Vpl{{0.3f, 0.2f, 0.9f}, {0, 0, -1}, glm::vec3(1.0f), 0});
  f.scene.lights.push_back(testing::pointLight({-0.2f, 0.1f, 1.1f}, 2.0f));
}

// Floor z = 0 of 2×2 m, sampled 32×32; optional occluder square at height h.
Fixture floorScene(bool occluder) {
  Fixture f;
  int white = addMaterial(f.scene, glm::vec3(0.5f));
  addQuad(f.scene, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 4);
  if (occluder) addQuad(f.scene, white, {-0.3f, -0.3f, 0.5f}, {0.6f, 0, 0}, {0, 0.6f, 0});
  f.pages.push_back(gridSamples({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 32, 32));
  return f;
}

double relativeRmse(const std::vector<glm::dvec3>& ref, const Lightmap& m) {
  double num = 0, den = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      double e = double(m.texels[i][c]) - ref[i][c];
      num += e * e;
      den += ref[i][c] * ref[i][c];
    }
  }
  return std::sqrt(num / std::max(den, 1e-300));
}

std::vector<glm::dvec3> cpuReference(const Fixture& f, const TexelSamples& s, float clampBound, bool shadows) {
  std::vector<glm::dvec3> ref(s.layerSize(), glm::dvec3(0.0));
  const int L = s.supersample * s.supersample;
  for (int l = 0; l < L; ++l)
    for (size_t i = 0; i < s.layerSize(); ++i) {
      const glm::vec4 pw = s.positionWeight[l * s.layerSize() + i];
      if (pw.w <= 0) continue;
      const glm::vec3 n = glm::vec3(s.normal[l * s.layerSize() + i]);
      for (const Vpl& v : f.vpls.vpls)
        ref[i] += double(pw.w) * cpuVpl(v, glm::vec3(pw), n, clampBound, shadows ? f.rt.get() : nullptr);
    }
  return ref;
}

TEST(GlShadowViews, CubeFaceMatrixMatchesGlFaceSelection) {
  // A direction through each face's clip matrix lands on the (s, t) the GL spec's table gives.
  const VplFrame identity{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const glm::vec3 dirs[] = {{1, 0.2f, -0.3f}, {-1, 0.4f, 0.1f}, {0.3f, 1, -0.2f},
                            {-0.1f, -1, 0.6f}, {0.5f, -0.25f, 1}, {0.2f, 0.3f, -1}};
  for (const glm::vec3& d : dirs) {
    glm::vec2 st;
    const int face = cubeFaceOf(d, st);
    auto view = cubeFaceView(glm::vec3(0), identity, face, 64, 0.01f, false);
    ASSERT_TRUE(view);
    glm::vec4 c = view->clip * glm::vec4(d, 1.0f);
    EXPECT_NEAR(0.5f * (c.x / c.w + 1), st.x, 1e-6f);
    EXPECT_NEAR(0.5f * (c.y / c.w + 1), st.y, 1e-6f);
    // Reversed-Z: window depth = near / distance along the face axis.
    EXPECT_NEAR(c.z / c.w, 0.01f / std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}), 1e-6f);
  }
}

TEST(GlShadowViews, HemisphereSkipsBackFaceAndHalvesSides) {
  const VplFrame f = vplFrame(glm::normalize(glm::vec3(0.3f, -0.2f, 1.0f)));
  EXPECT_NEAR(glm::dot(f.tangent, f.normal), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(f.bitangent, f.normal), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(glm::cross(f.tangent, f.bitangent), f.normal), 1.0f, 1e-6f);
  int faces = 0, fullFaces = 0;
  for (int face = 0; face < 6; ++face) {
    auto v = cubeFaceView(glm::vec3(0), f, face, 256, 0.01f, true);
    if (!v) continue;
    ++faces;
    const int area = v->scissor.z * v->scissor.w;
    if (area == 256 * 256) ++fullFaces;
    else EXPECT_EQ(area, 129 * 256);
  }
  EXPECT_EQ(faces, 5);
  EXPECT_EQ(fullFaces, 1);
}

TEST(GlShadowViews, CullsClustersOutsideTheFace) {
  Scene s;
  int m = addMaterial(s, glm::vec3(0.5f));
  addQuad(s, m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 8);  // 128 triangles
  std::vector<glm::vec3> pos = s.primitives[0].positions;
  std::vector<uint32_t> idx = s.primitives[0].indices;
  std::vector<TriangleCluster> clusters;
  appendClusters(pos, idx, 0, 128, 16, clusters);  // 8 clusters, one row of cells each... (2 rows of 8 cells)
  ASSERT_EQ(clusters.size(), 8u);
  // Looking up (+Z) from below the plane sees it; the −Z face of a VPL above looking down too,
  // but the +Z face of a VPL above the plane sees nothing.
  const VplFrame id{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<int> counts;
  std::vector<const void*> offsets;
  size_t drawn = 0;
  cullClusters(*cubeFaceView({0, 0, 1}, id, 4, 64, 0.01f, false), clusters, counts, offsets, drawn);
  EXPECT_EQ(drawn, 0u);
  cullClusters(*cubeFaceView({0, 0, 1}, id, 5, 64, 0.01f, false), clusters, counts, offsets, drawn);
  EXPECT_EQ(drawn, 128u);
  EXPECT_EQ(counts.size(), 1u);  // neighbours merged into one draw range
  // Per-cell clusters; the +X face from (0.3, 0, 0.01) sees only cells reaching beyond x = 0.3:
  // the 5 columns of cells with x ≤ 0.25 (80 triangles) are culled, the last column is drawn.
  clusters.clear();
  appendClusters(pos, idx, 0, 128, 2, clusters);
  ASSERT_EQ(clusters.size(), 64u);
  drawn = 0;
  cullClusters(*cubeFaceView({0.3f, 0, 0.01f}, id, 0, 64, 0.001f, false), clusters, counts, offsets, drawn);
  EXPECT_LE(drawn, 48u);
  EXPECT_GE(drawn, 2u * 4u);
}

// One VPL over an open floor: exactly the closed form Φ cosθx cosθy / (π² r²) per texel.
// The automatic face size holds a face texel's footprint at the contribution-weighted median VPL → texel
// distance r to k texel spacings: F = 2r/(k·h) rounded up to a multiple of 32, within [min, max].
TEST(GlShadowViews, CubeFaceSizeHoldsTheFootprintToTheTexelSpacing) {
  const float h = 0.002f;  // 8 × 8 texels over 16 mm
  const std::vector<TexelSamples> pages{gridSamples({-0.008f, -0.008f, 0}, {0.016f, 0, 0}, {0, 0.016f, 0}, 8, 8)};
  auto choose = [&](std::vector<Vpl> vpls, float k = 1.0f) { return chooseCubeFaceSize(vpls, pages, 0.0f, k, 32, 256); };
  auto above = [](float r) { return Vpl{{0.0f, 0.0f, r}, {0, 0, -1}, glm::vec3(1.0f), 1}; };

  const CubeFaceChoice c = choose({above(0.05f)});
  EXPECT_NEAR(c.texelSpacing, h, 1e-6f);
  EXPECT_GE(c.medianDistance, 0.05f);
  EXPECT_LE(c.medianDistance, std::sqrt(0.05f * 0.05f + 2 * 0.007f * 0.007f));  // farthest texel centre
  EXPECT_EQ(c.size, 32 * static_cast<int>(std::ceil(2.0f * c.medianDistance / c.texelSpacing / 32.0f)));
  EXPECT_EQ(c.size, 64);                                 // 2 · 0.05 / 0.002 = 50 (+ the patch's extent) → 64
  EXPECT_EQ(choose({above(0.05f)}, 0.5f).size, 128);     // Nyquist: 100 → 128
  EXPECT_EQ(choose({above(0.5f)}).size, 256);            // 500: the upper bound
  EXPECT_EQ(choose({above(0.01f)}).size, 32);            // 10: the lower bound
  // Weighted by contribution (∝ 1/r²): a VPL 10× farther away moves the median hardly at all.
  EXPECT_LT(choose({above(0.05f), above(0.5f)}).medianDistance, 0.06f);
  // Nothing faces the texels: the upper bound, no distance.
  const CubeFaceChoice none = choose({Vpl{{0, 0, 0.05f}, {0, 0, 1}, glm::vec3(1.0f), 1}});
  EXPECT_EQ(none.size, 256);
  EXPECT_EQ(none.medianDistance, 0.0f);
}

TEST(GlBackend, SingleVplMatchesClosedForm) {
  Fixture f = floorScene(false);
  Vpl v;
  v.position = {0.2f, -0.1f, 0.8f};
  v.normal = glm::normalize(glm::vec3(0.3f, 0.1f, -1.0f));
  v.power = {2.0f, 1.0f, 0.5f};
  f.vpls.vpls.push_back(v);
  auto maps = f.bake();
  ASSERT_EQ(maps.size(), 1u);
  const auto ref = cpuReference(f, f.pages[0], 0.0f, false);
  double maxRel = 0;
  for (size_t i = 0; i < ref.size(); ++i)
    for (int c = 0; c < 3; ++c)
      maxRel = std::max(maxRel, std::abs(maps[0].texels[i][c] - ref[i][c]) / std::max(ref[i][c], 1e-6));
  EXPECT_LT(maxRel, 1e-4);
  EXPECT_EQ(maps[0].valid[0], 1);
  // Spot value: texel (16,16) centre (1/32, 1/32, 0).
  EXPECT_GT(maps[0].texels[16 * 32 + 16].r, 0.1f);
}

// n unit-power VPLs in a row above the floor (VPL i at first + i·step), each tilted by its y so the
// shadow cubes see the occluder from several directions.
void addVplRow(Fixture& f, int n, glm::vec3 first, glm::vec3 step) {
  for (int i = 0; i < n; ++i) {
    Vpl v;
    v.position = first + step * static_cast<float>(i);
    v.normal = glm::normalize(glm::vec3(v.position.y, 0.05f, -1.0f));
    v.power = glm::vec3(1.0f);
    f.vpls.vpls.push_back(v);
  }
}

// VPLs above an occluder: the shadow cubes agree with Embree visibility (texels on the penumbra
// boundary can differ by a shadow texel; the relative RMSE is what must be small).
TEST(GlBackend, VplShadowsMatchRayTracedVisibility) {
  Fixture f = floorScene(true);
  f.rt = std::make_unique<RayTracer>(f.scene);
  addVplRow(f, 5, {-0.4f, -0.2f, 0.9f}, {0.2f, 0.1f, 0.05f});
  GlBackendOptions opt;
  opt.vplsPerPass = 2;  // several passes and folds
  opt.foldEveryPasses = 1;
  opt.cubeFaceSize = 1024;  // shadow edges within a millimetre on this 6 cm texel grid
  auto maps = f.bake({}, opt);
  const auto ref = cpuReference(f, f.pages[0], 0.0f, true);
  const auto open = cpuReference(f, f.pages[0], 0.0f, false);
  double shadowed = 0, total = 0;
  for (size_t i = 0; i < ref.size(); ++i) shadowed += open[i].x - ref[i].x, total += open[i].x;
  EXPECT_GT(shadowed / total, 0.1);  // the occluder matters
  EXPECT_LT(relativeRmse(ref, maps[0]), 0.03);
  size_t off = 0;
  for (size_t i = 0; i < ref.size(); ++i) off += std::abs(maps[0].texels[i].x - ref[i].x) > 0.02 * ref[i].x + 1e-6;
  EXPECT_LT(off, ref.size() / 50);  // only texels on a shadow edge may differ
}

// A wall standing on the floor, VPLs on one side: the floor behind the wall's foot is in shadow. The
// slope-scaled bias lets a lookup pass occluders closer than slopeBias · footprint · (tanθ + 1.5) to the
// receiver, so a lit band runs along the foot. With 128² faces (a 1.1 cm footprint here, 3.1 cm texels)
// the old bias of 3 footprints lit a band 2–3 texels wide; 1 footprint (what the 2×2 filter needs: it
// reads one texel around the lookup) leaves at most the first texel, and resolving the contact texels
// with rays (GlBackendOptions::resolveContacts, the default, with the Embree evaluator) leaves none.
// A wall x = 0, 30 cm high, standing on a floor; four VPLs on its far side light the 32×32 floor page behind it.
Fixture wallOnFloor() {
  Fixture f;
  const int white = addMaterial(f.scene, glm::vec3(0.5f));
  addQuad(f.scene, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 4);
  addQuad(f.scene, white, {0, -1, 0}, {0, 2, 0}, {0, 0, 0.3f});
  f.pages.push_back(gridSamples({0, -1, 0}, {1, 0, 0}, {0, 2, 0}, 32, 32));
  f.rt = std::make_unique<RayTracer>(f.scene);
  for (int i = 0; i < 4; ++i)
    f.vpls.vpls.push_back(Vpl{{-0.5f, -0.3f + 0.2f * i, 0.5f}, glm::normalize(glm::vec3(1, 0, -1)), glm::vec3(1.0f), 1});
  return f;
}

TEST(GlBackend, CoarseCubesLeakAtMostOneTexelAlongAContact) {
  Fixture f = wallOnFloor();
  const auto ref = cpuReference(f, f.pages[0], 0.0f, true);
  const auto open = cpuReference(f, f.pages[0], 0.0f, false);
  // Widest lit band (texels from the foot) over the rows, where Embree sees the floor fully shadowed.
  auto band = [&](float slopeBias, bool resolveContacts) {
    GlBackendOptions opt;
    opt.cubeFaceSize = 128;
    opt.slopeBias = slopeBias;
    opt.resolveContacts = resolveContacts;
    const auto maps = f.bake({}, opt);
    int widest = 0;
    for (int y = 0; y < 32; ++y) {
      int x = 0;
      while (x < 32 && ref[32 * y + x].x == 0.0 && maps[0].texels[32 * y + x].x > 0.05 * open[32 * y + x].x) ++x;
      widest = std::max(widest, x);
    }
    return widest;
  };
  for (int y = 0; y < 32; ++y) ASSERT_EQ(ref[32 * y].x, 0.0) << y;  // the foot is in shadow
  const float bias = GlBackendOptions{}.slopeBias;
  const int resolved = band(bias, true), now = band(bias, false), old = band(3.0f, false);
  std::printf("lit band along the foot: %d texel(s) with contact texels resolved, %d (slope bias %.1f), %d (3.0)\n",
              resolved, now, bias, old);
  EXPECT_EQ(resolved, 0);  // the foot's texels are contact texels: rays find them dark
  EXPECT_LE(now, 1);
  EXPECT_GE(old, 2);
}

// Smooth shading normals on a hard-edged box (an asset smoothed across its corners): the texel samples'
// normals lean up to 55° away from the face they sit on. The depth bias must follow the surface the
// shadow map sampled, i.e. the geometric normal; with the shading normal it under-biased where the normal
// leans towards a grazing VPL, and the face shadowed itself.
TEST(GlBackend, SmoothShadingNormalsOnHardEdgesMatchRayTracedVisibility) {
  Fixture f;
  const int white = addMaterial(f.scene, glm::vec3(0.5f));
  addQuad(f.scene, white, {-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, 4);
  addBox(f.scene, white, {-0.5f, -0.5f, 0.0f}, {0.5f, 0.5f, 1.0f}, false);
  // Samples on the box's +X face (x = 0.5), normals as a smooth box would interpolate them: from the centre.
  TexelSamples t = gridSamples({0.5f, -0.5f, 0.0f}, {0, 1, 0}, {0, 0, 1}, 24, 24, 6);  // the box's +X quad
  ASSERT_NEAR(glm::dot(glm::normalize(glm::cross(f.scene.primitives[6].positions[1] - f.scene.primitives[6].positions[0],
                                                 f.scene.primitives[6].positions[2] - f.scene.primitives[6].positions[0])),
                       glm::vec3(1, 0, 0)), 1.0f, 1e-6f);
  for (size_t i = 0; i < t.layerSize(); ++i)
    t.normal[i] = glm::vec4(glm::normalize(glm::vec3(t.positionWeight[i]) - glm::vec3(0, 0, 0.5f)), 0.0f);
  f.pages.push_back(t);
  f.rt = std::make_unique<RayTracer>(f.scene);
  for (int i = 0; i < 6; ++i) {  // VPLs beside the box, nearly in the face's plane: grazing on the face
    const float side = i % 2 ? 1.0f : -1.0f;
    f.vpls.vpls.push_back(Vpl{{0.55f + 0.05f * (i / 2), side * (1.5f + 0.2f * i), 0.2f + 0.25f * (i / 2)},
                              glm::normalize(glm::vec3(0.3f, -side, 0.0f)), glm::vec3(1.0f), 1});
  }
  GlBackendOptions opt;
  opt.cubeFaceSize = 256;
  const auto maps = f.bake({}, opt);
  const auto ref = cpuReference(f, f.pages[0], 0.0f, true);
  const double e = relativeRmse(ref, maps[0]);
  double sumRef = 0, sumGl = 0;
  for (size_t i = 0; i < ref.size(); ++i) sumRef += ref[i].x, sumGl += maps[0].texels[i].x;
  std::printf("smooth normals on a box face: GL vs ray-traced visibility, relative RMSE %.4f (sums %.4g, %.4g)\n", e,
              sumGl, sumRef);
  EXPECT_GT(sumRef, 0.0);
  EXPECT_LT(e, 0.02);
}

// The sampler's depth comparison (GL_LINEAR on a compare-mode depth array) is the same 2×2 percentage-
// closer filter as the four texelFetch taps and compares it replaced. The sampler rounds its filter
// weights its own way: a few shadow-edge texels may differ by up to 1/256 of one VPL's unshadowed value
// (a GPU's 8-bit sub-texel precision); every other texel agrees to float rounding.
TEST(GlBackend, HardwareDepthCompareEqualsFourTapPcf) {
  Fixture f = floorScene(true);
  addVplRow(f, 5, {-0.4f, -0.2f, 0.9f}, {0.2f, 0.1f, 0.05f});
  GlBackendOptions hw, taps;
  hw.cubeFaceSize = taps.cubeFaceSize = 64;  // coarse: many texels on a filtered shadow edge
  taps.shadowCompare = false;
  const auto a = f.bake({}, hw), b = f.bake({}, taps);
  size_t partial = 0, rounded = 0;  // texels on a filtered edge; texels differing beyond float rounding
  double num = 0, den = 0;
  const auto open = cpuReference(f, f.pages[0], 0.0f, false);
  for (size_t i = 0; i < a[0].size(); ++i) {
    const double d = std::abs(a[0].texels[i].x - b[0].texels[i].x);
    EXPECT_LE(d, open[i].x / 256.0 + 1e-9) << i;
    rounded += d > 1e-5 * open[i].x + 1e-9;
    partial += a[0].texels[i].x > 0.01 * open[i].x && a[0].texels[i].x < 0.99 * open[i].x;
    num += d * d;
    den += double(b[0].texels[i].x) * b[0].texels[i].x;
  }
  EXPECT_GT(partial, 20u);            // the filter is exercised
  EXPECT_LT(rounded, partial);        // only edge texels can differ beyond rounding
  EXPECT_LT(std::sqrt(num / den), 1e-3);
  std::printf("edge texels %zu, beyond rounding %zu, relative RMSE %.2e\n", partial, rounded, std::sqrt(num / den));
}

// The VPL depth atlas: every lookup path (sampler compare, 4-tap PCF, nearest texel) reads only its own
// tile, and flushing the shadow scene after every face or never gives the same maps bit for bit.
TEST(GlBackend, DepthAtlasPathsAgreeAndFlushingChangesNothing) {
  Fixture f = floorScene(true);
  f.rt = std::make_unique<RayTracer>(f.scene);
  addVplRow(f, 7, {-0.45f, -0.25f, 0.85f}, {0.15f, 0.08f, 0.04f});  // 3 per pass: a partial last batch
  GlBackendOptions base;
  base.vplsPerPass = 3;
  base.cubeFaceSize = 512;
  GlBackendOptions flushAll = base, taps = base, nearest = base;
  base.shadowFlushTriangles = 0;
  flushAll.shadowFlushTriangles = 1;
  taps.shadowCompare = false;
  nearest.shadowPcf = false;
  const auto a = f.bake({}, base), b = f.bake({}, flushAll), c = f.bake({}, taps), d = f.bake({}, nearest);
  const auto ref = cpuReference(f, f.pages[0], 0.0f, true);
  for (size_t i = 0; i < a[0].size(); ++i) EXPECT_EQ(a[0].texels[i], b[0].texels[i]) << i;
  EXPECT_LT(relativeRmse(ref, a[0]), 0.03);
  EXPECT_LT(relativeRmse(ref, c[0]), 0.03);
  EXPECT_LT(relativeRmse(ref, d[0]), 0.04);
  std::printf("vs ray traced: compare %.4f, taps %.4f, nearest %.4f\n", relativeRmse(ref, a[0]),
              relativeRmse(ref, c[0]), relativeRmse(ref, d[0]));
}

// Invalid texels are skipped by the early depth test against the page's validity mask: they stay 0
// and the valid texels are exactly what a bake without the mask gives.
TEST(GlBackend, ValidityMaskSkipsOnlyInvalidTexels) {
  Fixture f = floorScene(true);
  TexelSamples& s = f.pages[0];
  for (size_t i = 0; i < s.layerSize(); ++i)
    if ((i * 7) % 5 == 0 || (i / 32) % 8 < 2) s.valid[i] = 0;  // scattered and whole 8-texel rows
  addVplAndPointLight(f);
  GlBackendOptions masked, unmasked;
  masked.pointFaceSize = unmasked.pointFaceSize = 256;
  unmasked.skipInvalidTexels = false;
  const auto a = f.bake({}, masked), b = f.bake({}, unmasked);
  size_t valid = 0;
  for (size_t i = 0; i < s.layerSize(); ++i) {
    EXPECT_EQ(a[0].valid[i], s.valid[i]);
    EXPECT_EQ(a[0].texels[i], b[0].texels[i]) << i;
    if (!s.valid[i]) {
      EXPECT_EQ(a[0].texels[i], glm::vec3(0.0f)) << i;
    }
    valid += s.valid[i] && a[0].texels[i].x > 0.0f;
  }
  EXPECT_GT(valid, s.layerSize() / 3);
}

TEST(GlBackend, ClampBoundsGeometryTerm) {
  Fixture f = floorScene(false);
  Vpl v;
  v.position = {0.0f, 0.0f, 0.05f};
  v.normal = {0, 0, -1};
  v.power = glm::vec3(1.0f);
  f.vpls.vpls.push_back(v);
  VplEvalOptions eval;
  eval.clampBound = 10.0f;  // 1/r² = 400 below the VPL
  auto maps = f.bake(eval);
  const auto ref = cpuReference(f, f.pages[0], eval.clampBound, false);
  EXPECT_LT(relativeRmse(ref, maps[0]), 1e-4);
  float peak = 0;
  for (auto& t : maps[0].texels) peak = std::max(peak, t.x);
  EXPECT_NEAR(peak, 10.0 / (kPi * kPi), 1e-5);
}

TEST(GlBackend, ManyVplsAccumulateWithoutPrecisionLoss) {
  // 1536 VPLs over 12 passes of 128, folded in double: the sum matches the CPU double sum.
  Fixture f = floorScene(false);
  f.pages[0] = gridSamples({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 8, 8);
  for (int i = 0; i < 1536; ++i) {
    Vpl v;
    const double a = 2.399963 * i;  // golden-angle spiral
    v.position = glm::vec3(0.8 * std::cos(a) * std::sqrt(i / 1536.0), 0.8 * std::sin(a) * std::sqrt(i / 1536.0),
                           0.5 + 0.3 * ((i * 7) % 11) / 11.0);
    v.normal = {0, 0, -1};
    v.power = glm::vec3(1e-3f * (1 + i % 5));
    f.vpls.vpls.push_back(v);
  }
  GlBackendOptions opt;
  opt.vplsPerPass = 128;
  opt.cubeFaceSize = 16;
  opt.foldEveryPasses = 4;
  GlBakeStats stats;
  opt.stats = &stats;
  auto maps = f.bake({}, opt);
  const auto ref = cpuReference(f, f.pages[0], 0.0f, false);
  for (size_t i = 0; i < ref.size(); ++i) EXPECT_NEAR(maps[0].texels[i].x / ref[i].x, 1.0, 2e-5) << i;
  EXPECT_EQ(stats.vpls, 1536u);
  EXPECT_EQ(stats.passes, 12u);
  EXPECT_EQ(stats.facesRendered, 5u * 1536u);
  EXPECT_FALSE(stats.renderer.empty());
}

TEST(GlBackend, SupersampleLayersAreWeighted) {
  // S = 2: four layers; weights 0.4/0.3/0.2/0.1 of four distinct positions.
  Fixture f = floorScene(false);
  TexelSamples s = gridSamples({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 4, 4);
  TexelSamples ss = s;
  ss.supersample = 2;
  ss.positionWeight.clear();
  ss.normal.clear();
  const float w[4] = {0.4f, 0.3f, 0.2f, 0.1f};
  for (int l = 0; l < 4; ++l)
    for (size_t i = 0; i < s.layerSize(); ++i) {
      glm::vec4 p = s.positionWeight[i];
      ss.positionWeight.push_back(glm::vec4(p.x + 0.1f * l, p.y, 0.0f, w[l]));
      ss.normal.push_back(s.normal[i]);
    }
  f.pages[0] = ss;
  Vpl v;
  v.position = {0.1f, 0.2f, 0.6f};
  v.normal = {0, 0, -1};
  v.power = glm::vec3(1.0f);
  f.vpls.vpls.push_back(v);
  auto maps = f.bake();
  const auto ref = cpuReference(f, ss, 0.0f, false);
  EXPECT_LT(relativeRmse(ref, maps[0]), 1e-5);
}

double pointLightCpu(const Light& L, glm::vec3 x, glm::vec3 n, const RayTracer& rt) {
  glm::vec3 d = L.position - x;
  float r = glm::length(d);
  float c = glm::dot(n, d / r);
  if (c <= 0 || rt.occluded(x + n * rt.epsilon(), d / r, 0.0f, r - rt.epsilon())) return 0.0;
  return lightKind(L).intensityToward(L, -d / r).x * c / (r * r) / kPi;
}

TEST(GlBackend, PointAndSpotLightsAreExactWithShadowMaps) {
  for (LightType type : {LightType::Point, LightType::Spot}) {
    Fixture f = floorScene(true);
    f.rt = std::make_unique<RayTracer>(f.scene);
    Light L = testing::pointLight({0.1f, 0.05f, 1.2f}, 3.0f);
    L.type = type;
    L.direction = glm::normalize(glm::vec3(0.1f, 0.0f, -1.0f));
    L.innerConeAngle = 0.4f;
    L.outerConeAngle = 0.7f;
    f.scene.lights.push_back(L);
    GlBackendOptions opt;
    opt.pointFaceSize = 256;
    opt.lightMapSize = 512;
    auto maps = f.bake({}, opt);
    std::vector<glm::dvec3> ref;
    for (const glm::vec4& p : f.pages[0].positionWeight)
      ref.push_back(glm::dvec3(pointLightCpu(L, glm::vec3(p), {0, 0, 1}, *f.rt)));
    double rmse = 0, den = 0;
    for (size_t i = 0; i < ref.size(); ++i) rmse += std::pow(maps[0].texels[i].x - ref[i].x, 2), den += ref[i].x * ref[i].x;
    EXPECT_LT(std::sqrt(rmse / den), 0.03) << (type == LightType::Point ? "point" : "spot");
    // A texel far from the shadow edge: exact. Texel (2, 2) at (-0.84, -0.84).
    EXPECT_NEAR(maps[0].texels[2 * 32 + 2].x, ref[2 * 32 + 2].x, 1e-4 * ref[2 * 32 + 2].x + 1e-9);
  }
}

// An EXT_lights_ies light 1 m above a 2×2 m floor, its nadir straight down and its horizontal angle 0 along +X:
// each texel holds candela(θ, φ) × multiplier × cosθ / d² as the map's E/π (docs/export.md), on the GL backend
// (its profile table, direct_light.frag) and on Embree (the light kind's direct term), θ from 0 to 55°.
TEST(GlBackend, IesLightOnAFloorIsCandelaTimesCosineOverDistanceSquared) {
  Fixture f = floorScene(false);
  Light L;
  L.type = LightType::Ies;
  L.position = {0.1f, -0.05f, 1.0f};
  L.direction = {0.0f, 0.0f, -1.0f};
  L.profileAxisX = {1.0f, 0.0f, 0.0f};
  L.intensity = 1.5f;
  L.profile = std::make_shared<const IesProfile>(parseIesProfile(testing::cosineIesProfile(3.0), "floor.ies"));
  f.scene.lights.push_back(L);
  f.rt = std::make_unique<RayTracer>(f.scene);
  GlBackendOptions opt;
  opt.pointFaceSize = 256;
  const std::vector<Lightmap> gl = f.bake({}, opt);
  const BakeInputs in{f.scene, *f.rt, f.pages, f.vpls, {}, {}};
  const std::vector<Lightmap> embree = EmbreeEvaluator().evaluate(in);
  double glWorst = 0.0, embreeWorst = 0.0, widest = 0.0;
  for (size_t i = 0; i < f.pages[0].layerSize(); ++i) {
    const glm::vec4 pw = f.pages[0].positionWeight[i];
    if (pw.w <= 0.0f) continue;
    const glm::dvec3 d = glm::dvec3(glm::vec3(pw)) - glm::dvec3(L.position);  // from the light
    const double r2 = glm::dot(d, d), r = std::sqrt(r2);
    const double theta = std::acos(-d.z / r) * 180.0 / kPi, phi = std::atan2(d.y, d.x) * 180.0 / kPi;
    const double expected = pw.w * 1.5 * testing::cosineIesCandela(3.0, theta, phi) * (-d.z / r) / (kPi * r2);
    glWorst = std::max(glWorst, std::abs(gl[0].texels[i].x - expected) / expected);
    embreeWorst = std::max(embreeWorst, std::abs(embree[0].texels[i].x - expected) / expected);
    widest = std::max(widest, theta);
  }
  EXPECT_GT(widest, 50.0);
  EXPECT_LT(glWorst, 1e-3);
  EXPECT_LT(embreeWorst, 1e-4);
  // Beside the light along +X and −X, about 40° off the nadir: the profile's f(0°) = 1.5 against f(180°) = 0.5.
  const size_t plusX = 16 * 32 + 30, minusX = 16 * 32 + 3;
  EXPECT_GT(embree[0].texels[plusX].x, 2.0f * embree[0].texels[minusX].x);
  EXPECT_GT(gl[0].texels[plusX].x, 2.0f * gl[0].texels[minusX].x);
}

TEST(GlBackend, DirectionalLightIsExactWithOrthoShadowMap) {
  Fixture f = floorScene(true);
  f.rt = std::make_unique<RayTracer>(f.scene);
  Light L;
  L.type = LightType::Directional;
  L.direction = glm::normalize(glm::vec3(0.3f, 0.2f, -1.0f));
  L.intensity = 2.0f;
  f.scene.lights.push_back(L);
  GlBackendOptions opt;
  opt.lightMapSize = 512;
  auto maps = f.bake({}, opt);
  const glm::vec3 toLight = -L.direction;
  const double open = 2.0 * toLight.z / kPi;
  size_t inShadow = 0, mismatched = 0;
  for (size_t i = 0; i < f.pages[0].layerSize(); ++i) {
    glm::vec3 x = glm::vec3(f.pages[0].positionWeight[i]);
    bool lit = !f.rt->occluded(x + glm::vec3(0, 0, 1e-4f), toLight, 0.0f, 100.0f);
    inShadow += !lit;
    double expect = lit ? open : 0.0;
    if (std::abs(maps[0].texels[i].x - expect) > 1e-5) ++mismatched;
  }
  EXPECT_GT(inShadow, 50u);
  EXPECT_LE(mismatched, 8u);  // at most a few texels on the shadow edge
}

// A bake with VPLs and a punctual light equals the sum of the two bakes alone: the direct pass is
// added to the VPL partial sums that are still on the GPU (none folded: one pass, no fold).
TEST(GlBackend, DirectAndVplPassesAdd) {
  Fixture f = floorScene(true);
  addVplAndPointLight(f);
  GlBackendOptions opt;
  opt.foldEveryPasses = 100;
  VplEvalOptions both, vplOnly, directOnly;
  vplOnly.includeDirect = false;
  directOnly.includeVpls = false;
  const auto a = f.bake(both, opt), b = f.bake(vplOnly, opt), c = f.bake(directOnly, opt);
  double sumA = 0, sumB = 0, sumC = 0;
  for (size_t i = 0; i < a[0].size(); ++i) {
    EXPECT_NEAR(a[0].texels[i].x, b[0].texels[i].x + c[0].texels[i].x, 1e-6 + 1e-5 * a[0].texels[i].x) << i;
    sumA += a[0].texels[i].x, sumB += b[0].texels[i].x, sumC += c[0].texels[i].x;
  }
  EXPECT_GT(sumB, 0.1 * sumA);
  EXPECT_GT(sumC, 0.1 * sumA);
}

// A context's programs are built once: a second bake on the same context compiles nothing and gives
// the same map (interleaved sampling calls the backend n² + 1 times per bake).
TEST(GlBackend, SecondBakeOnAContextReusesItsPrograms) {
  Fixture f = floorScene(true);
  f.vpls.vpls = {Vpl{{0.1f, 0.0f, 1.0f}, {0, 0, -1}, glm::vec3(2.0f), 1}};
  GlContext context;
  GlBackendOptions opt;
  opt.context = &context;
  const std::vector<Lightmap> first = f.bake({}, opt);
  const size_t builds = context.programs().builds();
  EXPECT_GE(builds, 2u);  // depth, direct, accumulation
  const std::vector<Lightmap> second = f.bake({}, opt);
  EXPECT_EQ(context.programs().builds(), builds);
  ASSERT_EQ(first.size(), second.size());
  for (size_t i = 0; i < first[0].size(); ++i) ASSERT_EQ(first[0].texels[i], second[0].texels[i]) << i;
}

// Stands in for any evaluator: 7 in every texel it is asked for, and what it was asked.
class ConstantEvaluator final : public Evaluator {
 public:
  std::vector<Lightmap> evaluate(const BakeInputs& in, const EvaluationRequest& request) const override {
    ++calls;
    subset = request.texelSubset ? *request.texelSubset : std::vector<std::vector<uint8_t>>{};
    std::vector<Lightmap> maps;
    for (size_t p = 0; p < in.texels.size(); ++p) {
      maps.push_back(blankLightmap(in.texels[p]));
      for (size_t t = 0; t < maps[p].size(); ++t)
        if (!request.texelSubset || (*request.texelSubset)[p][t]) {
          maps[p].texels[t] = glm::vec3(7.0f);
          maps[p].valid[t] = 1;
        }
    }
    return maps;
  }
  const char* name() const override { return "constant"; }
  nlohmann::json stats() const override { return {{"calls", calls}}; }
  mutable int calls = 0;
  mutable std::vector<std::vector<uint8_t>> subset;
};

// The GL evaluator knows no other evaluator: its contact texels go to whichever it was handed, and only
// they; every other texel keeps the bits the shadow maps gave it.
TEST(GlEvaluator, ContactTexelsGoToTheEvaluatorItIsGiven) {
  Fixture f = wallOnFloor();
  GlBackendOptions opt;
  opt.cubeFaceSize = 128;
  const std::vector<Lightmap> traced = f.bake({}, opt);  // the Embree evaluator's contact texels
  GlBakeStats stats;
  opt.stats = &stats;
  const ConstantEvaluator constant;
  const BakeInputs in{f.scene, *f.rt, f.pages, f.vpls, {}, {}};
  const std::vector<Lightmap> maps = GlEvaluator(opt, &constant).evaluate(in);
  ASSERT_EQ(constant.calls, 1);
  ASSERT_EQ(constant.subset.size(), 1u);
  size_t contacts = 0;
  for (size_t t = 0; t < maps[0].size(); ++t) {
    if (constant.subset[0][t]) {
      ++contacts;
      EXPECT_EQ(maps[0].texels[t], glm::vec3(7.0f)) << t;
    } else {
      EXPECT_EQ(maps[0].texels[t], traced[0].texels[t]) << t;
    }
  }
  EXPECT_GE(contacts, 32u);  // at least the row of texels along the wall's foot
  EXPECT_LT(contacts, maps[0].size() / 2);
  EXPECT_EQ(stats.contactTexels, contacts);

  GlBakeStats alone;
  opt.stats = &alone;
  GlEvaluator(opt, nullptr).evaluate(in);  // no contact evaluator: nothing resolved
  EXPECT_EQ(alone.contactTexels, 0u);
  EXPECT_EQ(alone.texelsEvaluated, 32u * 32u);
}

// A texel subset: the texels outside it come back invalid and 0, those inside with the bits of the whole
// page, and the L1 pages alike.
TEST(GlEvaluator, TexelSubsetKeepsItsTexelsOnly) {
  Fixture f = floorScene(true);
  addVplAndPointLight(f);
  std::vector<std::vector<uint8_t>> subset(1, std::vector<uint8_t>(32 * 32, 0));
  for (size_t t = 0; t < subset[0].size(); ++t) subset[0][t] = (t / 32 + t % 32) % 2;  // a checkerboard
  L1Pages wholeL1, partL1;
  EvaluationRequest whole, part;
  whole.directional = &wholeL1;
  part.directional = &partL1;
  part.texelSubset = &subset;
  GlBakeStats wholeStats, partStats;
  GlBackendOptions opt;
  opt.pointFaceSize = 256;
  opt.stats = &wholeStats;
  const std::vector<Lightmap> a = f.bake({}, opt, whole);
  opt.stats = &partStats;
  const std::vector<Lightmap> b = f.bake({}, opt, part);
  ASSERT_EQ(b.size(), 1u);
  size_t inside = 0;
  for (size_t t = 0; t < b[0].size(); ++t) {
    if (subset[0][t]) {
      ++inside;
      ASSERT_EQ(b[0].valid[t], 1) << t;
      EXPECT_EQ(b[0].texels[t], a[0].texels[t]) << t;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(partL1[k][0].texels[t], wholeL1[k][0].texels[t]) << t;
    } else {
      EXPECT_EQ(b[0].valid[t], 0) << t;
      EXPECT_EQ(b[0].texels[t], glm::vec3(0.0f)) << t;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(partL1[k][0].texels[t], glm::vec3(0.0f)) << t;
    }
  }
  EXPECT_EQ(inside, 512u);
  EXPECT_GT(a[0].texels[16 * 32 + 3].x, 0.0f);  // lit: the comparison above is not of zeros
  EXPECT_EQ(wholeStats.texelsEvaluated, 1024u);
  EXPECT_EQ(partStats.texelsEvaluated, 512u);
}

// stats(): the figures the pipeline reports ("renderer", "gl", "timings.gl"), added over the calls.
TEST(GlEvaluator, StatsAddUpOverCalls) {
  Fixture f = floorScene(true);
  addVplAndPointLight(f);
  f.rt = std::make_unique<RayTracer>(f.scene);
  const BakeInputs in{f.scene, *f.rt, f.pages, f.vpls, {}, {}};
  GlBackendOptions opt;
  opt.pointFaceSize = 256;
  const GlEvaluator gl(opt);
  EXPECT_STREQ(gl.name(), "gl");
  gl.evaluate(in);
  gl.evaluate(in);
  const nlohmann::json stats = gl.stats();
  EXPECT_FALSE(stats.at("renderer").get<std::string>().empty());
  EXPECT_EQ(stats.at("counts").at("passes"), 4);  // per call: one VPL pass, one point light
  EXPECT_EQ(stats.at("counts").at("contactTexels"), 0);
  EXPECT_GT(stats.at("timings").at("setupSeconds").get<double>(), 0.0);
  EXPECT_EQ(stats.at("timings").at("contactSeconds").get<double>(), 0.0);
}

TEST(GlBackend, EmptyInputsGiveZeroMaps) {
  Fixture f = floorScene(false);
  auto maps = f.bake();
  ASSERT_EQ(maps.size(), 1u);
  for (auto& t : maps[0].texels) EXPECT_EQ(t, glm::vec3(0.0f));
}

}  // namespace
}  // namespace irbake
