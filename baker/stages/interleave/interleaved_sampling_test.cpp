// Interleaved sampling around the Embree backend, its pieces composed as the bake's backend stage composes them
// (testing::bakeBackendStage): the classes partition the texels, punctual lights stay exact, and on closed forms
// the interleaved estimate matches the exact answer like the full one does.
#include "stages/interleave/interleaved_sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "transport/geometry_term.h"
#include "vpl/vpl.h"
#include "testing/backend_stage.h"
#include "testing/scenes.h"

namespace irbake {
namespace {
using namespace irbake::testing;
constexpr double kPi = 3.14159265358979323846;

const EmbreeEvaluator kEmbree;

TEST(InterleavedSampling, ClassesPartitionTheTexels) {
  TexelSamples page = gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 7, 5);
  page.page = 3;
  for (int n : {2, 3}) {
    std::vector<int> seen(page.layerSize(), 0);
    for (int cy = 0; cy < n; ++cy)
      for (int cx = 0; cx < n; ++cx) {
        const auto cls = interleaveClass({page}, n, cx, cy);
        ASSERT_EQ(cls.size(), 1u);
        EXPECT_EQ(cls[0].page, 3);
        for (size_t i = 0; i < cls[0].layerSize(); ++i) {
          // Find the texel this class slot came from by its position.
          const glm::vec3 p(cls[0].positionWeight[i]);
          const int x = static_cast<int>(std::floor(p.x * 7)), y = static_cast<int>(std::floor(p.y * 5));
          EXPECT_EQ(x % n, cx);
          EXPECT_EQ(y % n, cy);
          ++seen[static_cast<size_t>(y) * 7 + x];
        }
      }
    for (int s : seen) EXPECT_EQ(s, 1) << "n = " << n;
  }
}

// The mix averages the m = n² classes, so every bounce's light survives the split exactly when the
// classes' powers of that bounce sum to m times its power: also for a bounce with fewer VPLs than
// classes (Sponza's deep bounces), whose VPLs then sit one per class.
TEST(InterleavedSampling, ClassSubsetsKeepEveryBouncesPower) {
  VplSet vpls;
  const int counts[] = {32, 3, 1};  // bounce 0: a multiple of m; bounces 1, 2: fewer than m
  for (int b = 0; b < 3; ++b)
    for (int k = 0; k < counts[b]; ++k)
      vpls.vpls.push_back(Vpl{glm::vec3(0.0f), glm::vec3(0, 1, 0), glm::vec3(1.0f + 0.25f * k), b});
  for (int n : {2, 4}) {
    const int m = n * n;
    const std::vector<VplSet> subsets = classVplSubsets(vpls, n);
    ASSERT_EQ(subsets.size(), static_cast<size_t>(m));
    for (int b = 0; b < 3; ++b) {
      double whole = 0.0, classes = 0.0;
      for (const Vpl& v : vpls.vpls) whole += v.bounce == b ? v.power.x : 0.0;
      for (const VplSet& s : subsets)
        for (const Vpl& v : s.vpls) classes += v.bounce == b ? v.power.x : 0.0;
      EXPECT_NEAR(classes / (m * whole), 1.0, 1e-6) << "n = " << n << ", bounce " << b;
    }
  }
}

// Point light over a black floor: no VPL at all, so the interleaved bake is the exact direct light.
TEST(InterleavedSampling, PunctualLightsStayExact) {
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.5f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  const glm::vec3 L(0.3f, -0.2f, 0.7f);
  s.lights.push_back(pointLight(L, 5.0f));
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 32, 32)};
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 256;
  const VplSet vpls = generateVpls(s, rt, w);  // bounce VPLs on the floor: they cannot light it
  VplEvalOptions eval;
  eval.clampBound = deriveClampBound(s, vpls);
  BakeInputs in{s, rt, texels, vpls, eval, {}};
  int calls = 0;
  const auto maps = bakeBackendStage(in, 2, kEmbree, &calls);
  EXPECT_EQ(classVplSubsets(vpls, 2).size(), 4u);
  EXPECT_EQ(calls, 5);  // the point light once, then one call per class
  double worst = 0.0;
  for (size_t i = 0; i < maps[0].size(); ++i) {
    const glm::dvec3 d = glm::dvec3(L) - glm::dvec3(glm::vec3(texels[0].positionWeight[i]));
    const double r2 = glm::dot(d, d), exact = 5.0 * (d.z / std::sqrt(r2)) / (kPi * r2);
    ASSERT_TRUE(maps[0].valid[i]);
    worst = std::max(worst, std::abs(maps[0].texels[i].x / exact - 1.0));
  }
  std::printf("[ figure ] interleaved point over plane: max relative error %.2e\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// Unit square emitter (Le = 1) 0.5 m over a 2 × 2 m black floor: the map is the form factor. With
// 2×2 and 4×4 interleaving each texel sees a quarter / a sixteenth of the 4096 VPLs; after the class
// filter the error against the closed form is 0.24% / 1.0% (full set: 0.05%; the 4×4 tent spans 7
// texels = 22 cm of a curved form factor here), and the mean stays unbiased (0.2%).
TEST(InterleavedSampling, EmitterOverFloorMatchesFormFactor) {
  const float h = 0.5f;
  Scene s;
  const int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  const int floor = addMaterial(s, glm::vec3(0.0f));
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, h), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  addQuad(s, floor, glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 64, 64)};
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 4096;
  const VplSet vpls = generateVpls(s, rt, w);
  BakeInputs in{s, rt, texels, vpls, VplEvalOptions{}, {}};  // no clamp: nothing closer than 0.5 m
  const std::vector<glm::dvec3> poly = {{-0.5, -0.5, h}, {0.5, -0.5, h}, {0.5, 0.5, h}, {-0.5, 0.5, h}};
  for (int n : {1, 2, 4}) {
    const auto maps = bakeBackendStage(in, n, kEmbree);
    double se = 0, ref2 = 0, sum = 0, sumRef = 0;
    for (size_t i = 0; i < maps[0].size(); ++i) {
      const double exact = polygonFormFactor(glm::dvec3(glm::vec3(texels[0].positionWeight[i])), glm::dvec3(0, 0, 1), poly);
      se += std::pow(maps[0].texels[i].x - exact, 2);
      ref2 += exact * exact;
      sum += maps[0].texels[i].x;
      sumRef += exact;
    }
    const double rel = std::sqrt(se / ref2), bias = sum / sumRef - 1.0;
    std::printf("[ figure ] emitter over floor, interleave %d×%d: relative RMSE %.4f, bias %+.4f\n", n, n, rel, bias);
    EXPECT_LT(rel, n < 4 ? 0.005 : 0.015) << "n = " << n;
    EXPECT_LT(std::abs(bias), 0.002) << "n = " << n;
  }
}

}  // namespace
}  // namespace irbake
