// What a bake may write and what it must never touch: previous outputs survive a failed bake, no output
// lands on an input or another output, only irbake's own temps are cleaned up, a killed bake leaves no
// lock, and damaged partials and checkpoints are refused.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/output_lock.h"
#include "irbake_process.h"
#include "pipeline/vpl_sum_file.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("output_safety", name); }

IrbakeRun runIrbake(const std::vector<std::string>& args, const fs::path& log) { return irbake::testing::runIrbakeLogged(args, log); }

fs::path samples() { return irbake::testing::sampleScenes("output_safety"); }

// A small, fast bake of the sample Cornell box.
const std::vector<std::string> kSmall = {"--texels-per-unit", "12", "--vpls", "64", "--backend", "embree", "--quiet"};

IrbakeRun bake(const fs::path& scene, const fs::path& out, std::vector<std::string> extra, const fs::path& log) {
  std::vector<std::string> args{"bake", scene.string(), "-o", out.string()};
  args.insert(args.end(), kSmall.begin(), kSmall.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return runIrbake(args, log);
}

// Every file of a folder with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = fileText(e.path());
  return files;
}

// A copy of the sample Cornell box (glTF + .bin) in its own folder, under `name`.gltf.
fs::path copyOfCornell(const fs::path& dir, const std::string& name) {
  fs::create_directories(dir);
  nlohmann::json doc = nlohmann::json::parse(fileText(samples() / "cornell_box.gltf"));
  for (auto& b : doc["buffers"])
    if (b.contains("uri")) {
      const std::string uri = b["uri"].get<std::string>();
      fs::copy_file(samples() / uri, dir / uri, fs::copy_options::overwrite_existing);
    }
  std::ofstream(dir / (name + ".gltf")) << doc.dump();
  return dir / (name + ".gltf");
}

}  // namespace

// A --report that is a folder was found only at the rename, whose rollback then deleted the previous
// good outputs. It is refused before any work (usage, exit 2), the previous bake byte for byte intact.
TEST(OutputSafety, ReportNamingAFolderKeepsThePreviousOutputs) {
  const fs::path dir = scratch("report_folder");
  const fs::path out = dir / "o";
  IrbakeRun first = bake(samples() / "cornell_box.gltf", out, {}, dir / "first.txt");
  ASSERT_EQ(first.code, 0) << first.output;
  const auto before = snapshot(out);
  ASSERT_TRUE(before.count("scene.gltf") && before.count("lightmap_0.exr") && before.count("lightmap_0.png"));
  fs::create_directories(dir / "rdir");
  std::ofstream(dir / "rdir" / "x") << "x";
  IrbakeRun second = bake(samples() / "cornell_box.gltf", out, {"--seed", "3", "--report", (dir / "rdir").string()},
                          dir / "second.txt");
  EXPECT_EQ(second.code, 2) << second.output;
  EXPECT_NE(second.output.find("rdir"), std::string::npos) << second.output;
  EXPECT_NE(second.output.find("folder"), std::string::npos) << second.output;
  EXPECT_TRUE(snapshot(out) == before) << "the previous outputs changed";
  EXPECT_TRUE(fs::exists(dir / "rdir" / "x"));
}

// A set whose rename fails half-way puts back every file it had already replaced.
TEST(OutputSafety, FailedRenameRestoresTheFilesItReplaced) {
  const fs::path dir = scratch("rename_restore");
  std::ofstream(dir / "a.txt") << "old a";
  fs::create_directories(dir / "later");  // a folder where the set's last file should go
  const std::vector<irbake::PendingFile> files = {
      {dir / "a.txt", [](const fs::path& t) { std::ofstream(t) << "new a"; }},
      {dir / "b.txt", [](const fs::path& t) { std::ofstream(t) << "new b"; }},
  };
  irbake::writeAllAtomically(files);
  EXPECT_EQ(fileText(dir / "a.txt"), "new a");
  // Second set: replaces a.txt and b.txt, then fails on c.txt's rename (c.txt's folder vanishes).
  const std::vector<irbake::PendingFile> failing = {
      {dir / "a.txt", [](const fs::path& t) { std::ofstream(t) << "newer a"; }},
      {dir / "b.txt", [](const fs::path& t) { std::ofstream(t) << "newer b"; }},
      {dir / "sub" / "c.txt",
       [&](const fs::path& t) {
         std::ofstream(t) << "c";
         fs::remove_all(dir / "sub");  // the temp goes with its folder: the rename of c fails
       }},
  };
  EXPECT_THROW(irbake::writeAllAtomically(failing), irbake::Error);
  EXPECT_EQ(fileText(dir / "a.txt"), "new a");
  EXPECT_EQ(fileText(dir / "b.txt"), "new b");
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_FALSE(irbake::isIrbakeTempName(e.path().filename().string())) << "temp left: " << e.path();
}

// Only irbake's own temps are stale temps: user files that merely look like temps stay.
TEST(OutputSafety, StaleTempCleanupRemovesOnlyIrbakeTemps) {
  const fs::path dir = scratch("stale_temps");
  const fs::path out = dir / "o";
  fs::create_directories(out);
  for (const char* name : {"thesis.tmp1", "backup.tmp2024_06_01", "scene.gltf.tmp803_3", ".irbake-tmp.x.1.a"})
    std::ofstream(out / name) << "user data";
  const fs::path stale = irbake::tempPathFor(out / "lightmap_0.exr");
  std::ofstream(stale) << "half-written";
  EXPECT_TRUE(irbake::isIrbakeTempName(stale.filename().string()));
  IrbakeRun run = bake(samples() / "cornell_box.gltf", out, {}, dir / "log.txt");
  ASSERT_EQ(run.code, 0) << run.output;
  for (const char* name : {"thesis.tmp1", "backup.tmp2024_06_01", "scene.gltf.tmp803_3", ".irbake-tmp.x.1.a"})
    EXPECT_EQ(fileText(out / name), "user data") << name;
  EXPECT_FALSE(fs::exists(stale));
}

// --report naming one of the bake's outputs or inputs is refused (exit 2) and nothing changes.
TEST(OutputSafety, ReportNamingAnOutputOrAnInputIsRefused) {
  const fs::path dir = scratch("report_clash");
  const fs::path scene = copyOfCornell(dir / "in", "box");
  const fs::path out = dir / "o";
  ASSERT_EQ(bake(scene, out, {}, dir / "first.txt").code, 0);
  const auto outBefore = snapshot(out), inBefore = snapshot(dir / "in");
  const std::vector<fs::path> clashes = {out / "scene.gltf", out / "scene.bin", out / "lightmap_0.exr",
                                         out / "lightmap_0.png", scene, dir / "in" / "cornell_box.bin"};
  for (const fs::path& report : clashes) {
    IrbakeRun run = bake(scene, out, {"--report", report.string()}, dir / "clash.txt");
    EXPECT_EQ(run.code, 2) << report << ": " << run.output;
    EXPECT_NE(run.output.find(report.filename().string()), std::string::npos) << run.output;
  }
  IrbakeRun glb = bake(scene, dir / "x.glb", {"--report", (dir / "x.glb").string()}, dir / "glb.txt");
  EXPECT_EQ(glb.code, 2) << glb.output;
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  EXPECT_TRUE(snapshot(out) == outBefore);
  EXPECT_TRUE(snapshot(dir / "in") == inBefore);
}

// -o into the input's own folder must not overwrite the input: the glTF named by -o, or scene.gltf.
TEST(OutputSafety, OutputOntoTheInputIsRefused) {
  const fs::path dir = scratch("onto_input");
  const fs::path named = copyOfCornell(dir / "a", "cornell_box");
  const fs::path plain = copyOfCornell(dir / "b", "scene");
  const auto aBefore = snapshot(dir / "a"), bBefore = snapshot(dir / "b");
  IrbakeRun onto = bake(named, named, {}, dir / "onto.txt");
  EXPECT_EQ(onto.code, 2) << onto.output;
  EXPECT_NE(onto.output.find("cornell_box.gltf"), std::string::npos) << onto.output;
  IrbakeRun folder = bake(plain, dir / "b", {}, dir / "folder.txt");
  EXPECT_EQ(folder.code, 2) << folder.output;
  EXPECT_NE(folder.output.find("scene.gltf"), std::string::npos) << folder.output;
  EXPECT_TRUE(snapshot(dir / "a") == aBefore);
  EXPECT_TRUE(snapshot(dir / "b") == bBefore);
  // Into its own folder under another name: allowed, and the input is untouched.
  IrbakeRun beside = bake(named, dir / "a" / "baked.gltf", {}, dir / "beside.txt");
  EXPECT_EQ(beside.code, 0) << beside.output;
  EXPECT_EQ(fileText(named), aBefore.at("cornell_box.gltf"));
  EXPECT_EQ(fileText(dir / "a" / "cornell_box.bin"), aBefore.at("cornell_box.bin"));
}

// --portable is one more output: refused when it names an input, another output, a folder or a non-GLB name,
// before any work, leaving the previous bake and the inputs as they were.
TEST(OutputSafety, PortableNamingAnOutputOrAnInputIsRefused) {
  const fs::path dir = scratch("portable_clash");
  const fs::path scene = copyOfCornell(dir / "in", "box");
  const fs::path out = dir / "o";
  ASSERT_EQ(bake(scene, out, {"--portable", (dir / "p.glb").string()}, dir / "first.txt").code, 0);
  ASSERT_TRUE(fs::exists(dir / "p.glb"));
  const auto outBefore = snapshot(out), inBefore = snapshot(dir / "in");
  const std::string portableBefore = fileText(dir / "p.glb");
  const std::vector<fs::path> clashes = {out / "scene.gltf", out / "scene.bin", out / "report.json", scene,
                                         dir / "in" / "cornell_box.bin", out, dir / "p.gltf"};
  for (const fs::path& portable : clashes) {
    IrbakeRun run = bake(scene, out, {"--portable", portable.string()}, dir / "clash.txt");
    EXPECT_EQ(run.code, 2) << portable << ": " << run.output;
    EXPECT_NE(run.output.find(portable.filename().string()), std::string::npos) << run.output;
  }
  IrbakeRun glb = bake(scene, dir / "x.glb", {"--portable", (dir / "x.glb").string()}, dir / "glb.txt");
  EXPECT_EQ(glb.code, 2) << glb.output;
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  IrbakeRun report = bake(scene, out, {"--portable", (dir / "r.glb").string(), "--report", (dir / "r.glb").string()},
                          dir / "report.txt");
  EXPECT_EQ(report.code, 2) << report.output;
  EXPECT_FALSE(fs::exists(dir / "r.glb"));
  EXPECT_TRUE(snapshot(out) == outBefore);
  EXPECT_TRUE(snapshot(dir / "in") == inBefore);
  EXPECT_EQ(fileText(dir / "p.glb"), portableBefore);
}

// --portable goes beside the other outputs: alone, as OUTDIR/portable.glb; a bare name, in OUTDIR (also with
// -o OUT.glb: its folder); a name with a folder, there. The report names the file and counts its time.
TEST(OutputSafety, PortableGoesBesideTheOutputsUnlessAPathIsGiven) {
  const fs::path dir = scratch("portable_where");
  const fs::path scene = copyOfCornell(dir / "in", "box");
  IrbakeRun alone = bake(scene, dir / "a", {"--portable"}, dir / "alone.txt");
  ASSERT_EQ(alone.code, 0) << alone.output;
  EXPECT_TRUE(fs::exists(dir / "a" / "portable.glb"));
  const nlohmann::json report = nlohmann::json::parse(fileText(dir / "a" / "report.json"));
  EXPECT_EQ(fs::path(report["portable"]["file"].get<std::string>()), dir / "a" / "portable.glb");
  EXPECT_TRUE(report["timings"]["seconds"].contains("portable"));
  EXPECT_GE(report["timings"]["memoryPeakMiB"].get<double>(), 1.0);
  ASSERT_EQ(bake(scene, dir / "b" / "level.glb", {"--portable", "shipped.glb"}, dir / "bare.txt").code, 0);
  EXPECT_TRUE(fs::exists(dir / "b" / "shipped.glb"));
  ASSERT_EQ(bake(scene, dir / "c", {"--portable", (dir / "elsewhere" / "p.glb").string()}, dir / "path.txt").code, 0);
  EXPECT_TRUE(fs::exists(dir / "elsewhere" / "p.glb"));
  EXPECT_FALSE(fs::exists(dir / "c" / "p.glb"));
  // A bare name is checked where it goes: there it is the glTF output itself.
  IrbakeRun clash = bake(scene, dir / "d" / "level.glb", {"--portable", "level.glb"}, dir / "clash.txt");
  EXPECT_EQ(clash.code, 2) << clash.output;
  EXPECT_FALSE(fs::exists(dir / "d" / "level.glb"));
}

// A bake killed by SIGTERM, SIGINT or SIGABRT takes its lock file with it.
TEST(OutputSafety, KilledBakeLeavesNoLock) {
  const fs::path dir = scratch("killed");
  for (int sig : {SIGTERM, SIGINT, SIGABRT}) {
    const fs::path out = dir / std::string("o").append(std::to_string(sig));  // append: GCC 12 warns falsely on "o" + string
    std::vector<std::string> args{"bake", (samples() / "cornell_box.gltf").string(), "-o", out.string(),
                                  "--texels-per-unit", "40", "--vpls", "4096", "--backend", "embree", "--quiet"};
    const pid_t pid = irbake::testing::startIrbake(args, dir / "log.txt");
    const fs::path lock = out / irbake::OutputFolderLock::kFileName;
    // Held once the bake's pid is in it.
    for (int i = 0; i < 4000 && fileText(lock).empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_FALSE(fileText(lock).empty()) << fileText(dir / "log.txt");
    kill(pid, sig);
    EXPECT_EQ(irbake::testing::waitForIrbake(pid), 128 + sig);
    EXPECT_FALSE(fs::exists(lock)) << "signal " << sig;
  }
}

// A --report in another bake's folder waits for nobody: that folder is busy, refused at once.
TEST(OutputSafety, ReportIntoAnotherBakesLockedFolderIsRefused) {
  const fs::path dir = scratch("report_locked");
  const fs::path other = dir / "other";
  const irbake::OutputFolderLock held(other);
  IrbakeRun run = bake(samples() / "cornell_box.gltf", dir / "o", {"--report", (other / "r.json").string()}, dir / "log.txt");
  EXPECT_EQ(run.code, 3) << run.output;
  EXPECT_NE(run.output.find("busy"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(other / "r.json"));
  EXPECT_FALSE(fs::exists(dir / "o" / "scene.gltf"));
}

// A full disk is said as such, naming the output (never a temp), and the previous outputs stay. Needs a
// private mount namespace with a small tmpfs (root, or user namespaces); skipped where there is none.
TEST(OutputSafety, FullDiskSaysSoAndKeepsThePreviousOutputs) {
  const fs::path dir = scratch("full_disk");
  const fs::path mount = dir / "small";
  fs::create_directories(mount);
  const fs::path script = dir / "run.sh";
  // No probes in the first bake: its 1.2k probes (150 kB) alone would not fit the 120 kB disk.
  const std::string small = "--texels-per-unit 12 --vpls 64 --backend embree --probes off --quiet";
  std::ofstream(script) << "set -u\n"
                        << "mount -t tmpfs -o size=120k tmpfs '" << mount.string() << "' || exit 77\n"
                        << "'" << IRBAKE_EXE << "' bake '" << (samples() / "cornell_box.gltf").string() << "' -o '"
                        << (mount / "o").string() << "' " << small << " || exit 70\n"
                        << "ls -la '" << (mount / "o").string() << "' > '" << (dir / "before.txt").string() << "'\n"
                        << "md5sum '" << (mount / "o").string() << "'/* > '" << (dir / "sums_before.txt").string() << "'\n"
                        << "'" << IRBAKE_EXE << "' bake '" << (samples() / "cornell_box.gltf").string() << "' -o '"
                        << (mount / "o").string() << "' --texels-per-unit 60 --vpls 64 --backend embree --quiet"
                        << " > '" << (dir / "second.txt").string() << "' 2>&1\n"
                        << "echo $? > '" << (dir / "code.txt").string() << "'\n"
                        << "md5sum '" << (mount / "o").string() << "'/* > '" << (dir / "sums_after.txt").string() << "'\n"
                        << "ls -a '" << (mount / "o").string() << "' > '" << (dir / "after.txt").string() << "'\n";
  const int status = std::system(("unshare -m bash '" + script.string() + "' > '" + (dir / "log.txt").string() + "' 2>&1").c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 77 || code == 1) GTEST_SKIP() << "no private tmpfs mount here: " << fileText(dir / "log.txt");
  ASSERT_EQ(code, 0) << fileText(dir / "log.txt");
  const std::string message = fileText(dir / "second.txt");
  EXPECT_EQ(std::stoi(fileText(dir / "code.txt")), 3) << message;
  EXPECT_NE(message.find("no space left"), std::string::npos) << message;
  EXPECT_EQ(message.find(".irbake-tmp"), std::string::npos) << message;
  EXPECT_EQ(message.find(".tmp"), std::string::npos) << message;
  EXPECT_EQ(fileText(dir / "sums_before.txt"), fileText(dir / "sums_after.txt"));
  EXPECT_EQ(fileText(dir / "after.txt").find(".irbake-tmp"), std::string::npos) << fileText(dir / "after.txt");
}

namespace {
// Shards 1/2 and 2/2 of the small bake, in dir/shard_1 and dir/shard_2.
void bakeShards(const fs::path& dir, const std::vector<std::string>& extra = {}) {
  for (int k : {1, 2}) {
    std::vector<std::string> args = {"--vpl-block", "16", "--shard", std::to_string(k) + "/2"};
    args.insert(args.end(), extra.begin(), extra.end());
    IrbakeRun shard = bake(samples() / "cornell_box.gltf", dir / ("shard_" + std::to_string(k)), args, dir / "shard.txt");
    ASSERT_EQ(shard.code, 0) << shard.output;
  }
}
}  // namespace

// Partials and checkpoints carry a checksum: a flipped byte anywhere, or an edited header, is refused
// naming the file, and a file that is not one says so.
TEST(OutputSafety, DamagedPartialsAndCheckpointsAreRefused) {
  const fs::path dir = scratch("checksums");
  bakeShards(dir);
  const fs::path partial = dir / "shard_1" / "partial_1_of_2.vplsum";
  const std::string good = fileText(partial);
  ASSERT_GT(good.size(), 200u);
  for (size_t at : {size_t(20), good.size() / 2, good.size() - 20, good.size() - 3}) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    std::ofstream(partial, std::ios::binary | std::ios::trunc) << bad;
    IrbakeRun merge = runIrbake({"merge", (dir / "shard_1").string(), (dir / "shard_2").string(), "-o", (dir / "m").string()},
                             dir / "merge.txt");
    EXPECT_EQ(merge.code, 4) << at << ": " << merge.output;
    EXPECT_NE(merge.output.find("partial_1_of_2.vplsum"), std::string::npos) << merge.output;
    EXPECT_NE(merge.output.find("checksum"), std::string::npos) << merge.output;
  }
  std::ofstream(partial, std::ios::binary | std::ios::trunc) << "junk that is no partial at all";
  IrbakeRun junk = runIrbake({"merge", partial.string(), (dir / "shard_2").string(), "-o", (dir / "m").string()}, dir / "junk.txt");
  EXPECT_EQ(junk.code, 4) << junk.output;
  EXPECT_NE(junk.output.find("not an irbake VPL sum file"), std::string::npos) << junk.output;
  EXPECT_FALSE(fs::exists(dir / "m" / "scene.gltf"));

  // A checkpoint whose header says more blocks are done than were summed.
  std::string edited = good;
  const size_t at = edited.find("\"endBlock\":");
  ASSERT_NE(at, std::string::npos);
  const size_t digit = at + std::string("\"endBlock\":").size();
  edited[digit] = edited[digit] == '9' ? '8' : static_cast<char>(edited[digit] + 1);
  const fs::path resumed = dir / "resumed";
  fs::create_directories(resumed);
  std::ofstream(resumed / ".irbake.checkpoint", std::ios::binary) << edited;
  IrbakeRun resume = bake(samples() / "cornell_box.gltf", resumed, {"--vpl-block", "16", "--resume"}, dir / "resume.txt");
  EXPECT_EQ(resume.code, 4) << resume.output;
  EXPECT_NE(resume.output.find(".irbake.checkpoint"), std::string::npos) << resume.output;
  EXPECT_FALSE(fs::exists(resumed / "scene.gltf"));
}

// A resume is refused only for a different bake, and the refusal names the options that differ; an
// option given at its default ("--seed 0") or the same number written otherwise ("12.0") is the same bake.
TEST(OutputSafety, ResumeNamesTheOptionThatDiffersAndAcceptsTheSameBakeWrittenOtherwise) {
  const fs::path dir = scratch("resume_options");
  bakeShards(dir);
  const fs::path out = dir / "resumed";
  fs::create_directories(out);
  fs::copy_file(dir / "shard_1" / "partial_1_of_2.vplsum", out / ".irbake.checkpoint");
  IrbakeRun other = bake(samples() / "cornell_box.gltf", out, {"--vpl-block", "16", "--resume", "--seed", "3"}, dir / "other.txt");
  EXPECT_EQ(other.code, 2) << other.output;
  EXPECT_NE(other.output.find("different seed"), std::string::npos) << other.output;
  other = bake(samples() / "cornell_box.gltf", out, {"--vpl-block", "16", "--resume", "--clamp-k", "50"}, dir / "other.txt");
  EXPECT_EQ(other.code, 2) << other.output;
  EXPECT_NE(other.output.find("different options --clamp-k (50 vs default)"), std::string::npos) << other.output;
  ASSERT_TRUE(fs::exists(out / ".irbake.checkpoint"));
  // The same bake: explicit defaults, numbers written another way, options in another order.
  std::vector<std::string> args{"bake", (samples() / "cornell_box.gltf").string(), "-o", out.string(), "--resume",
                                "--seed", "0", "--vpl-block", "+16", "--backend", "embree", "--vpls", "64",
                                "--texels-per-unit", "12.000", "--final-gather", "auto", "--quiet"};
  IrbakeRun same = runIrbake(args, dir / "same.txt");
  EXPECT_EQ(same.code, 0) << same.output;
  EXPECT_FALSE(fs::exists(out / ".irbake.checkpoint"));
  // And the merged shards give the same bytes as the resumed bake.
  IrbakeRun merge = runIrbake({"merge", (dir / "shard_1").string(), (dir / "shard_2").string(), "-o", (dir / "m").string(), "--quiet"},
                           dir / "merge.txt");
  ASSERT_EQ(merge.code, 0) << merge.output;
  EXPECT_EQ(fileText(dir / "m" / "lightmap_0.exr"), fileText(out / "lightmap_0.exr"));
}

// The scene hash reads what the loader reads: a percent-encoded buffer URI names a file whose bytes count.
TEST(OutputSafety, SceneHashReadsPercentEncodedFiles) {
  const fs::path dir = scratch("uri_hash");
  nlohmann::json doc = nlohmann::json::parse(fileText(samples() / "cornell_box.gltf"));
  ASSERT_TRUE(doc["buffers"][0].contains("uri"));
  fs::copy_file(samples() / doc["buffers"][0]["uri"].get<std::string>(), dir / "my box.bin");
  doc["buffers"][0]["uri"] = "my%20box.bin";
  std::ofstream(dir / "scene.gltf") << doc.dump();
  const std::string before = irbake::hashSceneFiles(dir / "scene.gltf");
  std::string bin = fileText(dir / "my box.bin");
  bin[bin.size() / 2] = static_cast<char>(bin[bin.size() / 2] ^ 1);
  std::ofstream(dir / "my box.bin", std::ios::binary | std::ios::trunc) << bin;
  EXPECT_NE(irbake::hashSceneFiles(dir / "scene.gltf"), before);
}

// --shard takes K/N exactly: no wrap-around of large numbers, no empty value.
TEST(OutputSafety, ShardArgumentIsParsedExactly) {
  const fs::path dir = scratch("shard_args");
  for (const std::string shard : {"4294967297/2", "", "1/4294967298", "1/2x", "-1/2", "1/", "/2"}) {
    IrbakeRun run = bake(samples() / "cornell_box.gltf", dir / "o", {"--shard", shard}, dir / "log.txt");
    EXPECT_EQ(run.code, 2) << "'" << shard << "': " << run.output;
    EXPECT_NE(run.output.find("--shard"), std::string::npos) << run.output;
  }
  EXPECT_FALSE(fs::exists(dir / "o" / "scene.gltf"));
}

// Light and clamp values a bake cannot use are usage errors naming the option, before any work.
TEST(OutputSafety, UnusableNumbersAreUsageErrorsNamingTheOption) {
  const fs::path dir = scratch("numbers");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--clamp", "1e-300"}, "--clamp"},      {{"--sun", "0,-1,0,1e300"}, "--sun"},
      {{"--sun", "0,0,0,5"}, "--sun"},          {{"--sky", "1e300,0,0"}, "--sky"},
      {{"--sky", "-1,0,0"}, "--sky"},           {{"--sun", "0,-1,0,-2"}, "--sun"},
  };
  for (const auto& [args, option] : cases) {
    IrbakeRun run = bake(samples() / "cornell_box.gltf", dir / "o", args, dir / "log.txt");
    EXPECT_EQ(run.code, 2) << args[1] << ": " << run.output;
    EXPECT_NE(run.output.find(option), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("ClampMode"), std::string::npos) << run.output;
  }
  // A huge direction is still a direction.
  IrbakeRun huge = bake(samples() / "point_over_plane.gltf", dir / "o", {"--sun", "1e300,-1e300,0,1"}, dir / "huge.txt");
  EXPECT_EQ(huge.code, 0) << huge.output;
}
