#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/exr_io.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
fs::path scratchDir(const std::string& name) {
  fs::path dir = fs::current_path() / "test_scratch" / "exr_io" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
size_t filesIn(const fs::path& dir) {
  size_t n = 0;
  for (auto& e : fs::directory_iterator(dir)) (void)e, ++n;
  return n;
}
Lightmap ramp(int w, int h, int page) {
  Lightmap m;
  m.page = page;
  m.width = w;
  m.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.texels.push_back(glm::vec3(x * 0.25f, y * 1e-3f, 1e4f + x - y * 3.5f));
  m.valid.assign(m.size(), 1);
  return m;
}
}  // namespace

TEST(Exr, RoundTripIsBitExactFloat) {
  fs::path dir = scratchDir("roundtrip");
  Lightmap m = ramp(13, 7, 2);  // odd sizes catch row/column swaps
  writeExr(m, dir / "lightmap_2.exr");
  EXPECT_EQ(filesIn(dir), 1u);  // no temp file left
  Lightmap r = readExr(dir / "lightmap_2.exr");
  EXPECT_EQ(r.width, 13);
  EXPECT_EQ(r.height, 7);
  EXPECT_EQ(r.page, 2);
  ASSERT_EQ(r.texels.size(), m.texels.size());
  for (size_t i = 0; i < m.texels.size(); ++i) EXPECT_EQ(r.texels[i], m.texels[i]) << i;
  EXPECT_EQ(r.valid, std::vector<uint8_t>(m.size(), 1));
}

TEST(Exr, NaNIsRefusedAndNothingIsWritten) {
  fs::path dir = scratchDir("nan");
  Lightmap m = ramp(4, 4, 0);
  m.texels[5].z = std::nanf("");
  try {
    writeExr(m, dir / "bad.exr");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NumericError);
  }
  EXPECT_EQ(filesIn(dir), 0u);
}

TEST(Exr, UnwritableAndMissingPathsAreIoErrors) {
  fs::path dir = scratchDir("io");
  { std::ofstream(dir / "plainfile") << "x"; }
  try {
    writeExr(ramp(2, 2, 0), dir / "plainfile" / "sub" / "a.exr");  // a file where a folder should be
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_NE(std::string(e.what()).find("a.exr"), std::string::npos);
  }
  try {
    readExr(dir / "missing.exr");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
  }
  { std::ofstream(dir / "garbage.exr") << "not an image"; }
  EXPECT_THROW(readExr(dir / "garbage.exr"), Error);
  EXPECT_EQ(filesIn(dir), 2u);
}
