#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/exr_io.h"
#include "imageio/image_io.h"
#include "pipeline/diff.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
Lightmap constant(int w, int h, glm::vec3 v, int page = 0) {
  Lightmap m;
  m.page = page;
  m.width = w;
  m.height = h;
  m.texels.assign(m.size(), v);
  m.valid.assign(m.size(), 1);
  return m;
}
}  // namespace

TEST(Diff, ConstantOffsetGivesExactFigures) {
  // A = 1.1, B = 1.0 everywhere: RMSE 0.1, relative 0.1, bias +0.1 (10%), max 0.1.
  std::vector<Lightmap> a{constant(4, 4, glm::vec3(1.1f))}, b{constant(4, 4, glm::vec3(1.0f))};
  MapDifference d = compareMaps(a, b);
  EXPECT_EQ(d.texels, 16u);
  EXPECT_NEAR(d.rmse, 0.1, 1e-6);
  EXPECT_NEAR(d.relativeRmse, 0.1, 1e-6);
  EXPECT_NEAR(d.meanBias, 0.1, 1e-6);
  EXPECT_NEAR(d.relativeBias, 0.1, 1e-6);
  EXPECT_NEAR(d.maxError, 0.1, 1e-6);
}

TEST(Diff, AreaWeightsAndValidityCount) {
  // Two texels: errors 1 (weight 3) and 0 (weight 1) → RMSE sqrt(3/4); an invalid texel is ignored.
  std::vector<Lightmap> a{constant(3, 1, glm::vec3(2.0f))}, b{constant(3, 1, glm::vec3(2.0f))};
  a[0].texels[0] = glm::vec3(3.0f);
  a[0].texels[2] = glm::vec3(100.0f);
  std::vector<std::vector<float>> w{{3.0f, 1.0f, 0.0f}};
  MapDifference d = compareMaps(a, b, w);
  EXPECT_EQ(d.texels, 2u);
  EXPECT_NEAR(d.rmse, std::sqrt(0.75), 1e-9);
  EXPECT_NEAR(d.relativeRmse, std::sqrt(0.75) / 2.0, 1e-9);
  EXPECT_NEAR(d.meanBias, 0.75, 1e-9);
  EXPECT_NEAR(d.maxError, 1.0, 1e-9);
  a[0].valid[2] = 0;  // unweighted: the valid flags decide
  EXPECT_EQ(compareMaps(a, b).texels, 2u);
}

TEST(Diff, DifferentAtlasesAreRefused) {
  std::vector<Lightmap> a{constant(4, 4, glm::vec3(1.0f))}, b{constant(4, 8, glm::vec3(1.0f))};
  EXPECT_THROW(compareMaps(a, b), Error);
  std::vector<Lightmap> two{constant(4, 4, glm::vec3(1.0f)), constant(4, 4, glm::vec3(1.0f))};
  EXPECT_THROW(compareMaps(a, two), Error);
}

TEST(Diff, ReadsBakeFoldersAndSingleExrs) {
  fs::path dir = fs::current_path() / "test_scratch" / "diff" / "bakeA";
  fs::remove_all(dir);
  fs::create_directories(dir);
  writeExr(constant(2, 2, glm::vec3(0.5f), 0), dir / "lightmap_0.exr");
  writeExr(constant(4, 2, glm::vec3(0.25f), 1), dir / "lightmap_1.exr");
  BakeOnDisk bake = readBakeFromDisk(dir);
  ASSERT_EQ(bake.pages.size(), 2u);
  EXPECT_EQ(bake.pages[1].width, 4);
  EXPECT_EQ(bake.pages[1].texels[3], glm::vec3(0.25f));
  EXPECT_TRUE(bake.areas.empty());  // no glTF beside the pages
  EXPECT_EQ(readBakeFromDisk(dir / "lightmap_1.exr").pages.size(), 1u);
  fs::remove(dir / "lightmap_0.exr");
  EXPECT_THROW(readBakeFromDisk(dir), Error);  // page 0 missing
  EXPECT_THROW(readBakeFromDisk(dir / "nothing"), Error);
}

// An all-NaN page would score relativeRmse 0 (NaN compares false everywhere): it is refused, naming it.
TEST(Diff, RefusesPagesWithNaNOrInf) {
  fs::path dir = fs::current_path() / "test_scratch" / "diff" / "nan";
  fs::remove_all(dir);
  fs::create_directories(dir);
  writeExr(constant(2, 2, glm::vec3(0.5f), 0), dir / "good.exr");
  for (float bad : {NAN, INFINITY}) {
    imageio::Pixels px;
    px.width = 2;
    px.height = 2;
    px.channels = 3;
    px.f32.assign(12, 0.5f);
    px.f32[4] = bad;
    imageio::api().writeFile((dir / "bad.exr").string(), "openexr", px, 0, "bad.exr");
    try {
      readBakeFromDisk(dir / "bad.exr");
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidData);
      EXPECT_NE(std::string(e.what()).find("bad.exr"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("1 of 4 texels are NaN or Inf"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(readBakeFromDisk(dir / "good.exr").pages.size(), 1u);
}
