// A fuzz harness for the command lines of irbake (bake, merge, diff, info, unwrap, probe) and irview (headless
// --screenshot), for --config files, and for the files irbake reads back (partials for merge, checkpoints for
// resume, EXR pages for diff): seeded mutations of valid runs, each run as a user would.
// Every run must end with exit 0 or a documented error code and exactly one "<program>: error: ..." line, never
// a signal or a hang; a run that exits 0 writes no NaN; a damaged partial or checkpoint is never accepted; and
// no run changes an input: the files the valid runs read live in one folder, hashed (XXH3) before and after
// every run.
// IRBAKE_FUZZ_RUNS scales the run counts (default 1: under two minutes on two cores).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/checksum.h"
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

// A program under `timeout` (a hang is a finding: 124), run in `cwd` so that relative outputs land there.
IrbakeRun runProgram(const std::string& exe, std::vector<std::string> args, const fs::path& log, const fs::path& cwd) {
  args.insert(args.begin(), {"60", exe});
  std::string cmd = "cd '" + cwd.string() + "' && /usr/bin/timeout";
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

IrbakeRun runIrbake(const std::vector<std::string>& args, const fs::path& log) {
  return runProgram(IRBAKE_EXE, args, log, log.parent_path());
}

size_t occurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// The contract of every run: a documented exit code; an error is one line naming what is wrong.
void expectContract(const IrbakeRun& run, const std::string& what, const std::string& program = "irbake") {
  static const std::set<int> documented = {0, 2, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_TRUE(documented.count(run.code)) << what << " exited " << run.code << ":\n" << run.output.substr(0, 2000);
  if (run.code != 0) {
    EXPECT_EQ(occurrences(run.output, program + ": error: "), 1u) << what << ":\n" << run.output.substr(0, 2000);
  }
}

// NaN or Inf in a float accessor of a .gltf whose buffers are files beside it (positions, normals, UVs, probes).
bool hasNonFiniteFloats(const fs::path& gltf) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(fileText(gltf));
  } catch (const std::exception&) {
    return false;  // not a glTF the bake wrote (an output name a mutation chose): not ours to read
  }
  std::vector<std::string> buffers;
  for (const auto& b : doc.value("buffers", nlohmann::json::array()))
    buffers.push_back(b.contains("uri") ? fileText(gltf.parent_path() / b["uri"].get<std::string>()) : std::string());
  static const std::map<std::string, size_t> kComponents = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
  for (const auto& a : doc.value("accessors", nlohmann::json::array())) {
    if (a.value("componentType", 0) != 5126 || !a.contains("bufferView")) continue;
    const auto& view = doc["bufferViews"][a["bufferView"].get<size_t>()];
    const std::string& bytes = buffers.at(view["buffer"].get<size_t>());
    const size_t n = kComponents.at(a["type"].get<std::string>());
    const size_t stride = view.value("byteStride", size_t(4 * n));
    const size_t begin = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
    for (size_t e = 0; e < a["count"].get<size_t>(); ++e)
      for (size_t c = 0; c < n; ++c) {
        float v;
        const size_t at = begin + e * stride + 4 * c;
        if (at + 4 > bytes.size()) return true;  // an accessor past its buffer is as broken
        std::memcpy(&v, bytes.data() + at, 4);
        if (!std::isfinite(v)) return true;
      }
  }
  return false;
}

// Every EXR page in dir (or dir itself, a file) holds finite texels; every .gltf's float accessors are finite.
void expectFiniteOutputs(const fs::path& where, const std::string& what) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (fs::is_directory(where, ec)) {
    for (const auto& e : fs::directory_iterator(where, ec)) files.push_back(e.path());
  } else if (fs::is_regular_file(where, ec)) {
    files.push_back(where);
  }
  for (const fs::path& f : files) {
    if (f.extension() == ".gltf") {
      EXPECT_FALSE(hasNonFiniteFloats(f)) << what << ": NaN or Inf in " << f;
    }
    if (f.extension() != ".exr") continue;
    try {
      const irbake::Lightmap m = irbake::readExr(f);
      for (const auto& t : m.texels)
        ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)) << what << ": NaN in " << f;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": an output EXR that does not read back: " << f << ": " << e.what();
    }
  }
}

fs::path samples() { return irbake::testing::sampleScenes("cli_fuzz"); }

// Values a hostile user (or a broken script) puts where a value goes. The device files are reached through
// links in `dir`, so that an output aimed at one (the harness runs as root on CI) replaces the link, never
// the device; the file system's root is left out for the same reason.
std::vector<std::string> hostileValues(const fs::path& dir) {
  std::error_code ec;
  fs::create_symlink("/dev/null", dir / "null", ec);
  fs::create_symlink("/proc/self/mem", dir / "mem", ec);
  return {"", "-1", "0", "1", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "0x10", "010", "4294967297",
          "9223372036854775808", "1/0", "0/0", "2/1", "1/1", "1//2", "1,2", "1,2,3", "0,0,0,0", "1e300,0,0,5",
          "-1,-1,-1", "auto", "AUTO", " 3", "3 ", "%s%n", "\xff\xfe", std::string(5000, 'a'), "--", "-o", "--help",
          ".", "..", (dir / "null").string(), (dir / "mem").string(), "no/such/file.gltf", "out.glb", "out.gltf",
          "r.json", "*=indirect", "name:*=baked", "#0=shadowmask", "sun=indirect", "x.png", "x.exr"};
}

// The files every valid run reads, in one folder: the samples, a bake with probes (probe, irview, diff), the
// two shards of a bake (merge) and a config file. Hashed before and after each run.
class Inputs {
 public:
  explicit Inputs(const fs::path& root) : root_(root) {
    fs::create_directories(root_);
    fs::copy(samples(), root_ / "samples", fs::copy_options::recursive | fs::copy_options::skip_existing);
    const std::string scene = (root_ / "samples" / "point_over_plane.gltf").string();
    const std::vector<std::string> small = {"--texels-per-unit", "2", "--vpls", "16", "--backend", "embree", "--quiet"};
    auto bake = [&](const std::string& out, std::vector<std::string> extra) {
      std::vector<std::string> args{"bake", scene, "-o", (root_ / out).string()};
      args.insert(args.end(), small.begin(), small.end());
      args.insert(args.end(), extra.begin(), extra.end());
      const IrbakeRun r = runIrbake(args, root_.parent_path() / "inputs_log.txt");
      EXPECT_EQ(r.code, 0) << r.output;
    };
    bake("baked", {"--probes", "0.5"});
    bake("shard_1", {"--shard", "1/2"});
    bake("shard_2", {"--shard", "2/2"});
    std::ofstream(root_ / "bake.toml") << "# a level's bake\n[bake]\nscene = \"samples/point_over_plane.gltf\"\n"
                                          "texels-per-unit = 2\npaths = 16\nbackend = \"embree\"\nseed = 3\n"
                                          "sun = \"0,-1,0.3,2\"\nlight-mode = [\"sun=indirect\", \"*=baked\"]\n"
                                          "probes = \"off\"\nquiet = true\n";
    for (const auto& e : fs::recursive_directory_iterator(root_))
      if (e.is_regular_file()) hashes_[e.path()] = hash(e.path());
  }
  const fs::path& root() const { return root_; }
  fs::path operator/(const std::string& name) const { return root_ / name; }

  // Every input is as it was; anything a run added inside the folder (an output aimed at it) is removed.
  void expectUnchanged(const std::string& what) {
    std::vector<fs::path> added;
    for (const auto& e : fs::recursive_directory_iterator(root_))
      if (!hashes_.count(e.path()) && !e.is_directory()) added.push_back(e.path());
    for (const fs::path& p : added) fs::remove(p);
    for (const auto& [path, digest] : hashes_) {
      std::error_code ec;
      EXPECT_TRUE(fs::is_regular_file(path, ec) && hash(path) == digest) << what << " changed the input " << path;
    }
  }

 private:
  static uint64_t hash(const fs::path& p) {
    const std::string bytes = fileText(p);
    return irbake::checksum64(bytes.data(), bytes.size());
  }
  fs::path root_;
  std::map<fs::path, uint64_t> hashes_;
};

// least..least+2 mutations of a valid command line: a hostile value, a missing word, a repeated word, two words
// swapped.
std::vector<std::string> mutated(std::vector<std::string> args, const std::vector<std::string>& hostile,
                                 std::mt19937& rng, int least = 1) {
  const int mutations = least + static_cast<int>(rng() % 3);
  for (int m = 0; m < mutations && args.size() > 1; ++m) {
    const size_t at = 1 + rng() % (args.size() - 1);
    switch (rng() % 4) {
      case 0: args[at] = hostile[rng() % hostile.size()]; break;
      case 1: args.erase(args.begin() + static_cast<long>(at)); break;
      case 2: args.insert(args.begin() + static_cast<long>(at), args[rng() % args.size()]); break;
      case 3: std::swap(args[at], args[1 + rng() % (args.size() - 1)]); break;
    }
  }
  return args;
}

std::string describe(const std::string& program, const std::vector<std::string>& args) {
  std::string what = program;
  for (const auto& a : args) what += " [" + a.substr(0, 60) + "]";
  return what;
}

}  // namespace

// Mutated bake (options and --config), merge, diff, info, unwrap and probe command lines.
TEST(CliFuzz, MutatedCommandLinesKeepTheErrorContract) {
  const fs::path dir = scratch("args");
  Inputs in(dir / "in");
  const std::vector<std::string> hostile = hostileValues(dir);
  const std::string scene = (in / "samples/point_over_plane.gltf").string();
  const std::string out = (dir / "o").string();
  const std::vector<std::vector<std::string>> valid = {
      {"bake", scene, "-o", out, "--texels-per-unit", "2", "--vpls", "16", "--quiet"},
      {"bake", scene, "-o", out, "--texels-per-unit", "2", "--vpls", "16", "--backend", "embree",
       "--sun", "0,-1,0,2", "--sky", "0.1,0.1,0.1", "--seed", "3", "--clamp", "1", "--light-mode", "sun=indirect", "--quiet"},
      {"bake", scene, "-o", (dir / "s").string(), "--texels-per-unit", "2", "--vpls", "16", "--shard", "1/2", "--quiet"},
      {"bake", "--config", (in / "bake.toml").string(), "-o", out, "--dump-config", (dir / "dumped.toml").string()},
      {"merge", (in / "shard_1").string(), (in / "shard_2").string(), "-o", (dir / "m").string(), "--quiet"},
      {"diff", (in / "baked/lightmap_0.exr").string(), (in / "baked/lightmap_0.exr").string()},
      {"info", scene},
      {"unwrap", scene, "-o", (dir / "u.gltf").string(), "--texels-per-unit", "2", "--padding", "1"},
      {"probe", (in / "baked/scene.gltf").string(), "--at", "0,0.5,0", "--normal", "0,1,0"},
  };
  std::mt19937 rng(20261127);
  const int runs = 400 * runsScale();
  int succeeded = 0;
  for (int i = 0; i < runs; ++i) {
    const std::vector<std::string> args = mutated(valid[rng() % valid.size()], hostile, rng);
    const std::string what = describe("irbake", args);
    const IrbakeRun run = runIrbake(args, dir / "log.txt");
    succeeded += run.code == 0;
    expectContract(run, what);
    in.expectUnchanged(what);
    if (run.code == 0) {
      for (const char* output : {"o", "m", "u.gltf"}) expectFiniteOutputs(dir / output, what);
      if (args[0] == "probe" || args[0] == "diff") {
        EXPECT_EQ(run.output.find("nan"), std::string::npos) << what << ":\n" << run.output;
        EXPECT_EQ(run.output.find("inf"), std::string::npos) << what << ":\n" << run.output;
      }
    }
  }
  std::printf("%d of %d mutated command lines exited 0\n", succeeded, runs);
}

namespace {
// A config file's text with one damage: a line dropped, doubled or swapped, a value replaced by a hostile one
// (quoted or bare), bytes flipped, a cut, a byte-order mark, a NUL or a very long line.
std::string mutatedConfig(const std::string& text, const std::vector<std::string>& hostile, std::mt19937& rng) {
  std::vector<std::string> lines;
  for (size_t start = 0; start < text.size();) {
    const size_t end = text.find('\n', start);
    lines.push_back(text.substr(start, end - start));
    start = end == std::string::npos ? text.size() : end + 1;
  }
  const size_t at = rng() % lines.size();
  std::string out;
  switch (rng() % 8) {
    case 0: lines.erase(lines.begin() + static_cast<long>(at)); break;
    case 1: lines.insert(lines.begin() + static_cast<long>(at), lines[rng() % lines.size()]); break;
    case 2: std::swap(lines[at], lines[rng() % lines.size()]); break;
    case 3:
    case 4: {
      const size_t eq = lines[at].find('=');
      const std::string& v = hostile[rng() % hostile.size()];
      if (eq != std::string::npos)
        lines[at] = lines[at].substr(0, eq + 1) + (rng() % 2 ? " \"" + v + "\"" : " " + v);
      break;
    }
    case 5: lines[at] = "\xEF\xBB\xBF" + lines[at]; break;
    case 6: lines[at].insert(rng() % (lines[at].size() + 1), rng() % 2 ? std::string(1, '\0') : std::string(70000, 'z')); break;
    case 7: break;  // bytes below
  }
  for (const std::string& l : lines) out += l + "\n";
  if (rng() % 4 == 0 && !out.empty()) {
    const size_t byte = rng() % out.size();
    const char flip = static_cast<char>(1 + rng() % 255);
    // Not inside the output's path: a flipped byte there could name a folder outside the test's scratch folder.
    const size_t output = out.find("output =");
    const bool inOutput = output != std::string::npos && byte >= output && byte < out.find('\n', output);
    if (!inOutput) out[byte] = static_cast<char>(out[byte] ^ flip);
  }
  if (rng() % 8 == 0) out.resize(rng() % out.size());
  return out;
}
}  // namespace

// Mutated --config files: refused with one line naming the file, or a bake that writes no NaN; neither the file
// nor any other input changes.
TEST(CliFuzz, MutatedConfigFilesKeepTheErrorContract) {
  const fs::path dir = scratch("config");
  Inputs in(dir / "in");
  const std::vector<std::string> hostile = hostileValues(dir);
  const std::string good = "[bake]\nscene = \"" + (in / "samples/point_over_plane.gltf").string() + "\"\noutput = \"" +
                           (dir / "o").string() + "\"\ntexels-per-unit = 2\npaths = 16\nbackend = \"embree\"\nseed = 1\n"
                           "sun = \"0,-1,0,2\"\nsky = \"0.1,0.1,0.1\"\nlight-mode = [\"sun=shadowmask\", \"*=indirect\"]\n"
                           "clamp = 1\nprobes = \"off\"\nquiet = true\n";
  std::mt19937 rng(11);
  const int runs = 100 * runsScale();
  int succeeded = 0;
  const fs::path config = dir / "config" / "bake.toml";
  fs::create_directories(config.parent_path());
  for (int i = 0; i < runs; ++i) {
    const std::string text = mutatedConfig(good, hostile, rng);
    std::ofstream(config, std::ios::binary | std::ios::trunc) << text;
    const std::string what = "bake --config with:\n" + text.substr(0, 600);
    const IrbakeRun run = runProgram(IRBAKE_EXE, {"bake", "--config", config.string()}, dir / "log.txt", config.parent_path());
    succeeded += run.code == 0;
    expectContract(run, what);
    EXPECT_EQ(fileText(config), text) << what << ": the config file changed";
    in.expectUnchanged(what);
    if (run.code == 0) expectFiniteOutputs(dir / "o", what);
  }
  std::printf("%d of %d mutated config files baked\n", succeeded, runs);
}

// Mutated irview command lines (headless screenshots of a bake with probes): the same contract.
TEST(CliFuzz, MutatedViewerCommandLinesKeepTheErrorContract) {
#ifndef IRVIEW_EXE
  GTEST_SKIP() << "irview is not part of this build";
#else
  if (!fs::exists(IRVIEW_EXE)) GTEST_SKIP() << "irview is not built (" << IRVIEW_EXE << "): cmake --build build --target irview";
  const fs::path dir = scratch("viewer");
  Inputs in(dir / "in");
  const std::vector<std::string> hostile = hostileValues(dir);
  const std::string scene = (in / "baked/scene.gltf").string();
  const std::string png = (dir / "shot.png").string(), exr = (dir / "shot.exr").string();
  const std::vector<std::vector<std::string>> valid = {
      {scene, "--screenshot", png, "--width", "48", "--height", "32"},
      {scene, "--screenshot", exr, "--width", "40", "--height", "24", "--view", "lightmap", "--exposure", "1"},
      {scene, "--screenshot", png, "--width", "32", "--height", "32", "--eye", "0,2,3", "--target", "0,0,0", "--fov", "60"},
      {scene, "--screenshot", png, "--width", "32", "--height", "24", "--view", "charts", "--lightmap-mode", "l0"},
      {scene, "--screenshot", png, "--width", "24", "--height", "24", "--walkthrough", "2"},
  };
  std::mt19937 rng(5);
  const int runs = 80 * runsScale();
  int succeeded = 0;
  for (int i = 0; i < runs; ++i) {
    std::vector<std::string> args = valid[rng() % valid.size()];
    args.insert(args.begin(), "irview");  // mutations keep word 0
    args = mutated(args, hostile, rng, 0);  // a third valid: each mutation of irview's few words mostly refuses
    args.erase(args.begin());
    const std::string what = describe("irview", args);
    const IrbakeRun run = runProgram(IRVIEW_EXE, args, dir / "log.txt", dir);
    succeeded += run.code == 0;
    expectContract(run, what, "irview");
    in.expectUnchanged(what);
    if (run.code == 0) expectFiniteOutputs(exr, what);
  }
  std::printf("%d of %d mutated irview command lines exited 0\n", succeeded, runs);
#endif
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
