// --config files as input: only a regular file of at most 1 MiB is read (a folder or /dev/zero is refused at
// once); messages quote at most a short, escaped excerpt of the file; a UTF-8 byte-order mark is skipped; every
// refused value names the file, the line and the key, irbake's own checks included; a repeated option
// (--light-mode) is one entry per value on the command line and an array in the file, and --dump-config's file
// reads back to the same bytes.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"
#include "testing/gltf_builder.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("config_file", name); }

// A floor under one point light named "lamp".
fs::path lampScene(const fs::path& dir) {
  irbake::GltfDocument doc =
      irbake::testing::meshDocument({{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {0, 2, 1, 0, 3, 2});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 3.0}, {"name", "lamp"}}};
  doc.root["extensionsUsed"] = {"KHR_lights_punctual"};
  doc.root["nodes"].push_back({{"translation", {0.2, 1.0, 0.1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["scenes"][0]["nodes"].push_back(1);
  irbake::testing::writeDocument(doc, dir / "lamp.gltf");
  return dir / "lamp.gltf";
}

const std::vector<std::string> kSmallBake = {"--texels-per-unit", "4", "--vpls", "16", "--backend", "embree", "--quiet"};

IrbakeRun run(const fs::path& dir, const std::string& log, std::vector<std::string> args) {
  return irbake::testing::runIrbakeLogged(args, dir / (log + ".txt"));
}

// irbake bake --config FILE SCENE -o DIR and the small bake's options.
IrbakeRun bakeWith(const fs::path& dir, const fs::path& config, const fs::path& scene, const std::string& out) {
  std::vector<std::string> args{"bake", "--config", config.string(), scene.string(), "-o", (dir / out).string()};
  args.insert(args.end(), kSmallBake.begin(), kSmallBake.end());
  return run(dir, out, args);
}

void write(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes; }

std::string modeOf(const fs::path& out, const std::string& key) {
  const nlohmann::json plan = nlohmann::json::parse(fileText(out / "report.json"))["plan"];
  return plan.contains(key) ? plan[key]["value"].get<std::string>() : "(no " + key + ")";
}

// Every byte prints: no control byte but the newline, no byte of invalid UTF-8 (here: none above 0x7F at all).
bool printable(const std::string& text) {
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n') || u >= 0x7F) return false;
  }
  return true;
}

}  // namespace

TEST(ConfigFile, OnlyARegularFileOfAtMostOneMebibyteIsRead) {
  const fs::path dir = scratch("not_a_file");
  const fs::path scene = lampScene(dir);
  fs::create_directories(dir / "folder.toml");
  const IrbakeRun folder = bakeWith(dir, dir / "folder.toml", scene, "folder");
  ASSERT_EQ(folder.code, 2) << folder.output;
  EXPECT_NE(folder.output.find((dir / "folder.toml").string() + ": --config names a folder"), std::string::npos) << folder.output;
  EXPECT_FALSE(fs::exists(dir / "folder" / "report.json"));
  const IrbakeRun zero = bakeWith(dir, "/dev/zero", scene, "zero");
  EXPECT_EQ(zero.code, 2) << zero.output;
  EXPECT_NE(zero.output.find("/dev/zero: --config needs a regular file"), std::string::npos) << zero.output;
  std::string comments;
  while (comments.size() <= (1u << 20)) comments += "# a comment line of a config file far too long to be one\n";
  write(dir / "large.toml", comments);
  const IrbakeRun large = bakeWith(dir, dir / "large.toml", scene, "large");
  EXPECT_EQ(large.code, 4) << large.output;
  EXPECT_NE(large.output.find("the config file is " + std::to_string(comments.size()) +
                              " bytes, more than the 1048576 (1 MiB) a config file may have"),
            std::string::npos)
      << large.output;
}

TEST(ConfigFile, MessagesQuoteAShortEscapedExcerptAndAByteOrderMarkIsSkipped) {
  const fs::path dir = scratch("excerpt");
  const fs::path scene = lampScene(dir);
  write(dir / "line.toml", std::string(300000, 'x') + "\n");
  const IrbakeRun line = bakeWith(dir, dir / "line.toml", scene, "line");
  EXPECT_EQ(line.code, 4) << line.output.substr(0, 400);
  EXPECT_LT(line.output.size(), 400u) << line.output.substr(0, 400);
  EXPECT_NE(line.output.find("line 1: expected key = value, got 'xxxxxxxx"), std::string::npos) << line.output.substr(0, 400);
  EXPECT_NE(line.output.find("…' (300000 bytes)"), std::string::npos) << line.output.substr(0, 400);

  write(dir / "binary.toml", std::string("seed = 1\n\x01\x02\xfe\xff\x00zz\x1b[2J\n", 20));
  const IrbakeRun binary = bakeWith(dir, dir / "binary.toml", scene, "binary");
  EXPECT_EQ(binary.code, 4) << binary.output;
  EXPECT_NE(binary.output.find("line 2: expected key = value, got '\\x01\\x02\\xFE\\xFF\\x00zz\\x1B[2J'"), std::string::npos)
      << binary.output;
  EXPECT_TRUE(printable(binary.output)) << binary.output;

  write(dir / "value.toml", "probes = \"" + std::string(100000, 'y') + "\"\n");
  const IrbakeRun value = bakeWith(dir, dir / "value.toml", scene, "value");
  EXPECT_EQ(value.code, 2) << value.output.substr(0, 400);
  EXPECT_LT(value.output.size(), 500u) << value.output.substr(0, 500);
  EXPECT_NE(value.output.find("line 1: key 'probes': "), std::string::npos) << value.output.substr(0, 400);

  write(dir / "bom.toml", "\xEF\xBB\xBFseed = 4\n");
  const IrbakeRun bom = bakeWith(dir, dir / "bom.toml", scene, "bom");
  ASSERT_EQ(bom.code, 0) << bom.output;
  EXPECT_EQ(nlohmann::json::parse(fileText(dir / "bom" / "report.json"))["options"]["seed"], "4");
  write(dir / "mark.toml", "seed = 4\n\xEF\xBB\xBFpaths = 8\n");  // not at the start: an invisible mark, shown escaped
  const IrbakeRun mark = bakeWith(dir, dir / "mark.toml", scene, "mark");
  EXPECT_EQ(mark.code, 4) << mark.output;
  EXPECT_NE(mark.output.find("line 2: '\\u{FEFF}paths' is not an option name"), std::string::npos) << mark.output;
}

TEST(ConfigFile, EveryRefusedValueNamesTheFileTheLineAndTheKey) {
  const fs::path dir = scratch("values");
  const fs::path scene = lampScene(dir);
  struct Case {
    std::string line, expect;
  };
  const std::vector<Case> cases = {
      {"probes = \"0\"", "line 2: key 'probes': --probes needs auto, off or a spacing in metres from 0.01 to 1e6 (got '0')"},
      {"sun = \"0,-1,0,-5\"", "line 2: key 'sun': --sun needs an irradiance E in (0, 1e20] W/m² (got '0,-1,0,-5')"},
      {"sky = \"1,1,1e30\"", "line 2: key 'sky': --sky needs three radiances in [0, 1e20]"},
      {"shard = \"3/2\"", "line 2: key 'shard': --shard needs K/N with 1 ≤ K ≤ N ≤ 1000000 (got '3/2')"},
      {"clamp = 1e-35", "line 2: key 'clamp': --clamp needs 0 (no clamp) or a bound in [1e-30, 1e30]"},
      {"probe-box = \"0,0,0,-1,1,1\"", "line 2: key 'probe-box': --probe-box needs X0,Y0,Z0,X1,Y1,Z1"},
      {"light-mode = [\"lamp=indirect\", \"lamp\"]", "line 2: key 'light-mode': --light-mode needs NAME=MODE"},
      {"env-intensity = 1e21", "line 2: key 'env-intensity': --env-intensity: must be a finite number in [0, 1e+20]"},
      {"seed = [\"1\"]", "line 2: key 'seed': takes one value, not an array"},
      {"light-mode = \"lamp=indirect\"\nlight-mode = \"*=baked\"", "line 3: key 'light-mode' is given twice"},
      // A name the scene does not have is found with the scene loaded: still file, line and key.
      {"light-mode = [\"lamp=indirect\", \"lantern=baked\"]",
       "line 2: key 'light-mode' ('lantern=baked'): no punctual light is named 'lantern' (its punctual lights: lamp)"}};
  for (const Case& c : cases) {
    write(dir / "c.toml", "quiet = true\n" + c.line + "\n");
    const IrbakeRun refused = bakeWith(dir, dir / "c.toml", scene, "o");
    EXPECT_NE(refused.code, 0) << c.line;
    EXPECT_NE(refused.output.find((dir / "c.toml").string() + ": " + c.expect), std::string::npos)
        << c.line << "\n" << refused.output;
    EXPECT_FALSE(fs::exists(dir / "o" / "report.json")) << c.line;
  }
}

TEST(ConfigFile, RepeatedLightModesComeFromTheFileAndTheDumpReplaysByteForByte) {
  const fs::path dir = scratch("repeated");
  const fs::path scene = lampScene(dir);
  // The file's light-mode takes one value: the SCENE after it on the command line stays the scene.
  write(dir / "one.toml", "light-mode = \"lamp=indirect\"\n");
  const IrbakeRun one = bakeWith(dir, dir / "one.toml", scene, "one");
  ASSERT_EQ(one.code, 0) << one.output;
  EXPECT_EQ(modeOf(dir / "one", "light-mode lamp #0"), "indirect");

  std::vector<std::string> args{"bake", scene.string(), "-o", (dir / "first").string(), "--sun", "0,-1,0.2,3",
                                "--light-mode", "sun=shadowmask", "--light-mode", "*=indirect",
                                "--dump-config", (dir / "dumped.toml").string()};
  args.insert(args.end(), kSmallBake.begin(), kSmallBake.end());
  const IrbakeRun first = run(dir, "first", args);
  ASSERT_EQ(first.code, 0) << first.output;
  EXPECT_EQ(modeOf(dir / "first", "light-mode lamp #0"), "indirect");
  EXPECT_EQ(modeOf(dir / "first", "light-mode sun #1"), "shadowmask");
  const std::string dumped = fileText(dir / "dumped.toml");
  EXPECT_NE(dumped.find("\nlight-mode = [\"sun=shadowmask\", \"*=indirect\"]\n"), std::string::npos) << dumped;

  const IrbakeRun again = run(dir, "again", {"bake", "--config", (dir / "dumped.toml").string(), "-o", (dir / "again").string()});
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(modeOf(dir / "again", "light-mode sun #1"), "shadowmask");
  for (const char* page : {"lightmap_0.exr", "lightmap_0_shadowmask.exr"}) {
    ASSERT_TRUE(fs::exists(dir / "first" / page)) << page;
    EXPECT_EQ(fileText(dir / "again" / page), fileText(dir / "first" / page)) << page;
  }
}
