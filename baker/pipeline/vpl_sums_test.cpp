// The exact VPL sum: any order and grouping of the blocks gives the same bits; files round-trip and a
// damaged one is refused by name.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "common/error.h"
#include "pipeline/vpl_sum_file.h"
#include "pipeline/vpl_sums.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
// Values spanning 12 decades, as block sums of a map do (bright near a light, dim in a corner).
std::vector<glm::vec3> blockValues(size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> exponent(-8.0f, 4.0f);
  std::vector<glm::vec3> v(count);
  for (auto& x : v) x = glm::vec3(std::pow(10.0f, exponent(rng)), std::pow(10.0f, exponent(rng)), std::pow(10.0f, exponent(rng)));
  return v;
}

bool sameBits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST(ExactVplSums, AnyOrderAndSplitGivesTheSameBitsAndTheDoubleSum) {
  const std::vector<glm::vec3> values = blockValues(1000, 7);
  ExactVplSums forward = ExactVplSums::zeros({{1}});
  for (const auto& v : values) ASSERT_TRUE(forward.add(0, 0, v));
  // Backwards, and as three "shards" summed separately then added in another order.
  ExactVplSums backward = ExactVplSums::zeros({{1}});
  for (auto it = values.rbegin(); it != values.rend(); ++it) ASSERT_TRUE(backward.add(0, 0, *it));
  std::vector<ExactVplSums> shards(3, ExactVplSums::zeros({{1}}));
  for (size_t i = 0; i < values.size(); ++i) ASSERT_TRUE(shards[i * 3 / values.size()].add(0, 0, values[i]));
  ExactVplSums merged = ExactVplSums::zeros({{1}});
  for (int s : {2, 0, 1}) merged.add(shards[s]);
  EXPECT_TRUE(sameBits(forward.value(0, 0), backward.value(0, 0)));
  EXPECT_TRUE(sameBits(forward.value(0, 0), merged.value(0, 0)));
  // A float sum in those two orders differs in the last bits (why the exact sum exists) ...
  glm::vec3 floatForward(0.0f), floatBackward(0.0f);
  for (const auto& v : values) floatForward += v;
  for (auto it = values.rbegin(); it != values.rend(); ++it) floatBackward += *it;
  EXPECT_FALSE(sameBits(floatForward, floatBackward));
  // ... and the exact sum is the double sum rounded to float (relative 2⁻²⁴ at most).
  glm::dvec3 reference(0.0);
  for (const auto& v : values) reference += glm::dvec3(v);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(forward.value(0, 0)[c], reference[c], reference[c] * 6e-8) << c;
  EXPECT_EQ(forward.pages[0].valid[0], 1);
}

TEST(ExactVplSums, RefusesValuesItCannotAddExactly) {
  ExactVplSums sums = ExactVplSums::zeros({{1, 1}});
  EXPECT_FALSE(sums.add(0, 0, glm::vec3(NAN, 0.0f, 0.0f)));
  EXPECT_FALSE(sums.add(0, 0, glm::vec3(0.0f, INFINITY, 0.0f)));
  EXPECT_FALSE(sums.add(0, 1, glm::vec3(0.0f, 0.0f, 2e12f)));  // ≥ 2⁴⁰
  EXPECT_EQ(sums.pages[0].valid[0], 0);
  EXPECT_TRUE(sums.add(0, 1, glm::vec3(1e12f)));
  EXPECT_FLOAT_EQ(sums.value(0, 1).x, 1e12f);
  EXPECT_EQ(sums.value(0, 0), glm::vec3(0.0f));  // untouched texel
  EXPECT_THROW(sums.add(ExactVplSums::zeros({{1, 1, 1}})), std::invalid_argument);
  ExactVplSums someReceive = ExactVplSums::zeros({{1, 0}});
  EXPECT_FALSE(someReceive.add(0, 1, glm::vec3(1.0f)));  // not a receiver: no sums there
  EXPECT_EQ(someReceive.pages[0].rgb.size(), 3u);
}

TEST(VplSumFile, RoundTripsAndRefusesDamage) {
  const fs::path dir = fs::current_path() / "test_scratch" / "vpl_sum_file";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ExactVplSums sums = ExactVplSums::zeros({{0, 1, 1, 0, 1}, {1, 1, 0}});
  const std::vector<glm::vec3> values = blockValues(4, 3);
  sums.add(0, 1, values[0]);
  sums.add(0, 4, values[1]);
  sums.add(1, 0, values[2]);
  sums.add(1, 0, values[3]);
  VplSumHeader h;
  h.kind = "partial";
  h.sceneHash = "0123456789abcdef";
  h.optionsHash = hashText("vpls=64\n");
  h.seed = 9;
  h.backend = "embree";
  h.blockCount = 10;
  h.firstBlock = 3;
  h.endBlock = 6;
  h.shardIndex = 2;
  h.shardCount = 3;
  h.command = {{"args", {"a.gltf", "--vpls", "64"}}};
  h.backendCounts = {{"passes", 4}};
  const fs::path file = dir / "p.vplsum";
  writeVplSumFile(file, h, sums);
  const VplSumFile back = readVplSumFile(file);
  EXPECT_EQ(back.header.mismatch(h), "");
  EXPECT_EQ(back.header.firstBlock, 3u);
  EXPECT_EQ(back.header.endBlock, 6u);
  EXPECT_EQ(back.header.shardIndex, 2);
  EXPECT_EQ(back.header.command, h.command);
  ASSERT_TRUE(back.sums.sameLayout(sums));
  for (size_t p = 0; p < 2; ++p) {
    EXPECT_EQ(back.sums.pages[p].valid, sums.pages[p].valid);
    EXPECT_EQ(back.sums.pages[p].slot, sums.pages[p].slot);
    EXPECT_TRUE(back.sums.pages[p].rgb == sums.pages[p].rgb);
  }
  VplSumHeader other = h;
  other.seed = 10;
  EXPECT_EQ(back.header.mismatch(other), "seed");
  other = h;
  other.sceneHash = "fedcba9876543210";
  EXPECT_EQ(back.header.mismatch(other), "scene");

  // Truncated (a copy cut short) and not ours: Parse errors naming the file.
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path cut = dir / "cut.vplsum";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() - 20);
  const fs::path notOurs = dir / "not_ours.vplsum";
  std::ofstream(notOurs) << "{\"hello\": 1}";
  for (const fs::path& bad : {cut, notOurs}) {
    try {
      readVplSumFile(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Parse);
      EXPECT_NE(std::string(e.what()).find(bad.filename().string()), std::string::npos) << e.what();
    }
  }
}
