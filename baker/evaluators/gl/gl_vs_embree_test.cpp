// The GL evaluator against the Embree evaluator (also its contact evaluator) on the same atlas, texel samples
// and VPL set: relative RMSE < 1% on each scene, the furnace within its tests' tolerance. Small pages
// (≈ 64² … 128²) keep each test to seconds on llvmpipe.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "atlas/atlas.h"
#include "evaluators/embree/embree_backend.h"
#include "transport/geometry_term.h"
#include "evaluators/gl/gl_backend.h"
#include "raytrace/ray_tracer.h"
#include "scene/gltf_loader.h"
#include "samples/sample_scenes.h"
#include "texels/texel_samples.h"
#include "vpl/vpl.h"

namespace irbake {
namespace {

struct Comparison {
  double relativeRmse = 0.0;  // GL vs Embree over valid texels, all channels
  double meanEmbree = 0.0, meanGl = 0.0;
  size_t validTexels = 0;
  GlBakeStats gl;
  // With directional: GL vs Embree on the L1 pages (all axes and channels, relative to the Embree pages'
  // RMS), and whether each backend's map with L1 is the bits of its map without.
  double l1RelativeRmse = 0.0;
  bool glMapUnchanged = false, embreeMapUnchanged = false;
};

bool sameBits(const std::vector<Lightmap>& a, const std::vector<Lightmap>& b) {
  if (a.size() != b.size()) return false;
  for (size_t p = 0; p < a.size(); ++p)
    if (a[p].valid != b[p].valid || a[p].texels.size() != b[p].texels.size() ||
        std::memcmp(a[p].texels.data(), b[p].texels.data(), a[p].texels.size() * sizeof(glm::vec3)) != 0)
      return false;
  return true;
}

// Relative RMSE of b against a over a's valid texels, all channels.
double relativeRmse(const std::vector<Lightmap>& b, const std::vector<Lightmap>& a, double& num, double& den) {
  for (size_t p = 0; p < std::min(a.size(), b.size()); ++p)
    for (size_t i = 0; i < a[p].size(); ++i) {
      if (!a[p].valid[i]) continue;
      for (int ch = 0; ch < 3; ++ch) {
        const double e = b[p].texels[i][ch] - double(a[p].texels[i][ch]);
        num += e * e;
        den += double(a[p].texels[i][ch]) * a[p].texels[i][ch];
      }
    }
  return std::sqrt(num / std::max(den, 1e-300));
}

Comparison compareBackends(Scene scene, int pageSize, int paths, int supersample = 1, bool includeDirect = true,
                           bool directional = false) {
  AtlasOptions atlas;
  atlas.targetPageSize = pageSize;
  atlas.maxPageSize = pageSize;
  atlas.texelsPerTriangle = 0.0f;  // one page of pageSize², also for Sponza
  buildAtlas(scene, atlas);
  RayTracer rt(scene);
  TexelSampleOptions to;
  to.supersample = supersample;
  const std::vector<TexelSamples> texels = buildTexelSamples(scene, rt, to);
  WalkOptions walk;
  walk.paths = paths;
  walk.seed = 7;
  const VplSet vpls = generateVpls(scene, rt, walk);
  VplEvalOptions eval;
  eval.clampBound = deriveClampBound(scene, vpls);
  eval.includeDirect = includeDirect;
  BakeInputs in{scene, rt, texels, vpls, eval, {}};
  const EmbreeEvaluator embree;
  const std::vector<Lightmap> ref = embree.evaluate(in);
  Comparison c;
  GlBackendOptions go;
  go.stats = &c.gl;
  const std::vector<Lightmap> gl = GlEvaluator(go, &embree).evaluate(in);
  EXPECT_EQ(gl.size(), ref.size());
  double num = 0, den = 0;
  for (size_t p = 0; p < std::min(gl.size(), ref.size()); ++p) {
    EXPECT_EQ(gl[p].size(), ref[p].size());
    for (size_t i = 0; i < ref[p].size(); ++i) {
      if (!ref[p].valid[i]) continue;
      EXPECT_EQ(gl[p].valid[i], 1);
      ++c.validTexels;
      for (int ch = 0; ch < 3; ++ch) {
        const double e = gl[p].texels[i][ch] - double(ref[p].texels[i][ch]);
        num += e * e;
        den += double(ref[p].texels[i][ch]) * ref[p].texels[i][ch];
        c.meanEmbree += ref[p].texels[i][ch];
        c.meanGl += gl[p].texels[i][ch];
      }
    }
  }
  c.relativeRmse = std::sqrt(num / std::max(den, 1e-300));
  c.meanEmbree /= std::max<size_t>(1, 3 * c.validTexels);
  c.meanGl /= std::max<size_t>(1, 3 * c.validTexels);
  std::printf("texels %zu, VPLs %zu: relative RMSE %.4f%%, mean embree %.6g gl %.6g\n", c.validTexels, vpls.vpls.size(),
              100.0 * c.relativeRmse, c.meanEmbree, c.meanGl);
  if (directional) {
    L1Pages refL1, glL1;
    EvaluationRequest er, gr;
    er.directional = &refL1;
    gr.directional = &glL1;
    c.embreeMapUnchanged = sameBits(embree.evaluate(in, er), ref);
    c.glMapUnchanged = sameBits(GlEvaluator({}, &embree).evaluate(in, gr), gl);
    double l1Num = 0.0, l1Den = 0.0;
    for (int k = 0; k < 3; ++k) c.l1RelativeRmse = relativeRmse(glL1[k], refL1[k], l1Num, l1Den);
    std::printf("L1 pages: relative RMSE %.4f%% (RMS of the Embree pages %.4g); maps unchanged: gl %d, embree %d\n",
                100.0 * c.l1RelativeRmse, std::sqrt(l1Den / std::max<size_t>(1, 9 * c.validTexels)), c.glMapUnchanged,
                c.embreeMapUnchanged);
  }
  return c;
}

TEST(GlVsEmbree, CornellBoxWithinOnePercent) {
  const Comparison c = compareBackends(samples::makeCornellBox(), 128, 256);
  EXPECT_GT(c.validTexels, 5000u);
  EXPECT_GT(c.meanEmbree, 0.0);
  EXPECT_LT(c.relativeRmse, 0.01);
}

// Directional maps: the GL evaluator's L1 targets against the Embree evaluator's L1 on the same VPLs, and
// neither map changes by a bit when the L1 pages are asked for. The Cornell box's coarse page gets the
// looser bound: near its inner corners L1 is dominated by wall VPLs at grazing angles, which L0 weights by
// cosθ ≈ 0 but L1 does not (E ω, not E cosθ, unbounded by the clamp of G), and which cube lookups shadow by acne.
TEST(GlVsEmbree, DirectionalL1AgreesAndMapsUnchanged) {
  for (bool corner : {false, true}) {
    const Comparison c =
        compareBackends(corner ? samples::makeCorner() : samples::makeCornellBox(), 128, 256, corner ? 2 : 1, true, true);
    EXPECT_TRUE(c.glMapUnchanged) << corner;
    EXPECT_TRUE(c.embreeMapUnchanged) << corner;
    EXPECT_LT(c.l1RelativeRmse, corner ? 0.01 : 0.025) << corner;
  }
}

TEST(GlVsEmbree, CornerSceneWithinOnePercent) {
  // Spot light (2D perspective shadow map) plus bounce VPLs in a corner: the VPL singularity case.
  const Comparison c = compareBackends(samples::makeCorner(), 128, 256);
  EXPECT_GT(c.validTexels, 3000u);
  EXPECT_LT(c.relativeRmse, 0.01);
}

// Triangles wound against their vertex normals (front faces away from the light, normals towards it) are lit on
// the normals' side by both backends: GL took the winding's side and left every texel black.
TEST(GlVsEmbree, TrianglesWoundAgainstTheirNormalsAreLitOnTheNormalsSide) {
  Scene scene = samples::makeCorner();
  for (Primitive& p : scene.primitives) {
    if (p.normals.size() != p.positions.size()) {
      p.normals.assign(p.positions.size(), glm::vec3(0.0f));
      for (size_t t = 0; 3 * t + 2 < p.indices.size(); ++t) {
        const uint32_t* i = &p.indices[3 * t];
        const glm::vec3 n = glm::normalize(glm::cross(p.positions[i[1]] - p.positions[i[0]], p.positions[i[2]] - p.positions[i[0]]));
        for (int k = 0; k < 3; ++k) p.normals[i[k]] = n;
      }
    }
    for (size_t t = 0; 3 * t + 2 < p.indices.size(); ++t) std::swap(p.indices[3 * t + 1], p.indices[3 * t + 2]);
  }
  const Comparison wound = compareBackends(scene, 128, 256);
  const Comparison plain = compareBackends(samples::makeCorner(), 128, 256);
  EXPECT_GT(wound.validTexels, 3000u);
  EXPECT_LT(wound.relativeRmse, 0.01);
  EXPECT_NEAR(wound.meanGl / plain.meanGl, 1.0, 0.02);  // lit as the plainly wound corner
}

TEST(GlVsEmbree, CornerBouncesOnlyWithinOnePercent) {
  // Only the VPLs (no exact direct light), so the comparison is about the VPL cubes alone.
  const Comparison c = compareBackends(samples::makeCorner(), 128, 256, 1, false);
  EXPECT_GT(c.meanEmbree, 0.0);
  EXPECT_LT(c.relativeRmse, 0.01);
}

// The real Cornell box from ../shared (McGuire's archive, converted; no NORMAL, so flat normals by the
// glTF rule), skipped without it. Its blocks once had smooth computed normals that leant 55° off their
// faces, and the GL backend's bias then followed the shading normal.
TEST(GlVsEmbree, SharedCornellBoxWithinOnePercent) {
  const char* src = std::getenv("IRBAKE_SOURCE_DIR");
  const std::filesystem::path file =
      std::filesystem::path(src ? src : ".") / "../shared/scenes/cornell_box/cornell_box.glb";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "third-party scene not present: " << file;
  const Comparison c = compareBackends(loadScene(file), 128, 256);
  EXPECT_GT(c.validTexels, 5000u);
  EXPECT_GT(c.meanEmbree, 0.0);
  EXPECT_LT(c.relativeRmse, 0.01);
}

// Contacts a shadow map cannot resolve (a cupboard 1 mm from a wall, a box resting on the
// floor, a lamp 0.1 mm under the ceiling). Without resolving contact texels with rays the GL backend lit
// the texels along every contact; the figures with resolveContacts off are printed for comparison.
TEST(GlVsEmbree, ContactsSampleWithinOnePercent) {
  const Comparison c = compareBackends(samples::makeContacts(), 256, 256);
  EXPECT_GT(c.validTexels, 20000u);
  EXPECT_GT(c.meanEmbree, 0.0);
  EXPECT_LT(c.relativeRmse, 0.01);
  EXPECT_GT(c.gl.contactTexels, 0u);
  std::printf("[ figure ] contacts: GL vs Embree %.3f%%, %zu contact texels (%.1f%%) traced in %.3f s\n",
              100 * c.relativeRmse, c.gl.contactTexels, 100.0 * c.gl.contactTexels / std::max<size_t>(1, c.gl.texelsEvaluated),
              c.gl.contactSeconds);
}

// Sponza (../shared, skipped without it) under a tilted sun: the sun's orthographic map and the bounce
// VPLs' cubes against ray-traced visibility, 66k triangles, a coarse atlas and few paths to stay quick.
TEST(GlVsEmbree, SponzaWithSunWithinOnePercent) {
  const char* src = std::getenv("IRBAKE_SOURCE_DIR");
  const std::filesystem::path file =
      std::filesystem::path(src ? src : ".") / "../shared/scenes/dabrovic_sponza/sponza.glb";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "third-party scene not present: " << file;
  Scene scene = loadScene(file);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(0.35f, -1.0f, 0.2f));
  sun.intensity = 5.0f;
  scene.lights.push_back(sun);
  const Comparison c = compareBackends(std::move(scene), 512, 64);
  EXPECT_GT(c.validTexels, 50000u);
  EXPECT_GT(c.meanEmbree, 0.0);
  EXPECT_LT(c.relativeRmse, 0.01);
  std::printf("[ figure ] sponza + sun: GL vs Embree %.3f%%, %zu contact texels (%.1f%%) traced in %.3f s\n",
              100 * c.relativeRmse, c.gl.contactTexels, 100.0 * c.gl.contactTexels / std::max<size_t>(1, c.gl.texelsEvaluated),
              c.gl.contactSeconds);
}

// See-through surfaces: a red BLEND pane (α 0.5) and a MASK-free clear transmissive pane
// between a point light and a floor, in a room whose bounces pass them too. GL draws them into shadow maps
// of their own and sends the texels they shade to the rays: the two backends agree.
TEST(GlVsEmbree, SeeThroughPanesWithinOnePercent) {
  Scene scene = samples::makeContacts();
  const int red = static_cast<int>(scene.materials.size());
  Material glass;
  glass.name = "red_glass";
  glass.baseColorFactor = glm::vec4(0.9f, 0.2f, 0.2f, 0.5f);
  glass.alphaMode = AlphaMode::Blend;
  scene.materials.push_back(glass);
  Primitive pane;
  pane.name = "pane";
  pane.material = red;
  pane.positions = {{2.6f, 0.8f, 1.0f}, {3.6f, 0.8f, 1.0f}, {3.6f, 0.8f, 2.0f}, {2.6f, 0.8f, 2.0f}};
  pane.normals.assign(4, glm::vec3(0, 1, 0));
  pane.indices = {0, 2, 1, 0, 3, 2};
  scene.primitives.push_back(pane);
  Light point;
  point.type = LightType::Point;
  point.position = glm::vec3(3.1f, 1.6f, 1.5f);
  point.intensity = 2.0f;
  scene.lights.push_back(point);
  const Comparison c = compareBackends(std::move(scene), 256, 256);
  std::printf("[ figure ] red pane: GL vs Embree %.3f%%, %zu texels traced (%.1f%%)\n", 100 * c.relativeRmse,
              c.gl.contactTexels, 100.0 * c.gl.contactTexels / std::max<size_t>(1, c.gl.texelsEvaluated));
  EXPECT_GT(c.validTexels, 20000u);
  EXPECT_LT(c.relativeRmse, 0.01);
}

TEST(GlVsEmbree, FurnaceMatchesClosedForm) {
  // Closed box, ρ = 0.5, Le = 1 on every wall: the incident radiance is Le/(1−ρ) everywhere, so the
  // map (irradiance/π) is exactly 2. The clamp is off, so the estimate is the plain VPL sum: it must
  // equal the Embree evaluator's on the same VPLs. Against the exact answer the unclamped sum converges
  // from below (rare near-corner VPLs carry the singular part), hence the looser bound there.
  Scene scene = samples::makeFurnace(0.5f, 1.0f);
  AtlasOptions atlas;
  atlas.targetPageSize = 64;
  atlas.maxPageSize = 64;
  buildAtlas(scene, atlas);
  RayTracer rt(scene);
  const std::vector<TexelSamples> texels = buildTexelSamples(scene, rt, {});
  WalkOptions walk;
  walk.paths = 2048;
  const VplSet vpls = generateVpls(scene, rt, walk);
  BakeInputs in{scene, rt, texels, vpls, VplEvalOptions{}, {}};
  GlBackendOptions go;
  go.cubeFaceSize = 64;  // a convex box: nothing to shadow, small cubes keep the test quick
  go.vplsPerPass = 64;
  const EmbreeEvaluator embree;
  const std::vector<Lightmap> gl = GlEvaluator(go, &embree).evaluate(in);
  const std::vector<Lightmap> em = embree.evaluate(in);
  double sumGl = 0, sumEm = 0;
  size_t n = 0;
  for (size_t p = 0; p < gl.size(); ++p)
    for (size_t i = 0; i < gl[p].size(); ++i)
      if (gl[p].valid[i]) sumGl += gl[p].texels[i].x, sumEm += em[p].texels[i].x, ++n;
  ASSERT_GT(n, 0u);
  std::printf("furnace: mean gl %.5f embree %.5f (exact 2)\n", sumGl / n, sumEm / n);
  EXPECT_NEAR(sumGl / n, sumEm / n, 0.001 * sumEm / n);
  EXPECT_NEAR(sumGl / n, 2.0, 0.03);
}

}  // namespace
}  // namespace irbake
