// The ray pilot: its scale, its rays' hits in scenes where every ray hits or none does, and its reference scene.
#include "pipeline/ray_pilot.h"

#include <gtest/gtest.h>

#include "testing/scenes.h"

namespace irbake {
namespace {

TEST(RayPilot, ScaleIsTheSecondsPerRayOverTheReferences) {
  EXPECT_DOUBLE_EQ(rayCostScale(2e-6, 1e-6), 2.0);  // a scene twice as costly per ray
  EXPECT_DOUBLE_EQ(rayCostScale(0.5e-6, 2e-6), 0.25);
  EXPECT_DOUBLE_EQ(rayCostScale(0.0, 1e-6), 1.0);  // nothing measured: the calibration's rays
  EXPECT_DOUBLE_EQ(rayCostScale(1e-6, 0.0), 1.0);
}

TEST(RayPilot, EveryRayHitsInsideABoxAndNoneAboveAPlane) {
  RayPilotOptions o;
  o.points = 64;
  o.raysPerPoint = 16;
  o.rounds = 1;
  Scene box;
  testing::addBox(box, testing::addMaterial(box, glm::vec3(0.5f)), glm::vec3(-1), glm::vec3(1), true, 2);
  const RayPilot inside = measureRayPilot(box, RayTracer(box), o);
  EXPECT_EQ(inside.rays, 64 * 16);
  EXPECT_DOUBLE_EQ(inside.hitFraction, 1.0);
  EXPECT_GT(inside.secondsPerRay, 0.0);
  EXPECT_GT(inside.referenceSecondsPerRay, 0.0);
  Scene plane;  // facing up: the cosine rays leave into the empty half-space
  testing::addQuad(plane, testing::addMaterial(plane, glm::vec3(0.5f)), glm::vec3(-5, 0, -5), glm::vec3(0, 0, 10),
                   glm::vec3(10, 0, 0), 4);
  EXPECT_DOUBLE_EQ(measureRayPilot(plane, RayTracer(plane), o).hitFraction, 0.0);
  Scene unmapped = box;  // no mapped surface to start from: the calibration's cost per ray
  for (Primitive& p : unmapped.primitives) p.mode = ObjectMode::ShadowOnly;
  const RayPilot none = measureRayPilot(unmapped, RayTracer(unmapped), o);
  EXPECT_DOUBLE_EQ(none.rayCost, 1.0);
  EXPECT_EQ(none.rays, 0);
}

TEST(RayPilot, ReferenceSceneIsABlockOfHousesOnAGround) {
  const Scene s = rayPilotReferenceScene();
  EXPECT_EQ(s.triangleCount(), 2u + 64u * 6u * 16u * 2u);
  const Bounds3 b = s.bounds();
  EXPECT_FLOAT_EQ(b.min.y, 0.0f);
  EXPECT_FLOAT_EQ(b.max.y, 16.0f);
  EXPECT_FLOAT_EQ(b.max.x - b.min.x, 40.0f);
}

}  // namespace
}  // namespace irbake
