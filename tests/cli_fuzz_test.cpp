// A fuzz harness for the command line and for the files irbake reads back (partials for merge,
// checkpoints for resume, EXR pages for diff): seeded mutations of valid runs, each run as a user would.
// Every run must end with exit 0 or a documented error code and one "irbake: error: ..." line, never a
// signal or a hang; a run that exits 0 writes no NaN; a damaged partial or checkpoint is never accepted.
// IRBAKE_FUZZ_RUNS scales the run counts (default 1: about a minute on two cores).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "export/exr_io.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("cli_fuzz", name); }

int runsScale() {
  const char* s = std::getenv("IRBAKE_FUZZ_RUNS");
  return s ? std::max(1, std::atoi(s)) : 1;
}

// irbake under `timeout` (a hang is a finding: 124).
IrbakeRun runIrbake(std::vector<std::string> args, const fs::path& log) {
  args.insert(args.begin(), {"60", IRBAKE_EXE});
  const fs::path timeout = "/usr/bin/timeout";
  std::string cmd = timeout.string();
  for (const auto& a : args) {
    std::string quoted = "'";
    for (char c : a) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    cmd += " " + quoted + "'";
  }
  cmd += " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return {code, fileText(log)};
}

// The contract of every run: a documented exit code; an error is one line naming what is wrong.
void expectContract(const IrbakeRun& run, const std::string& what) {
  static const std::set<int> documented = {0, 2, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_TRUE(documented.count(run.code)) << what << " exited " << run.code << ":\n" << run.output;
  if (run.code != 0) {
    EXPECT_NE(run.output.find("irbake: error: "), std::string::npos) << what << ":\n" << run.output;
  }
}

void expectFiniteExrs(const fs::path& dir, const std::string& what) {
  if (!fs::is_directory(dir)) return;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".exr") continue;
    const irbake::Lightmap m = irbake::readExr(e.path());
    for (const auto& t : m.texels)
      ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)) << what << ": NaN in " << e.path();
  }
}

fs::path samples() { return irbake::testing::sampleScenes("cli_fuzz"); }

// Values a hostile user (or a broken script) puts where a value goes.
const std::vector<std::string> kHostileValues = {
    "", "-1", "0", "1", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "0x10", "010", "4294967297",
    "9223372036854775808", "1/0", "0/0", "2/1", "1/1", "//", "1,2", "1,2,3", "0,0,0,0", "1e300,0,0,5", "-1,-1,-1",
    "auto", "AUTO", " 3", "3 ", "%s%n", "\xff\xfe", std::string(5000, 'a'), "--", "-o", "--help", ".", "..",
    "/", "/dev/null", "/proc/self/mem", "no/such/file.gltf", "out.glb", "out.gltf", "r.json"};

}  // namespace

// Mutated bake, merge, diff, info and unwrap command lines against the samples.
TEST(CliFuzz, MutatedCommandLinesKeepTheErrorContract) {
  const fs::path dir = scratch("args");
  const std::string scene = (samples() / "point_over_plane.gltf").string();
  const std::vector<std::vector<std::string>> valid = {
      {"bake", scene, "-o", (dir / "o").string(), "--texels-per-unit", "2", "--vpls", "16", "--quiet"},
      {"bake", scene, "-o", (dir / "o").string(), "--texels-per-unit", "2", "--vpls", "16", "--backend", "embree",
       "--sun", "0,-1,0,2", "--sky", "0.1,0.1,0.1", "--seed", "3", "--clamp", "1", "--quiet"},
      {"bake", scene, "-o", (dir / "s").string(), "--texels-per-unit", "2", "--vpls", "16", "--shard", "1/2", "--quiet"},
      {"merge", (dir / "s").string(), "-o", (dir / "m").string(), "--quiet"},
      {"diff", (dir / "o").string(), (dir / "o").string()},
      {"info", scene},
      {"unwrap", scene, "-o", (dir / "u.gltf").string(), "--texels-per-unit", "2"},
  };
  std::mt19937 rng(20261127);
  const int runs = 200 * runsScale();
  for (int i = 0; i < runs; ++i) {
    std::vector<std::string> args = valid[rng() % valid.size()];
    const int mutations = 1 + static_cast<int>(rng() % 3);
    for (int m = 0; m < mutations && args.size() > 1; ++m) {
      const size_t at = 1 + rng() % (args.size() - 1);
      switch (rng() % 4) {
        case 0: args[at] = kHostileValues[rng() % kHostileValues.size()]; break;   // a hostile value
        case 1: args.erase(args.begin() + static_cast<long>(at)); break;            // a missing word
        case 2: args.insert(args.begin() + static_cast<long>(at), args[rng() % args.size()]); break;  // repeated
        case 3: std::swap(args[at], args[1 + rng() % (args.size() - 1)]); break;    // out of order
      }
    }
    std::string what = "irbake";
    for (const auto& a : args) what += " [" + a.substr(0, 60) + "]";
    const IrbakeRun run = runIrbake(args, dir / "log.txt");
    expectContract(run, what);
    if (run.code == 0) expectFiniteExrs(dir / "o", what);
  }
}

namespace {
// Flips, truncations, zeroed ranges, splices: a damaged copy of `bytes`.
std::string damaged(const std::string& bytes, std::mt19937& rng) {
  std::string out = bytes;
  switch (rng() % 5) {
    case 0:
      for (int k = 1 + static_cast<int>(rng() % 4); k-- > 0;) {
        const size_t at = rng() % out.size();
        out[at] = static_cast<char>(out[at] ^ (1 + rng() % 255));
      }
      break;
    case 1: out.resize(rng() % out.size()); break;
    case 2: {
      const size_t at = rng() % out.size(), n = std::min<size_t>(out.size() - at, 1 + rng() % 64);
      std::fill(out.begin() + static_cast<long>(at), out.begin() + static_cast<long>(at + n), '\0');
      break;
    }
    case 3: out += out.substr(rng() % out.size()); break;
    case 4: {
      const size_t at = rng() % out.size();
      out.insert(at, out.substr(rng() % out.size(), 1 + rng() % 16));
      break;
    }
  }
  return out == bytes ? out + "x" : out;
}
}  // namespace

// Damaged partials (merge) and checkpoints (resume) are always refused, naming the file; damaged EXR
// pages (diff) are refused or scored with finite numbers.
TEST(CliFuzz, DamagedFilesReadBackAreRefusedOrFinite) {
  const fs::path dir = scratch("files");
  const std::string scene = (samples() / "cornell_box.gltf").string();
  const std::vector<std::string> small = {"--texels-per-unit", "8", "--vpls", "32", "--vpl-block", "8",
                                          "--backend", "embree", "--quiet"};
  auto bakeInto = [&](const fs::path& out, std::vector<std::string> extra) {
    std::vector<std::string> args{"bake", scene, "-o", out.string()};
    args.insert(args.end(), small.begin(), small.end());
    args.insert(args.end(), extra.begin(), extra.end());
    return runIrbake(args, out.string() + "_log.txt");
  };
  for (int k : {1, 2}) ASSERT_EQ(bakeInto(dir / ("shard_" + std::to_string(k)), {"--shard", std::to_string(k) + "/2"}).code, 0);
  ASSERT_EQ(bakeInto(dir / "whole", {}).code, 0);
  const fs::path partial = dir / "shard_1" / "partial_1_of_2.vplsum";
  const std::string good = fileText(partial);
  const std::string page = fileText(dir / "whole" / "lightmap_0.exr");
  std::mt19937 rng(7);
  const int runs = 40 * runsScale();
  for (int i = 0; i < runs; ++i) {
    // merge with a damaged partial
    std::ofstream(partial, std::ios::binary | std::ios::trunc) << damaged(good, rng);
    const IrbakeRun merge = runIrbake({"merge", (dir / "shard_1").string(), (dir / "shard_2").string(), "-o",
                                    (dir / "merged").string(), "--quiet"}, dir / "merge_log.txt");
    expectContract(merge, "merge of a damaged partial");
    EXPECT_NE(merge.code, 0) << "damaged partial merged";
    EXPECT_NE(merge.output.find("partial_1_of_2.vplsum"), std::string::npos) << merge.output;
    // resume from a damaged checkpoint
    const fs::path resumed = dir / "resumed";
    fs::remove_all(resumed);
    fs::create_directories(resumed);
    std::ofstream(resumed / ".irbake.checkpoint", std::ios::binary) << damaged(good, rng);
    const IrbakeRun resume = bakeInto(resumed, {"--resume"});
    expectContract(resume, "resume from a damaged checkpoint");
    EXPECT_NE(resume.code, 0) << "damaged checkpoint resumed";
    EXPECT_NE(resume.output.find(".irbake.checkpoint"), std::string::npos) << resume.output;
    // diff against a damaged page
    const fs::path bad = dir / "bad.exr";
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << damaged(page, rng);
    const IrbakeRun diff = runIrbake({"diff", bad.string(), (dir / "whole" / "lightmap_0.exr").string()}, dir / "diff_log.txt");
    expectContract(diff, "diff of a damaged page");
    if (diff.code == 0) {
      EXPECT_EQ(diff.output.find("nan"), std::string::npos) << diff.output;
      EXPECT_EQ(diff.output.find("inf"), std::string::npos) << diff.output;
    }
  }
  std::ofstream(partial, std::ios::binary | std::ios::trunc) << good;
  const IrbakeRun merge = runIrbake({"merge", (dir / "shard_1").string(), (dir / "shard_2").string(), "-o",
                                  (dir / "merged").string(), "--quiet"}, dir / "merge_log.txt");
  ASSERT_EQ(merge.code, 0) << merge.output;
  EXPECT_EQ(fileText(dir / "merged" / "lightmap_0.exr"), page);
}
