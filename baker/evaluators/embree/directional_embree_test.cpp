// Directional maps from the Embree evaluator (EvaluationRequest::directional) against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "evaluators/embree/embree_backend.h"
#include "common/maths.h"
#include "transport/directional.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

glm::vec3 tilted(float degrees, float azimuth) {
  const float a = glm::radians(degrees), b = glm::radians(azimuth);
  return {std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)};
}

L1Vectors texelL1(const L1Pages& axes, size_t page, size_t t) {
  return {axes[0][page].texels[t], axes[1][page].texels[t], axes[2][page].texels[t]};
}

// The maps and their L1 pages from one pass; the maps must be the bits of a pass without L1.
std::vector<Lightmap> bakeWithL1(const BakeInputs& in, L1Pages& axes) {
  EvaluationRequest request;
  request.directional = &axes;
  std::vector<Lightmap> maps = EmbreeEvaluator().evaluate(in, request);
  const std::vector<Lightmap> plain = bakeEmbree(in);
  EXPECT_EQ(maps.size(), plain.size());
  for (size_t p = 0; p < maps.size() && p < plain.size(); ++p) {
    EXPECT_EQ(maps[p].valid, plain[p].valid);
    EXPECT_EQ(std::memcmp(maps[p].texels.data(), plain[p].texels.data(), maps[p].size() * sizeof(glm::vec3)), 0) << p;
    for (const auto& axis : axes) EXPECT_EQ(axis[p].valid, plain[p].valid);
  }
  return maps;
}

}  // namespace

// Point light over a black plane: for normals tilted up to 85° in every direction the reconstruction is
// I max(0, n·ω) / (π r²) (one source: exact up to float rounding); L0 is the plain map, bit for bit.
TEST(EmbreeDirectional, PointLightOverPlaneTiltedNormals) {
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  const glm::vec3 L(0.3f, -0.2f, 0.7f);
  s.lights.push_back(pointLight(L, 5.0f));
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 16, 16)};
  RayTracer rt(s);
  VplSet vpls;
  BakeInputs in{s, rt, texels, vpls, VplEvalOptions{}, {}};
  L1Pages axes;
  const std::vector<Lightmap> maps = bakeWithL1(in, axes);
  double worst = 0.0;
  for (size_t t = 0; t < maps[0].size(); ++t) {
    ASSERT_TRUE(axes[0][0].valid[t] && axes[1][0].valid[t] && axes[2][0].valid[t]);
    EXPECT_EQ(axes[2][0].texels[t], glm::vec3(0.0f));  // nothing along the normal (+z)
    const glm::dvec3 d = glm::dvec3(L) - glm::dvec3(glm::vec3(texels[0].positionWeight[t]));
    const double r2 = glm::dot(d, d);
    const glm::dvec3 w = d / std::sqrt(r2);
    for (float tilt : {0.0f, 20.0f, 45.0f, 70.0f, 85.0f})
      for (float az : {0.0f, 60.0f, 150.0f, 270.0f}) {
        const glm::vec3 n = tilted(tilt, az);
        const double exact = 5.0 * std::max(0.0, glm::dot(glm::dvec3(n), w)) / (kPi * r2);
        const double rec = reconstructDirectional(maps[0].texels[t], texelL1(axes, 0, t), glm::vec3(0, 0, 1), n).x;
        worst = std::max(worst, std::abs(rec - exact) / (5.0 / (kPi * r2)));
      }
  }
  std::printf("[ figure ] point over plane, tilted normals: max error %.2e of I/(πr²)\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// A square emitter (Le = 1) 0.5 m over a black floor, through 4096 unclamped VPLs: the tangential part
// against the polygon's irradiance vector (Lambert: ½ Σ edge angle · edge-plane normal), RMSE < 2% of its
// largest magnitude; L0 unchanged.
TEST(EmbreeDirectional, QuadEmitterIrradianceVector) {
  const float h = 0.5f;
  Scene s;
  int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, h), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 12, 12)};
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 4096;
  VplSet vpls = generateVpls(s, rt, w);
  BakeInputs in{s, rt, texels, vpls, VplEvalOptions{}, {}};
  L1Pages axes;
  bakeWithL1(in, axes);
  const std::vector<glm::dvec3> poly = {{-0.5, -0.5, h}, {0.5, -0.5, h}, {0.5, 0.5, h}, {-0.5, 0.5, h}};
  double se = 0.0, largest = 0.0;
  for (size_t t = 0; t < axes[0][0].size(); ++t) {
    const glm::dvec3 x(glm::vec3(texels[0].positionWeight[t]));
    const glm::dvec3 v = polygonIrradianceVector(x, poly);  // Le = 1: g / π, towards the emitter
    const L1Vectors tv = texelL1(axes, 0, t);
    const glm::dvec3 got(tv[0].x, tv[1].x, tv[2].x);
    EXPECT_NEAR(got.z, 0.0, 1e-6);
    const glm::dvec3 d = got - glm::dvec3(v.x, v.y, 0.0);
    se += glm::dot(d, d);
    largest = std::max(largest, glm::length(glm::dvec2(v.x, v.y)));
  }
  const double rmse = std::sqrt(se / axes[0][0].size()) / largest;
  std::printf("[ figure ] quad emitter: tangential irradiance vector RMSE %.3e of its largest\n", rmse);
  EXPECT_LT(rmse, 0.02);
  EXPECT_GT(largest, 0.05);
}
