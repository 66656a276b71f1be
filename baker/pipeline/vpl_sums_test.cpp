// The exact VPL sum: any order and grouping of the blocks gives the same bits; files round-trip and a
// damaged one is refused by name.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

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
  EXPECT_EQ(someReceive.pages[0].values.size(), 3u);
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
    EXPECT_TRUE(back.sums.pages[p].values == sums.pages[p].values);
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

// Directional bakes sum four coefficients (L0, L1x, L1y, L1z) per texel: each is exact and order-free like
// the map, a value that cannot be added leaves every coefficient untouched, and one RGB value is refused.
TEST(ExactVplSums, FourCoefficientsAreEachExactAndAddedTogether) {
  const std::vector<glm::vec3> values = blockValues(4 * 300, 11);
  ExactVplSums forward = ExactVplSums::zeros({{1, 0, 1}}, 4), backward = ExactVplSums::zeros({{1, 0, 1}}, 4);
  EXPECT_EQ(forward.pages[0].values.size(), 2u * 12u);
  for (size_t b = 0; b < 300; ++b) ASSERT_TRUE(forward.add(0, 2, &values[4 * b]));
  for (size_t b = 300; b-- > 0;) ASSERT_TRUE(backward.add(0, 2, &values[4 * b]));
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(sameBits(forward.value(0, 2, c), backward.value(0, 2, c))) << c;
    glm::dvec3 reference(0.0);
    for (size_t b = 0; b < 300; ++b) reference += glm::dvec3(values[4 * b + c]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(forward.value(0, 2, c)[k], reference[k], reference[k] * 6e-8) << c;
  }
  EXPECT_EQ(forward.value(0, 0, 3), glm::vec3(0.0f));
  const glm::vec3 bad[4] = {glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(NAN)};
  EXPECT_FALSE(forward.add(0, 0, bad));
  EXPECT_EQ(forward.value(0, 0, 0), glm::vec3(0.0f));  // nothing of a refused value
  EXPECT_EQ(forward.pages[0].valid[0], 0);
  EXPECT_THROW(forward.add(0, 0, glm::vec3(1.0f)), std::invalid_argument);
  EXPECT_FALSE(forward.sameLayout(ExactVplSums::zeros({{1, 0, 1}})));  // same receivers, one coefficient
  EXPECT_THROW(forward.add(ExactVplSums::zeros({{1, 0, 1}})), std::invalid_argument);
  EXPECT_THROW(ExactVplSums::zeros({{1}}, 5), std::invalid_argument);
}

namespace {
std::string fileBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
VplSumHeader someHeader() {
  VplSumHeader h;
  h.kind = "checkpoint";
  h.sceneHash = "0123456789abcdef";
  h.optionsHash = hashText("directional=true\n");
  h.backend = "gl";
  h.blockCount = 4;
  h.endBlock = 2;
  h.command = nlohmann::json::object();
  h.backendCounts = nlohmann::json::object();
  return h;
}
}  // namespace

// Four coefficients round-trip bit for bit; files of earlier versions (no checksum) are refused as
// such; a count other than 1 or 4 is damage, caught by the checksum before anything else reads it.
TEST(VplSumFile, FourCoefficientsRoundTripAndOtherVersionsAreRefused) {
  const fs::path dir = fs::current_path() / "test_scratch" / "vpl_sum_file_v3";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ExactVplSums sums = ExactVplSums::zeros({{1, 1, 0, 1}}, 4);
  const std::vector<glm::vec3> values = blockValues(8, 5);
  ASSERT_TRUE(sums.add(0, 0, &values[0]));
  ASSERT_TRUE(sums.add(0, 3, &values[4]));
  const fs::path file = dir / "four.vplsum";
  writeVplSumFile(file, someHeader(), sums);
  const VplSumFile back = readVplSumFile(file);
  EXPECT_EQ(back.sums.coefficients, 4);
  ASSERT_TRUE(back.sums.sameLayout(sums));
  EXPECT_TRUE(back.sums.pages[0].values == sums.pages[0].values);
  EXPECT_EQ(back.sums.pages[0].valid, sums.pages[0].valid);

  const std::string bytes = fileBytes(file);
  ASSERT_EQ(bytes.substr(0, 15), "IRBAKE-VPLSUM-3");
  for (const char* old : {"IRBAKE-VPLSUM-1", "IRBAKE-VPLSUM-2"}) {
    std::string older = bytes;
    older.replace(0, 15, old);
    older.resize(older.size() - 8);  // no checksum then
    std::ofstream(dir / "old.vplsum", std::ios::binary | std::ios::trunc) << older;
    try {
      readVplSumFile(dir / "old.vplsum");
      ADD_FAILURE() << old << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Parse);
      EXPECT_NE(std::string(e.what()).find(old), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("old.vplsum"), std::string::npos) << e.what();
    }
  }
}

// Every byte is covered: flipping any one bit of a file (header, sums, end marker, checksum) is refused
// naming the file, and so is a header edited to claim more blocks.
TEST(VplSumFile, ChecksumCoversEveryByte) {
  const fs::path dir = fs::current_path() / "test_scratch" / "vpl_sum_checksum";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ExactVplSums sums = ExactVplSums::zeros({{1, 1, 0, 1}}, 1);
  const std::vector<glm::vec3> values = blockValues(3, 7);
  ASSERT_TRUE(sums.add(0, 0, values[0]));
  ASSERT_TRUE(sums.add(0, 3, values[1]));
  writeVplSumFile(dir / "good.vplsum", someHeader(), sums);
  const std::string good = fileBytes(dir / "good.vplsum");
  size_t refused = 0;
  for (size_t at = 15; at < good.size(); ++at) {  // past the magic, which says "not ours" instead
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ (1 << (at % 8)));
    std::ofstream(dir / "bad.vplsum", std::ios::binary | std::ios::trunc) << bad;
    try {
      readVplSumFile(dir / "bad.vplsum");
    } catch (const Error& e) {
      if (e.code() == ErrorCode::Parse && std::string(e.what()).find("bad.vplsum") != std::string::npos) ++refused;
    }
  }
  EXPECT_EQ(refused, good.size() - 15);
  std::string edited = good;
  const size_t at = edited.find("\"endBlock\":2");
  ASSERT_NE(at, std::string::npos);
  edited[at + 11] = '4';
  std::ofstream(dir / "edited.vplsum", std::ios::binary | std::ios::trunc) << edited;
  try {
    readVplSumFile(dir / "edited.vplsum");
    ADD_FAILURE() << "edited header accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
}
