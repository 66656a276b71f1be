// One bake split over machines and over interruptions gives the bytes of the bake on one
// machine: `bake --shard K/N` + `merge`, and `bake --resume` after SIGKILL at random moments.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "common/atomic_file.h"
#include "irbake_process.h"

namespace fs = std::filesystem;

namespace {

fs::path scratchFolder(const std::string& name) { return irbake::testing::scratchFolder("distributed", name); }

std::vector<std::string> split(const std::string& words) {
  std::istringstream in(words);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

using irbake::testing::fileText;
using irbake::testing::startIrbake;
int waitFor(pid_t pid) { return irbake::testing::waitForIrbake(pid); }

struct Finished {
  int code;
  std::string output;
};
Finished runIrbake(const std::vector<std::string>& args, const fs::path& log) {
  const int code = waitFor(startIrbake(args, log));
  return {code, fileText(log)};
}

const fs::path& cornellBox() {
  static const fs::path scene = [] {
    const fs::path dir = fs::current_path() / "test_scratch" / "distributed" / "samples";
    fs::create_directories(dir);
    runIrbake({"samples", dir.string(), "--quiet"}, dir.parent_path() / "samples_log.txt");
    return dir / "cornell_box.gltf";
  }();
  return scene;
}

// The outputs that must match byte for byte (the report's timings differ between any two runs); with
// directional, the L1 pages' EXRs and PNGs too.
void expectSameOutputs(const fs::path& expected, const fs::path& actual, bool directional = false) {
  std::vector<std::string> files = {"lightmap_0.exr", "scene.gltf", "scene.bin", "lightmap_0.png"};
  if (directional)
    for (const char* axis : {"l1x", "l1y", "l1z"})
      for (const char* ext : {".exr", ".png"}) files.push_back(std::string("lightmap_0_") + axis + ext);
  for (const std::string& file : files) {
    const std::string want = fileText(expected / file);
    ASSERT_FALSE(want.empty()) << expected / file;
    EXPECT_TRUE(fileText(actual / file) == want) << actual / file << " differs from " << expected / file;
  }
}

// Small enough to bake in seconds, with enough VPL blocks (16 VPLs each) to split.
const std::string kOptions = "--texels-per-unit 40 --vpl-block 16 --quiet";
const std::string kWalk = " --vpls 192 --seed 5";

// `irbake bake` of the Cornell box into `out` with `options`, then `extra`; its output in out_log.txt.
Finished bakeCornell(const std::vector<std::string>& options, const fs::path& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args{"bake", cornellBox().string(), "-o", out.string()};
  args.insert(args.end(), options.begin(), options.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return runIrbake(args, out.string() + "_log.txt");
}

}  // namespace

TEST(Distributed, ShardsMergeToTheBytesOfOneMachine) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  for (const std::string backend : {"gl", "embree"}) {
    const fs::path dir = scratchFolder("shards_" + backend);
    // Interleave 2: the blocks of the four texel classes are split across the shards too.
    std::vector<std::string> options = split(kOptions + kWalk + " --interleave 2 --backend " + backend);
    auto bake = [&](const fs::path& out, const std::vector<std::string>& extra) { return bakeCornell(options, out, extra); };
    Finished one = bake(dir / "one", {});
    ASSERT_EQ(one.code, 0) << one.output;
    for (int n : {2, 3}) {
      std::vector<std::string> merge{"merge"};
      for (int k = n; k >= 1; --k) {  // given to merge in reverse order
        const fs::path out = dir / ("shard_" + std::to_string(k) + "_of_" + std::to_string(n));
        Finished shard = bake(out, {"--shard", std::to_string(k) + "/" + std::to_string(n), "--threads", std::to_string(k % 2 + 1)});
        ASSERT_EQ(shard.code, 0) << shard.output;
        EXPECT_TRUE(fs::exists(out / ("partial_" + std::to_string(k) + "_of_" + std::to_string(n) + ".vplsum")));
        EXPECT_FALSE(fs::exists(out / "lightmap_0.exr"));  // a shard writes its partial only
        merge.push_back(out.string());
      }
      const fs::path merged = dir / ("merged_" + std::to_string(n));
      merge.insert(merge.end(), {"-o", merged.string(), "--quiet"});
      Finished m = runIrbake(merge, merged.string() + "_log.txt");
      ASSERT_EQ(m.code, 0) << m.output;
      expectSameOutputs(dir / "one", merged);
    }
  }
}

TEST(Distributed, MergeRefusesPartialsOfOtherBakesAndMissingOrDoubledShares) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  const fs::path dir = scratchFolder("merge_errors");
  auto shard = [&](const std::string& name, const std::string& share, const std::string& extra) {
    std::vector<std::string> args{"bake", cornellBox().string(), "-o", (dir / name).string(), "--backend", "embree", "--shard", share};
    for (const auto& a : split(kOptions + " " + extra)) args.push_back(a);
    Finished r = runIrbake(args, dir / (name + "_log.txt"));
    EXPECT_EQ(r.code, 0) << r.output;
  };
  shard("a1", "1/2", kWalk);
  shard("a2", "2/2", kWalk);
  shard("seed", "2/2", "--vpls 192 --seed 6");
  shard("vpls", "2/2", "--vpls 200 --seed 5");
  shard("three", "2/3", kWalk);
  // The same scene with one byte changed in its JSON (a trailing space): another scene.
  const fs::path edited = dir / "cornell_edited.gltf";
  std::ofstream(edited, std::ios::binary) << fileText(cornellBox()) << " ";
  fs::copy_file(cornellBox().parent_path() / "cornell_box.bin", dir / "cornell_box.bin", fs::copy_options::overwrite_existing);
  {
    std::vector<std::string> args{"bake", edited.string(), "-o", (dir / "scene").string(), "--backend", "embree", "--shard", "2/2"};
    for (const auto& a : split(kOptions + kWalk)) args.push_back(a);
    ASSERT_EQ(runIrbake(args, dir / "scene_log.txt").code, 0);
  }
  struct Case {
    std::vector<std::string> inputs;
    int code;
    std::string names, says;
  };
  const std::vector<Case> cases = {
      {{"a1", "seed"}, 5, "seed", "different seed"},
      {{"a1", "vpls"}, 5, "vpls", "different options"},
      {{"a1", "scene"}, 5, "scene", "different scene"},
      {{"a1", "three"}, 5, "three", "one of 2"},
      {{"a1"}, 2, "a1", "missing share(s) 2/2"},
      {{"a1", "a2", "a1"}, 2, "a1", "given twice"},
      {{"a1", "nothing_here"}, 3, "nothing_here", "no such file"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"merge"};
    for (const auto& in : c.inputs) args.push_back((dir / in).string());
    args.insert(args.end(), {"-o", (dir / "out").string()});
    Finished r = runIrbake(args, dir / "merge_log.txt");
    EXPECT_EQ(r.code, c.code) << r.output;
    EXPECT_NE(r.output.find(c.names), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out" / "lightmap_0.exr"));
  }
  // And the right two, in any order, merge.
  Finished ok = runIrbake({"merge", (dir / "a2").string(), (dir / "a1").string(), "-o", (dir / "out").string(), "--quiet"},
                  dir / "merge_log.txt");
  EXPECT_EQ(ok.code, 0) << ok.output;
}

// SIGKILL at three moments drawn from a fixed seed (reproducible), each run resuming the last: the
// outputs equal an uninterrupted bake's, byte for byte, and the checkpoint is gone.
TEST(Distributed, ResumeAfterSigkillGivesTheBytesOfAnUninterruptedBake) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  const fs::path dir = scratchFolder("resume");
  std::vector<std::string> args{"bake", cornellBox().string(), "--backend", "gl", "--checkpoint-seconds", "0"};
  for (const auto& a : split(kOptions + kWalk)) args.push_back(a);
  auto into = [&](const fs::path& out, bool resume) {
    std::vector<std::string> a = args;
    a.insert(a.end(), {"-o", out.string()});
    if (resume) a.push_back("--resume");
    return a;
  };
  const auto t0 = std::chrono::steady_clock::now();
  Finished whole = runIrbake(into(dir / "whole", false), dir / "whole_log.txt");
  ASSERT_EQ(whole.code, 0) << whole.output;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::mt19937 rng(14);
  std::uniform_real_distribution<double> moment(0.1 * seconds, 0.9 * seconds);
  const fs::path out = dir / "killed";
  int killedWhileRunning = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const pid_t pid = startIrbake(into(out, attempt > 0), dir / ("killed_log_" + std::to_string(attempt) + ".txt"));
    std::this_thread::sleep_for(std::chrono::duration<double>(moment(rng)));
    killedWhileRunning += kill(pid, SIGKILL) == 0 && waitFor(pid) == 128 + SIGKILL;
  }
  EXPECT_GE(killedWhileRunning, 1);
  Finished last = runIrbake(into(out, true), dir / "resumed_log.txt");
  ASSERT_EQ(last.code, 0) << last.output;
  expectSameOutputs(dir / "whole", out);
  EXPECT_FALSE(fs::exists(out / ".irbake.checkpoint"));
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_FALSE(irbake::isIrbakeTempName(entry.path().filename().string())) << entry.path();
}

TEST(Distributed, ResumeRefusesTheCheckpointOfAnotherBake) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  const fs::path dir = scratchFolder("resume_other");
  const fs::path out = dir / "out";
  std::vector<std::string> args{"bake", cornellBox().string(), "-o", out.string(), "--backend", "embree",
                                "--checkpoint-seconds", "0", "--vpls", "192"};
  for (const auto& a : split(kOptions)) args.push_back(a);
  // Killed as soon as its first checkpoint is there.
  const pid_t pid = startIrbake(args, dir / "first_log.txt");
  const fs::path checkpoint = out / ".irbake.checkpoint";
  for (int i = 0; i < 6000 && !fs::exists(checkpoint); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  waitFor(pid);
  ASSERT_TRUE(fs::exists(checkpoint)) << fileText(dir / "first_log.txt");
  std::vector<std::string> other = args;
  other.insert(other.end(), {"--resume", "--seed", "6"});
  Finished refused = runIrbake(other, dir / "refused_log.txt");
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_NE(refused.output.find(".irbake.checkpoint"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("different seed"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(out / "lightmap_0.exr"));
  EXPECT_TRUE(fs::exists(checkpoint));  // refused, not destroyed
}

// Directional bakes sum their L1 pages in the same exact block sums as the map: shards merged,
// and a bake resumed from a checkpoint, give the one-shot bake's bytes, L1 pages included, on both
// backends. The resume starts from the sums of the first half of the blocks, which is what shard 1/2's
// partial holds (same header fields as a checkpoint of that bake): deterministic, unlike a SIGKILL.
TEST(Distributed, DirectionalShardsAndResumeGiveTheBytesOfOneMachine) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  for (const std::string backend : {"gl", "embree"}) {
    const fs::path dir = scratchFolder("directional_" + backend);
    const std::vector<std::string> options =
        split(kOptions + kWalk + " --interleave 2 --directional --sun 0.3,-1,-0.4,2 --backend " + backend);
    auto bake = [&](const fs::path& out, const std::vector<std::string>& extra) { return bakeCornell(options, out, extra); };
    Finished one = bake(dir / "one", {});
    ASSERT_EQ(one.code, 0) << one.output;
    ASSERT_TRUE(fs::exists(dir / "one" / "lightmap_0_l1x.exr"));

    std::vector<std::string> merge{"merge"};
    for (int k : {2, 1}) {
      const fs::path out = dir / ("shard_" + std::to_string(k));
      Finished shard = bake(out, {"--shard", std::to_string(k) + "/2"});
      ASSERT_EQ(shard.code, 0) << shard.output;
      merge.push_back(out.string());
    }
    merge.insert(merge.end(), {"-o", (dir / "merged").string(), "--quiet"});
    Finished m = runIrbake(merge, dir / "merged_log.txt");
    ASSERT_EQ(m.code, 0) << m.output;
    expectSameOutputs(dir / "one", dir / "merged", true);

    const fs::path resumed = dir / "resumed";
    fs::create_directories(resumed);
    fs::copy_file(dir / "shard_1" / "partial_1_of_2.vplsum", resumed / ".irbake.checkpoint");
    {  // The same bake without --directional: another bake, refused, the checkpoint kept.
      std::vector<std::string> plain{"bake", cornellBox().string(), "-o", resumed.string(), "--resume"};
      for (const std::string& a : options)
        if (a != "--directional") plain.push_back(a);
      Finished refused = runIrbake(plain, dir / "refused_log.txt");
      EXPECT_EQ(refused.code, 2) << refused.output;
      EXPECT_NE(refused.output.find("different options"), std::string::npos) << refused.output;
      ASSERT_TRUE(fs::exists(resumed / ".irbake.checkpoint"));
    }
    Finished rr = bake(resumed, {"--resume"});
    ASSERT_EQ(rr.code, 0) << rr.output;
    expectSameOutputs(dir / "one", resumed, true);
    EXPECT_FALSE(fs::exists(resumed / ".irbake.checkpoint"));
  }
}

// --portable is where the finished bake writes: refused on a shard (which writes only its partial), given to
// merge instead, whose portable GLB is the bytes of the one-machine bake's.
TEST(Distributed, MergeWritesThePortableGlbOfOneMachine) {
  ASSERT_TRUE(fs::exists(cornellBox()));
  const fs::path dir = scratchFolder("portable");
  const std::vector<std::string> options = split(kOptions + kWalk + " --backend embree");
  Finished one = bakeCornell(options, dir / "one", {"--portable", (dir / "one.glb").string()});
  ASSERT_EQ(one.code, 0) << one.output;
  Finished refused = bakeCornell(options, dir / "refused", {"--shard", "1/2", "--portable", (dir / "x.glb").string()});
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--portable"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  std::vector<std::string> merge{"merge"};
  for (int k = 1; k <= 2; ++k) {
    const fs::path out = dir / ("shard_" + std::to_string(k));
    Finished shard = bakeCornell(options, out, {"--shard", std::to_string(k) + "/2"});
    ASSERT_EQ(shard.code, 0) << shard.output;
    merge.push_back(out.string());
  }
  merge.insert(merge.end(), {"-o", (dir / "merged").string(), "--portable", (dir / "merged.glb").string(), "--quiet"});
  Finished m = runIrbake(merge, dir / "merge_log.txt");
  ASSERT_EQ(m.code, 0) << m.output;
  const std::string want = fileText(dir / "one.glb");
  ASSERT_GT(want.size(), 1000u);
  EXPECT_TRUE(fileText(dir / "merged.glb") == want);
  expectSameOutputs(dir / "one", dir / "merged");
}
