// The tests' and benchmarks' backend stage (testing/backend_stage.h) against the bake's own (StagedBake): what
// the interleave tests and the speed benchmark measure must be what the command runs.
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "atlas/atlas.h"
#include "evaluators/embree/embree_backend.h"
#include "pipeline/bake.h"
#include "raytrace/ray_tracer.h"
#include "samples/sample_scenes.h"
#include "texels/texel_samples.h"
#include "testing/backend_stage.h"

using namespace irbake;

namespace {

// The corner (a spot light and its bounces) baked by the Embree backend with 1, 2×2 and 3×3 interleave classes,
// one VPL block per class and no stage after the backend's that changes the map (no compensation, shadow-edge
// pass, dilation or seams); then its atlas, texel samples and VPLs through bakeBackendStage: the same maps, bit
// for bit, from the same number of backend calls.
TEST(BackendStage, IsTheBakesBackendStageBitForBit) {
  for (int n : {1, 2, 3}) {
    BakeOptions o;
    o.backend = BackendKind::Embree;
    o.atlas.texelsPerUnit = 10.0f;
    o.walk.paths = 256;
    o.walk.seed = 7;
    o.eval.biasCompensation = false;
    o.shadowEdges.subSamples = 1;
    o.interleave = n;
    o.vplBlock = 1 << 20;
    o.postDilate = o.postSeams = false;
    const BakeResult r = bake(samples::makeCorner(), o);

    Scene scene = samples::makeCorner();
    buildAtlas(scene, o.atlas);
    const RayTracer rt(scene);
    const std::vector<TexelSamples> texels = buildTexelSamples(scene, rt, o.texels);
    VplEvalOptions eval;
    eval.clampBound = r.report["eval"]["clampBound"].get<float>();
    ASSERT_GT(eval.clampBound, 0.0f);
    const BakeInputs in{scene, rt, texels, r.vpls, eval, {}};
    int calls = 0;
    const std::vector<Lightmap> maps =
        irbake::testing::bakeBackendStage(in, n, EmbreeEvaluator(), &calls);

    EXPECT_EQ(calls, r.report["interleave"]["backendCalls"].get<int>()) << "n = " << n;
    EXPECT_EQ(calls, 1 + n * n) << "n = " << n;  // the spot light, then every class has VPLs
    ASSERT_EQ(maps.size(), r.maps.size());
    size_t valid = 0, differing = 0;
    for (size_t p = 0; p < maps.size(); ++p) {
      ASSERT_EQ(maps[p].size(), r.maps[p].size());
      EXPECT_EQ(maps[p].valid, r.maps[p].valid) << "page " << p << ", n = " << n;
      for (size_t t = 0; t < maps[p].size(); ++t) {
        valid += r.maps[p].valid[t] != 0;
        differing += maps[p].texels[t] != r.maps[p].texels[t];
      }
    }
    std::printf("[ figure ] corner, %dx%d classes: %zu valid texels, %zu differ from the bake's\n", n, n, valid,
                differing);
    EXPECT_GT(valid, 1000u);
    EXPECT_EQ(differing, 0u) << "n = " << n;
  }
}

}  // namespace
