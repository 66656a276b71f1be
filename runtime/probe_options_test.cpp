// irview's probe options: --probe-object X,Y,Z[,R] (repeatable, R default 0.1 m) and --view probes.
#include <gtest/gtest.h>

#include "common/error.h"
#include "viewer_options.h"

namespace irbake::view {
namespace {

TEST(ProbeOptions, ProbeObjectsParseWithTheirRadius) {
  const auto o = parseViewerOptions({"--probe-object", "1,2,3", "s.gltf", "--probe-object", "-0.5,0.25,4,0.3"});
  ASSERT_TRUE(o);
  ASSERT_EQ(o->probeObjects.size(), 2u);
  EXPECT_EQ(o->probeObjects[0], glm::vec4(1, 2, 3, 0.1f));
  EXPECT_EQ(o->probeObjects[1], glm::vec4(-0.5f, 0.25f, 4, 0.3f));
  EXPECT_EQ(o->scene, "s.gltf");  // the scene after the option is not taken as a second value
  EXPECT_FALSE(o->showProbes);
}

TEST(ProbeOptions, ViewProbesIsTheLitViewWithTheGrid) {
  const auto o = parseViewerOptions({"s.gltf", "--view", "probes"});
  ASSERT_TRUE(o);
  EXPECT_TRUE(o->showProbes);
  EXPECT_EQ(o->mode, ViewMode::Lit);
}

TEST(ProbeOptions, BadProbeObjectsAreRefused) {
  for (const char* bad : {"1,2", "1,2,3,4,5", "1,x,3", "1,2,3,0", "1,2,3,-1", "nan,0,0", "1,,3"})
    EXPECT_THROW(parseViewerOptions({"s.gltf", "--probe-object", bad}), Error) << bad;
}

}  // namespace
}  // namespace irbake::view
