// Closed forms of the transport maths both VPL backends evaluate (geometry_term.h).
#include "transport/geometry_term.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/maths.h"
#include "testing/scenes.h"

namespace irbake {
namespace {
using namespace irbake::testing;

TEST(GeometryTerm, ClosedFormsAndClamp) {
  // Receiver at origin facing +z, VPL at (0,0,2) facing down: G = 1/4.
  EXPECT_FLOAT_EQ(vplGeometryTerm(glm::vec3(0), glm::vec3(0, 0, 1), glm::vec3(0, 0, 2), glm::vec3(0, 0, -1)), 0.25f);
  // 45° offsets: cos = 1/√2 both, r² = 2 → G = 1/4.
  EXPECT_NEAR(vplGeometryTerm(glm::vec3(0), glm::vec3(0, 0, 1), glm::vec3(1, 0, 1), glm::vec3(0, 0, -1)), 0.25f, 1e-6f);
  // Facing away on either end: 0.
  EXPECT_EQ(vplGeometryTerm(glm::vec3(0), glm::vec3(0, 0, -1), glm::vec3(0, 0, 2), glm::vec3(0, 0, -1)), 0.0f);
  EXPECT_EQ(vplGeometryTerm(glm::vec3(0), glm::vec3(0, 0, 1), glm::vec3(0, 0, 2), glm::vec3(0, 0, 1)), 0.0f);
  EXPECT_EQ(clampGeometryTerm(5.0f, 2.0f), 2.0f);
  EXPECT_EQ(clampGeometryTerm(5.0f, 0.0f), 5.0f);
  EXPECT_NEAR(vplMapValue(glm::vec3(kPi * kPi), 0.5f).x, 0.5f, 1e-6f);
  // Clamp bound: π N / (k A) for a 2×3 plane and 10 VPLs.
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.5f)), glm::vec3(0), glm::vec3(2, 0, 0), glm::vec3(0, 3, 0));
  VplSet v;
  v.vpls.resize(10, Vpl{glm::vec3(0), glm::vec3(0, 0, 1), glm::vec3(1.0f), 1});
  v.vpls.push_back(Vpl{});  // zero power: not counted
  EXPECT_NEAR(deriveClampBound(s, v), kPi * 10 / (kClampVplsPerMean * 6.0), 1e-5);
  // Spot light: full inside the inner cone, zero outside the outer cone, squared linear ramp between.
  Light spot;
  spot.type = LightType::Spot;
  spot.position = glm::vec3(0, 0, 1);
  spot.intensity = 3.0f;
  spot.innerConeAngle = 0.2f;
  spot.outerConeAngle = 0.4f;
  PunctualContribution c = punctualDirect(spot, glm::vec3(0), glm::vec3(0, 0, 1));
  EXPECT_NEAR(c.mapValue.x, 3.0 / kPi, 1e-6);
  EXPECT_NEAR(c.distance, 1.0f, 1e-6f);
  EXPECT_EQ(punctualDirect(spot, glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)).mapValue.x, 0.0f);  // 45° > outer
  float midCos = 0.5f * (std::cos(0.2f) + std::cos(0.4f));
  glm::vec3 mid(std::sqrt(1 - midCos * midCos) / midCos, 0, 0);
  double r2 = 1.0 / (midCos * midCos);
  EXPECT_NEAR(punctualDirect(spot, mid, glm::vec3(0, 0, 1)).mapValue.x, 3.0 * 0.25 * midCos / r2 / kPi, 1e-5);
  const Light sun = directionalLight(glm::vec3(1, 0, -1), 2.0f);
  EXPECT_NEAR(punctualDirect(sun, glm::vec3(5), glm::vec3(0, 0, 1)).mapValue.x, 2.0 / std::sqrt(2.0) / kPi, 1e-6);
}

}  // namespace
}  // namespace irbake
