// The probe grid view (--view probes) and a probe object on a hand-made grid with closed-form values, no bake:
// two probes 1 m apart along x, probe 0 valid with a known SH, probe 1 invalid (drawn red, left out of the blend).
#include <gtest/gtest.h>

#include "common/error.h"
#include "glcontext/gl_context.h"
#include "probe_view.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

LightProbeGrid twoProbes() {
  LightProbeGrid g;
  g.origin = glm::vec3(0.0f);
  g.spacing = 1.0f;
  g.counts = glm::ivec3(2, 1, 1);
  g.coefficients.assign(2, ShCoefficients{});
  g.coefficients[0][0] = glm::vec3(0.5f, 0.4f, 0.3f);  // L0
  g.coefficients[0][2] = glm::vec3(0.2f, 0.1f, 0.0f);  // L1 along z
  g.coefficients[1][0] = glm::vec3(9.0f);              // invalid: must never show
  g.offsets.assign(2, glm::vec3(0.0f));
  g.valid = {1, 0};
  return g;
}

TEST(ProbeGridView, ValidProbesShowTheirShInvalidOnesRed) {
  const LightProbeGrid grid = twoProbes();
  const std::vector<ProbeSphere> spheres = probeGridSpheres(grid);
  ASSERT_EQ(spheres.size(), 2u);
  EXPECT_FLOAT_EQ(spheres[0].radius, 0.12f);
  EXPECT_TRUE(spheres[0].valid);
  EXPECT_FALSE(spheres[1].valid);

  GlContext gl;
  ViewerScene v = makeViewerScene(Scene{}, {});
  ViewRenderer renderer(v);
  addProbeOverlay(renderer, spheres);
  // From +z, looking at the middle of the two probes: the middle pixel of each sphere faces the camera, n ≈ +z.
  const glm::vec3 eye(0.5f, 0.0f, 3.0f);
  const ViewCamera camera = lookAt(eye, glm::vec3(0.5f, 0.0f, 0.0f), 30.0f, Bounds3{glm::vec3(-1.0f), glm::vec3(2.0f)});
  const int w = 201, h = 101;
  const RgbaImage img = renderer.render(camera, w, h, {});
  auto pixelOf = [&](const glm::vec3& p) {
    const glm::vec4 c = camera.projection(static_cast<float>(w) / h) * camera.view() * glm::vec4(p, 1.0f);
    return glm::ivec2(static_cast<int>((c.x / c.w * 0.5f + 0.5f) * w), static_cast<int>((0.5f - c.y / c.w * 0.5f) * h));
  };
  const glm::ivec2 p0 = pixelOf(glm::vec3(0.0f)), p1 = pixelOf(glm::vec3(1.0f, 0.0f, 0.0f));
  // The normal there points to the eye: (p0 − centre) ∥ (eye − centre), within the pixel's 0.5/201 of the view.
  const glm::vec3 n0 = glm::normalize(eye - glm::vec3(0.0f));
  const glm::vec3 expected = shIrradiance(grid.coefficients[0], n0);  // 0.886 L0 + 1.023 L1 n_z
  const glm::vec4 got = img.at(p0.x, p0.y);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expected[k], 0.01f * expected.x) << "channel " << k;
  EXPECT_EQ(img.at(p1.x, p1.y), glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  EXPECT_EQ(img.at(w / 2, 2), glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));  // background between and above them
}

// A probe object between them takes probe 0 alone (weights renormalised over the valid probes); one with no valid
// probe near is refused naming the file.
TEST(ProbeGridView, ProbeObjectBlendsValidProbesOnly) {
  LightProbeGrid grid = twoProbes();
  const ProbeSphere s = probeObject(grid, glm::vec3(0.7f, 0.0f, 0.0f), 0.2f, "grid.gltf");
  for (int k = 0; k < kShCoefficients; ++k) EXPECT_EQ(s.coefficients[k], grid.coefficients[0][k]);
  // Its ends at ± R blend probe 0 alone too, so the field over it is flat.
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < kShCoefficients; ++k) EXPECT_EQ(s.gradient[a][k], glm::vec3(0.0f)) << a << " " << k;
  EXPECT_FLOAT_EQ(s.radius, 0.2f);
  grid.valid = {0, 0};
  try {
    probeObject(grid, glm::vec3(0.7f, 0.0f, 0.0f), 0.2f, "grid.gltf");
    FAIL() << "a point without valid probes was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("grid.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no valid probe"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace irbake::view
