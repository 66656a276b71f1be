// The atlas estimate (atlas/atlas_estimate.h) against the real atlas on every sample scene.
#include <gtest/gtest.h>

#include <cstdio>

#include "atlas/atlas.h"
#include "atlas/atlas_estimate.h"
#include "samples/sample_scenes.h"

namespace irbake {
namespace {

double pageTexels(const AtlasResult& r) {
  double texels = 0.0;
  for (const AtlasPage& pg : r.pages) texels += double(pg.width) * pg.height;
  return texels;
}

// At --quality default's rule (16 texels per metre, a small scene at least one 1024² page): the same density, page
// edge and page count; chart texel centres and page texels within ±15%.
TEST(AtlasDensity, EstimateMatchesTheAtlasOnTheSamples) {
  AtlasOptions o;
  o.autoTexelsPerUnit = 16.0;
  for (samples::NamedSample& sample : samples::allSamples()) {
    const AtlasEstimate e = estimateAtlas(sample.scene, o);
    const AtlasResult r = buildAtlas(sample.scene, o);
    const double covered = r.stats.centreUtilisation * pageTexels(r);
    std::printf("%-18s density %8.4g / %8.4g  texels %9.0f / %9.0f  page texels %9.0f / %9.0f  pages %d / %zu\n",
                sample.name.c_str(), e.texelsPerUnit, r.stats.texelsPerUnit, e.texels, covered, e.pageTexels, pageTexels(r),
                e.pages, r.pages.size());
    EXPECT_NEAR(e.texelsPerUnit, r.stats.texelsPerUnit, 1e-6 * r.stats.texelsPerUnit) << sample.name;
    EXPECT_NEAR(e.texels, covered, 0.15 * covered) << sample.name;
    EXPECT_NEAR(e.pageTexels, pageTexels(r), 0.15 * pageTexels(r)) << sample.name;
    EXPECT_EQ(e.pageSize, r.stats.pageSize) << sample.name;
    EXPECT_EQ(size_t(e.pages), r.pages.size()) << sample.name;
  }
}

}  // namespace
}  // namespace irbake
