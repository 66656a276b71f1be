// The bake plan settles each automatic option and cross-stage rule once, with a reason.
#include "pipeline/bake_plan.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "samples/sample_scenes.h"

namespace irbake {
namespace {

using samples::makeCornellBox;
using samples::makeCorner;

GlProbe softwareGl() { return GlProbe{"", true}; }
GlProbe hardwareGl() { return GlProbe{"", false}; }
GlProbe noGl() { return GlProbe{"no EGL display", true}; }

BakeOptions autoOptions() {
  BakeOptions o;
  o.finalGather = FinalGatherMode::Auto;
  o.finalGatherPaths = 3072;  // paths left to the preset
  o.walk.paths = 4096;
  return o;
}

TEST(BakePlan, FinalGatherAutoFollowsEmittersAndEveryChoiceHasAReason) {
  const Scene emissive = makeCornellBox();  // its light is an emissive quad
  const RayTracer rtEmissive(emissive);
  const BakePlan withEmitter = planBake(emissive, rtEmissive, autoOptions(), softwareGl);
  EXPECT_FALSE(withEmitter.finalGather);
  EXPECT_EQ(withEmitter.walk.paths, 2048);  // half the preset's paths evaluated: the walk follows 8x as many
  EXPECT_EQ(withEmitter.walk.walkFactor, 8);
  EXPECT_EQ(withEmitter.walk.evaluatedEmitterShare, 0.5);  // the emitter's VPLs: half of those paths
  EXPECT_EQ(withEmitter.compensation.refineRays, autoOptions().compensation.refineRays);
  EXPECT_EQ(withEmitter.backend, BackendKind::Gl);  // 32 triangles, no see-through material
  EXPECT_EQ(withEmitter.walk.minAutoSplit, 4);  // the VPL sum is the map's bounced light: deep bounces fork

  const Scene lamp = makeCorner();  // a spot light, no emitter
  const RayTracer rtLamp(lamp);
  const BakePlan gathered = planBake(lamp, rtLamp, autoOptions(), softwareGl);
  EXPECT_TRUE(gathered.finalGather);
  EXPECT_EQ(gathered.walk.paths, 3072);         // the preset's paths under the gather
  EXPECT_EQ(gathered.walk.minAutoSplit, 1);     // the gather reads their map averaged: the walk's own split rule
  EXPECT_EQ(gathered.walk.walkFactor, 1);       // and every VPL walked is evaluated
  EXPECT_EQ(gathered.walk.evaluatedEmitterShare, 1.0);
  EXPECT_EQ(gathered.compensation.refineRays, 0);  // the gather replaces the residual at the texel
  EXPECT_LE(gathered.compensation.minRays, 2);
  EXPECT_FALSE(gathered.compensation.filterEachSweep);
  ASSERT_TRUE(gathered.choices.count("comp-refine"));

  const nlohmann::json j = gathered.toJson();
  for (const char* key : {"backend", "final-gather", "paths"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_FALSE(j[key]["reason"].get<std::string>().empty()) << key;
    EXPECT_TRUE(j[key]["automatic"].get<bool>()) << key;
  }
  EXPECT_EQ(j["final-gather"]["value"], "on");
}

// The compensated clamp's k: 256 near small emitters (the gathers' rays would meet them by chance), 1024 where
// there is none, or where emitters cover the surface (the final gather's rule), each with its reason.
TEST(BakePlan, TheTightClampWhereNoSmallEmitterIsNear) {
  struct Case {
    const char* name;
    Scene scene;
    double k;
  };
  for (Case& c : std::vector<Case>{{"cornell", makeCornellBox(), 256.0},
                                   {"furnace", samples::makeFurnace(0.9f, 0.1f), 1024.0},
                                   {"corner", makeCorner(), 1024.0}}) {
    const RayTracer rt(c.scene);
    BakePlan plan = planBake(c.scene, rt, autoOptions(), softwareGl);
    settleClamp(plan, autoOptions(), c.scene, 0.0);
    EXPECT_EQ(plan.clampK, c.k) << c.name;
    const nlohmann::json j = plan.toJson();
    ASSERT_TRUE(j.contains("clamp-k")) << c.name;
    EXPECT_TRUE(j["clamp-k"]["automatic"].get<bool>()) << c.name;
    EXPECT_FALSE(j["clamp-k"]["reason"].get<std::string>().empty()) << c.name;
  }
}

TEST(BakePlan, AskedForChoicesAreNotAutomatic) {
  const Scene lamp = makeCorner();
  const RayTracer rt(lamp);
  BakeOptions o = autoOptions();
  o.backend = BackendKind::Embree;
  o.finalGather = FinalGatherMode::Off;
  o.finalGatherPaths.reset();  // --paths given
  const BakePlan plan = planBake(lamp, rt, o, noGl);
  EXPECT_EQ(plan.backend, BackendKind::Embree);
  EXPECT_FALSE(plan.finalGather);
  EXPECT_EQ(plan.walk.paths, 4096);
  EXPECT_EQ(plan.walk.walkFactor, 1);  // a spot light's VPLs outweigh an emitter's: the walk is evaluated whole
  for (const char* key : {"backend", "final-gather", "paths"}) EXPECT_FALSE(plan.choices.at(key).automatic) << key;
  const Scene box = makeCornellBox();  // emitters only, no gather: the paths asked for are evaluated, 8x as many walked
  const RayTracer boxRt(box);
  EXPECT_EQ(planBake(box, boxRt, o, noGl).walk.walkFactor, 8);
  EXPECT_EQ(planBake(box, boxRt, o, noGl).walk.paths, 4096);
  o.walk.split = 1;  // --walk-split 1: Keller's walk, every VPL evaluated
  EXPECT_EQ(planBake(box, boxRt, o, noGl).walk.walkFactor, 1);
}

TEST(BakePlan, CompensationOverlapsOnlyOnHardwareGl) {
  const Scene box = makeCornellBox();
  const RayTracer rt(box);
  BakeOptions o = autoOptions();
  o.backend = BackendKind::Gl;
  EXPECT_FALSE(planBake(box, rt, o, softwareGl).overlapCompensation);
  EXPECT_TRUE(planBake(box, rt, o, hardwareGl).overlapCompensation);
  o.overlapCompensation = OverlapCompensation::Never;
  EXPECT_FALSE(planBake(box, rt, o, hardwareGl).overlapCompensation);
  o.backend = BackendKind::Auto;  // no GL context: Embree, nothing to overlap
  const BakePlan fallback = planBake(box, rt, o, noGl);
  EXPECT_EQ(fallback.backend, BackendKind::Embree);
  EXPECT_FALSE(fallback.overlapCompensation);
}

TEST(BakePlan, AUniformSkyUnderTheGatherIsCountedByItsRays) {
  Scene lamp = makeCorner();
  lamp.environment = Environment::uniform(glm::vec3(0.4f, 0.5f, 0.7f));
  const RayTracer rt(lamp);
  BakeOptions o = autoOptions();
  o.sky.minRays = 8;
  const BakePlan plan = planBake(lamp, rt, o, softwareGl);
  ASSERT_TRUE(plan.finalGather);
  EXPECT_TRUE(plan.skyByGather);
  EXPECT_EQ(plan.sky.minRays, 4);
  EXPECT_EQ(plan.gather.missRadiance, glm::vec3(0.4f, 0.5f, 0.7f));
  o.finalGather = FinalGatherMode::Off;
  const BakePlan plain = planBake(lamp, rt, o, softwareGl);
  EXPECT_FALSE(plain.skyByGather);
  EXPECT_EQ(plain.sky.minRays, 8);
}

}  // namespace
}  // namespace irbake
