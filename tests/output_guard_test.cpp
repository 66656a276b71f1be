// The output guard end to end: every command that writes a file (bake, merge, unwrap, samples, irview's
// --screenshot and --walkthrough), each of its output options, aimed at an input, at another output of the
// same command, at a folder and at a /proc path. Each run must be refused with exit 2 and a message naming
// the path, and every input and every earlier output must keep its bytes. Then: a bake removes a stale page
// only when its folder's manifest proves irbake wrote it, and `samples` never replaces a user's file.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/checksum.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("output_guard", name); }

// Runs `exe` with `args` (stdout and stderr into log): exit code or 128 + signal, and what it printed.
IrbakeRun runProgram(const std::string& exe, const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* out = std::freopen(log.c_str(), "w", stdout);
    if (!out || dup2(fileno(stdout), 2) < 0) _exit(127);
    std::vector<char*> argv{const_cast<char*>(exe.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), fileText(log)};
}

// Name -> XXH3 of the bytes of every file under `dir` (hidden files included): what must not change.
std::map<std::string, std::string> contents(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    irbake::Checksum64 sum;
    sum.add(fileText(e.path()));
    out[fs::relative(e.path(), dir).string()] = sum.hex();
  }
  return out;
}

struct Fixture {
  fs::path root, scenes, baked, glb, unwrapped, shards, frames;
};

// The inputs and earlier outputs every case aims at: the sample scenes, a bake into a folder, a bake into one
// GLB, an unwrap, a shard's partial, and a bake whose light-map PNG is named like a walkthrough frame.
const Fixture& fixture() {
  static Fixture f = [] {
    Fixture x;
    x.root = scratch("table");
    x.scenes = x.root / "scenes";
    const fs::path log = x.root / "setup.txt";
    auto must = [&](const std::vector<std::string>& args) {
      const IrbakeRun r = irbake::testing::runIrbakeLogged(args, log);
      if (r.code != 0) ADD_FAILURE() << "setup failed: " << r.output;
    };
    must({"samples", x.scenes.string(), "--quiet"});
    const std::string box = (x.scenes / "cornell_box.gltf").string();
    x.baked = x.root / "baked";
    must({"bake", box, "-o", x.baked.string(), "--quality", "preview", "--probes", "off", "--quiet"});
    x.glb = x.root / "one" / "box.glb";
    must({"bake", box, "-o", x.glb.string(), "--quality", "preview", "--probes", "off", "--quiet"});
    x.unwrapped = x.root / "unwrapped";
    fs::create_directories(x.unwrapped);
    must({"unwrap", box, "-o", (x.unwrapped / "u.gltf").string(), "--report", (x.unwrapped / "u.json").string()});
    x.shards = x.root / "shards";
    must({"bake", box, "-o", x.shards.string(), "--quality", "preview", "--probes", "off", "--shard", "1/1", "--quiet"});
    // A bake whose 8-bit page is named walk_0001.png: the second frame of --walkthrough 2 --screenshot walk.png.
    x.frames = x.root / "frames";
    fs::create_directories(x.frames);
    std::string gltf = fileText(x.baked / "scene.gltf");
    for (size_t at; (at = gltf.find("lightmap_0.png")) != std::string::npos;) gltf.replace(at, 14, "walk_0001.png");
    std::ofstream(x.frames / "scene.gltf", std::ios::binary) << gltf;
    fs::copy_file(x.baked / "scene.bin", x.frames / "scene.bin");
    fs::copy_file(x.baked / "lightmap_0.png", x.frames / "walk_0001.png");
    fs::create_directories(x.root / "folder.glb");
    fs::create_directories(x.root / "folder.png");
    fs::create_directories(x.root / "folder.json");
    return x;
  }();
  return f;
}

struct Case {
  std::string command, option, target;  // what the table's row and column are
  std::vector<std::string> args;
  std::string named;                     // the path the message must name
};

std::vector<Case> cases(const Fixture& f) {
  const std::string box = (f.scenes / "cornell_box.gltf").string(), bin = (f.scenes / "cornell_box.bin").string();
  const std::string baked = f.baked.string(), report = (f.baked / "report.json").string();
  const std::string gltfOut = (f.baked / "scene.gltf").string(), page = (f.baked / "lightmap_0.exr").string();
  const std::string partial = (f.shards / "partial_1_of_1.vplsum").string();
  const std::string proc = "/proc/version", procGlb = "/proc/irbake.glb", procPng = "/proc/irbake.png";
  const std::string folderGlb = (f.root / "folder.glb").string(), folderPng = (f.root / "folder.png").string();
  const std::string folderJson = (f.root / "folder.json").string();
  const std::string fresh = (f.root / "fresh").string(), freshGlb = (f.root / "fresh.glb").string();
  std::vector<Case> out;
  // The cases of one command: its leading arguments, then each case's option, target, arguments and name.
  auto command = [&out](std::string name, std::vector<std::string> lead) {
    return [&out, name, lead](std::string option, std::string target, std::vector<std::string> extra, std::string named) {
      std::vector<std::string> args = lead;
      args.insert(args.end(), extra.begin(), extra.end());
      out.push_back({name, option, target, args, named});
    };
  };
  auto bake = command("bake", {"bake", box, "--quality", "preview", "--probes", "off"});
  bake("-o", "input", {"-o", box}, box);
  bake("-o", "other output", {"-o", (f.root / "x.glb").string(), "--report", (f.root / "x.glb").string()}, "x.glb");
  bake("-o", "/proc", {"-o", procGlb}, procGlb);
  bake("--dump-config", "input", {"-o", fresh, "--dump-config", box}, box);
  bake("--dump-config", "input .bin", {"-o", fresh, "--dump-config", bin}, bin);
  bake("--dump-config", "other output", {"-o", baked, "--dump-config", report}, report);
  bake("--dump-config", "a page", {"-o", baked, "--dump-config", page}, page);
  bake("--dump-config", "folder", {"-o", fresh, "--dump-config", folderJson}, folderJson);
  bake("--dump-config", "/proc", {"-o", fresh, "--dump-config", proc}, proc);
  auto merge = command("merge", {"merge", f.shards.string()});
  merge("-o", "input", {"-o", box}, box);
  merge("-o", "a partial", {"-o", f.shards.string(), "--report", partial}, partial);
  merge("-o", "/proc", {"-o", procGlb}, procGlb);
  // --report and --portable are the same options in bake and merge: the same cases for both.
  for (const auto& add : {bake, merge}) {
    add("--report", "input", {"-o", fresh, "--report", bin}, bin);
    add("--report", "other output", {"-o", baked, "--report", gltfOut}, gltfOut);
    add("--report", "folder", {"-o", fresh, "--report", folderJson}, folderJson);
    add("--report", "/proc", {"-o", fresh, "--report", proc}, proc);
    add("--portable", "input", {"-o", fresh, "--portable", box}, box);
    add("--portable", "other output", {"-o", freshGlb, "--portable", freshGlb}, freshGlb);
    add("--portable", "folder", {"-o", fresh, "--portable", folderGlb}, folderGlb);
    add("--portable", "/proc", {"-o", fresh, "--portable", procGlb}, procGlb);
  }
  const std::string u = (f.unwrapped / "u.gltf").string();
  auto unwrap = command("unwrap", {"unwrap", box});
  unwrap("-o", "input", {"-o", box}, box);
  unwrap("-o", "other output", {"-o", u, "--report", u}, u);
  unwrap("-o", "folder", {"-o", folderGlb}, folderGlb);
  unwrap("-o", "/proc", {"-o", procGlb}, procGlb);
  unwrap("--report", "input", {"-o", freshGlb, "--report", box}, box);
  unwrap("--report", "input .bin", {"-o", freshGlb, "--report", bin}, bin);
  unwrap("--report", "other output", {"-o", u, "--report", (f.unwrapped / "u.bin").string()}, "u.bin");
  unwrap("--report", "folder", {"-o", freshGlb, "--report", folderJson}, folderJson);
  unwrap("--report", "/proc", {"-o", freshGlb, "--report", proc}, proc);
  out.push_back({"samples", "OUTDIR", "a file", {"samples", box}, box});
  out.push_back({"samples", "OUTDIR", "/proc", {"samples", "/proc/irbake"}, "/proc/irbake"});
#ifdef IRVIEW_EXE
  auto view = command("irview", {(f.baked / "scene.gltf").string(), "--width", "16", "--height", "16"});
  auto walk = command("irview", {(f.frames / "scene.gltf").string(), "--width", "16", "--height", "16"});
  view("--screenshot", "input page (PNG)", {"--screenshot", (f.baked / "lightmap_0.png").string()}, "lightmap_0.png");
  view("--screenshot", "input page (EXR)", {"--screenshot", page}, page);
  view("--screenshot", "folder", {"--screenshot", folderPng}, folderPng);
  view("--screenshot", "/proc", {"--screenshot", procPng}, procPng);
  walk("--walkthrough", "input (frame 1)", {"--walkthrough", "2", "--screenshot", (f.frames / "walk.png").string()}, "walk_0001.png");
  walk("--walkthrough", "folder (frame 0)", {"--walkthrough", "2", "--screenshot", (f.root / "folder.png").string()},
       "folder_0000.png");
  walk("--walkthrough", "/proc", {"--walkthrough", "2", "--screenshot", procPng}, "/proc/irbake_0000.png");
#endif
  return out;
}

}  // namespace

TEST(OutputGuard, EveryCommandAndOutputOptionRefusesInputsOtherOutputsFoldersAndProc) {
  const Fixture& f = fixture();
  fs::create_directories(f.root / "folder_0000.png");
  const std::map<std::string, std::string> before = contents(f.root);
  int n = 0;
  for (const Case& c : cases(f)) {
    const std::string what = c.command + " " + c.option + " onto " + c.target;
#ifdef IRVIEW_EXE
    const std::string exe = c.command == "irview" ? IRVIEW_EXE : IRBAKE_EXE;
#else
    const std::string exe = IRBAKE_EXE;
#endif
    const IrbakeRun run = runProgram(exe, c.args, f.root.parent_path() / ("case_" + std::to_string(n++) + ".txt"));
    EXPECT_EQ(run.code, 2) << what << ":\n" << run.output;
    EXPECT_NE(run.output.find(c.named), std::string::npos) << what << " does not name " << c.named << ":\n" << run.output;
    EXPECT_EQ(run.output.find(".irbake-tmp"), std::string::npos) << what << ":\n" << run.output;
    EXPECT_EQ(contents(f.root), before) << what << " changed a file:\n" << run.output;
  }
  EXPECT_FALSE(fs::exists(f.root / "fresh")) << "a refused bake created its output folder";
}

TEST(OutputGuard, RefusedBakeWritesNoDumpAndAGoodOneWritesItWithTheOutputs) {
  const fs::path dir = scratch("dump");
  const std::string box = (irbake::testing::sampleScenes("output_guard_dump") / "cornell_box.gltf").string();
  const IrbakeRun refused = irbake::testing::runIrbakeIn(
      dir, {"bake", box, "-o", (dir / "o").string(), "--probes", "0", "--dump-config", (dir / "d.toml").string()});
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_FALSE(fs::exists(dir / "d.toml")) << "a refused bake wrote its --dump-config";
  const IrbakeRun good = irbake::testing::runIrbakeIn(
      dir, {"bake", box, "-o", (dir / "o").string(), "--quality", "preview", "--probes", "off", "--quiet", "--dump-config",
            (dir / "d.toml").string()});
  ASSERT_EQ(good.code, 0) << good.output;
  const std::string dump = fileText(dir / "d.toml");
  EXPECT_NE(dump.find("quality = \"preview\""), std::string::npos) << dump;
  EXPECT_NE(dump.find("what this bake chose"), std::string::npos) << dump;
  EXPECT_NE(fileText(dir / "o" / "report.json").find("d.toml"), std::string::npos) << "the report does not list the dump";
  // The dump's own folder is the user's, not the bake's: no manifest there.
  EXPECT_FALSE(fs::exists(dir / ".irbake-manifest"));
}

TEST(OutputGuard, StalePagesAreRemovedOnlyWhenTheManifestProvesIrbakeWroteThem) {
  const fs::path dir = scratch("stale");
  const std::string scene = (irbake::testing::sampleScenes("output_guard_stale") / "point_over_plane.gltf").string();
  const std::string out = (dir / "o").string();
  const std::vector<std::string> bake = {"bake", scene, "-o", out, "--quality", "preview", "--probes", "off", "--quiet"};
  std::vector<std::string> masked = bake;
  masked.insert(masked.end(), {"--light-mode", "point=shadowmask"});
  const IrbakeRun first = irbake::testing::runIrbakeIn(dir, masked);
  ASSERT_EQ(first.code, 0) << first.output;
  ASSERT_TRUE(fs::exists(dir / "o" / "lightmap_0_shadowmask.exr"));
  // A user's file and a user's folder named like pages this bake will not write.
  { std::ofstream(dir / "o" / "lightmap_1.exr") << "the user's own file"; }
  fs::create_directories(dir / "o" / "lightmap_2.exr");
  // The shadow-mask page the first bake wrote, edited since: not provably ours any more.
  const IrbakeRun second = irbake::testing::runIrbakeIn(dir, bake);
  ASSERT_EQ(second.code, 0) << second.output;
  EXPECT_FALSE(fs::exists(dir / "o" / "lightmap_0_shadowmask.exr")) << "irbake's own stale mask page stayed";
  EXPECT_FALSE(fs::exists(dir / "o" / "lightmap_0_shadowmask.png")) << "irbake's own stale mask page stayed";
  EXPECT_EQ(fileText(dir / "o" / "lightmap_1.exr"), "the user's own file");
  EXPECT_TRUE(fs::is_directory(dir / "o" / "lightmap_2.exr"));
  EXPECT_NE(second.output.find("left " + (dir / "o" / "lightmap_2.exr").string()), std::string::npos) << second.output;
  EXPECT_EQ(second.output.find("removed " + (dir / "o" / "lightmap_2.exr").string()), std::string::npos) << second.output;
  // A page of ours changed by hand since is kept too.
  const IrbakeRun third = irbake::testing::runIrbakeIn(dir, masked);
  ASSERT_EQ(third.code, 0) << third.output;
  { std::ofstream(dir / "o" / "lightmap_0_shadowmask.png", std::ios::app) << "edited"; }
  const IrbakeRun fourth = irbake::testing::runIrbakeIn(dir, bake);
  ASSERT_EQ(fourth.code, 0) << fourth.output;
  EXPECT_TRUE(fs::exists(dir / "o" / "lightmap_0_shadowmask.png")) << "an edited page was removed";
  EXPECT_FALSE(fs::exists(dir / "o" / "lightmap_0_shadowmask.exr"));
}

TEST(OutputGuard, LayersOfAnEarlierBakesOtherGroupsAreRemovedWhenOurs) {
  const fs::path dir = scratch("stale_layers");
  const std::string scene = (irbake::testing::sampleScenes("output_guard_stale_layers") / "point_over_plane.gltf").string();
  const fs::path o = dir / "o";
  const std::vector<std::string> bake = {"bake", scene, "-o", o.string(), "--quality", "preview", "--probes", "off",
                                         "--quiet", "--sun", "0.3,-1,0.2,2"};
  auto grouped = [&](const std::string& sunGroup) {
    std::vector<std::string> args = bake;
    args.insert(args.end(), {"--light-group", sunGroup + "=sun", "--light-group", "lamp=*"});
    return args;
  };
  const IrbakeRun first = irbake::testing::runIrbakeIn(dir, grouped("day"));
  ASSERT_EQ(first.code, 0) << first.output;
  for (const char* name : {"lightmap_0_day.exr", "lightmap_0_day.png", "lightmap_0_lamp.exr", "lightmap_0_lamp.png"})
    ASSERT_TRUE(fs::exists(o / name)) << name;
  { std::ofstream(o / "lightmap_0_mine.exr") << "the user's own file"; }
  // Another name for the sun's group: the old layer goes, the lamp's is written again, the user's file stays.
  const IrbakeRun second = irbake::testing::runIrbakeIn(dir, grouped("noon"));
  ASSERT_EQ(second.code, 0) << second.output;
  EXPECT_FALSE(fs::exists(o / "lightmap_0_day.exr")) << second.output;
  EXPECT_FALSE(fs::exists(o / "lightmap_0_day.png")) << second.output;
  EXPECT_TRUE(fs::exists(o / "lightmap_0_noon.exr"));
  EXPECT_TRUE(fs::exists(o / "lightmap_0_lamp.exr"));
  EXPECT_EQ(fileText(o / "lightmap_0_mine.exr"), "the user's own file");
  EXPECT_NE(second.output.find("left " + (o / "lightmap_0_mine.exr").string()), std::string::npos) << second.output;
  // No groups at all: every layer of ours goes; one edited since stays.
  { std::ofstream(o / "lightmap_0_lamp.png", std::ios::app) << "edited"; }
  const IrbakeRun third = irbake::testing::runIrbakeIn(dir, bake);
  ASSERT_EQ(third.code, 0) << third.output;
  for (const char* name : {"lightmap_0_noon.exr", "lightmap_0_noon.png", "lightmap_0_lamp.exr"})
    EXPECT_FALSE(fs::exists(o / name)) << name << " stayed\n" << third.output;
  EXPECT_TRUE(fs::exists(o / "lightmap_0_lamp.png")) << "an edited layer was removed";
  EXPECT_TRUE(fs::exists(o / "lightmap_0.exr"));
}

TEST(OutputGuard, SamplesNeverReplaceAUsersFileButRewriteTheirOwn) {
  const fs::path dir = scratch("samples");
  const IrbakeRun first = irbake::testing::runIrbakeIn(dir, {"samples", (dir / "s").string(), "--quiet"});
  ASSERT_EQ(first.code, 0) << first.output;
  const IrbakeRun again = irbake::testing::runIrbakeIn(dir, {"samples", (dir / "s").string(), "--quiet"});
  EXPECT_EQ(again.code, 0) << "samples refused to rewrite its own files:\n" << again.output;
  fs::create_directories(dir / "u");
  { std::ofstream(dir / "u" / "furnace.gltf") << "the user's furnace"; }
  const IrbakeRun user = irbake::testing::runIrbakeIn(dir, {"samples", (dir / "u").string(), "--quiet"});
  EXPECT_EQ(user.code, 2) << user.output;
  EXPECT_NE(user.output.find("furnace.gltf"), std::string::npos) << user.output;
  EXPECT_EQ(fileText(dir / "u" / "furnace.gltf"), "the user's furnace");
  EXPECT_FALSE(fs::exists(dir / "u" / "cornell_box.gltf")) << "a refused samples run wrote some of its files";
}
