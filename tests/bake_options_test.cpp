// How a user sets up a bake: --help that fits a screen and --help-all with every option, --quality presets,
// and a config file (--config) that gives the same bake as the command line, refused with file, line and key.
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("bake_options", name); }
fs::path samples() { return irbake::testing::sampleScenes("bake_options"); }
IrbakeRun runIrbake(const std::vector<std::string>& args, const fs::path& log) {
  return irbake::testing::runIrbakeLogged(args, log);
}

nlohmann::json report(const fs::path& out) { return nlohmann::json::parse(fileText(out / "report.json")); }

size_t lines(const std::string& text) { return static_cast<size_t>(std::count(text.begin(), text.end(), '\n')); }

}  // namespace

TEST(BakeOptions, HelpFitsAScreenAndHelpAllListsEveryOption) {
  const fs::path dir = scratch("help");
  const IrbakeRun help = runIrbake({"bake", "--help"}, dir / "help.txt");
  ASSERT_EQ(help.code, 0) << help.output;
  EXPECT_LE(lines(help.output), 45u) << help.output;
  for (const char* common : {"--output", "--quality", "--config", "--sun", "--sky", "--env", "--texels-per-unit",
                             "--directional", "--threads", "--quiet", "--help-all"})
    EXPECT_NE(help.output.find(common), std::string::npos) << common;
  EXPECT_EQ(help.output.find("--comp-refine"), std::string::npos) << "an expert knob in the short help";
  const IrbakeRun all = runIrbake({"bake", "--help-all"}, dir / "all.txt");
  ASSERT_EQ(all.code, 0) << all.output;
  for (const char* option : {"--paths", "--vpls", "--bounces", "--walk-split", "--vpl-importance", "--vpl-probes", "--vpl-keep",
                             "--max-texels", "--supersample", "--clamp", "--clamp-k", "--no-bias-compensation", "--comp-rays",
                             "--comp-refine", "--comp-ray-budget", "--comp-filter", "--final-gather", "--gather-rays",
                             "--gather-pre-rays", "--gather-ray-budget", "--gather-filter", "--gather-outliers", "--interleave", "--cube-face",
                             "--spp", "--sky-rays", "--sky-ray-budget", "--shadow-edge-samples", "--env-intensity",
                             "--env-rotation", "--backend", "--no-gltf", "--dump-config", "--verbose", "--shard", "--resume",
                             "--checkpoint-seconds", "--vpl-block", "--no-leak-control", "--no-dilate", "--no-seams"})
    EXPECT_NE(all.output.find(option), std::string::npos) << option << " missing from --help-all";
  EXPECT_NE(all.output.find("Final gather:"), std::string::npos) << all.output;
}

// Each preset sets the walk's paths and the stages' rays; an option given on its own still wins.
TEST(BakeOptions, QualityPresetsSetPathsAndRaysAndOwnOptionsWin) {
  const fs::path dir = scratch("quality");
  // Emitters: no final gather, so half the preset's paths are evaluated, resampled from a walk of 8x as many that
  // forks past bounce 1 (docs/units.md).
  const std::string scene = (samples() / "cornell_box.gltf").string();
  struct Case {
    std::vector<std::string> extra;
    int paths, compRays;
  };
  const std::vector<Case> cases = {{{"--quality", "preview"}, 256, 4},
                                   {{}, 2048, 16},
                                   {{"--quality", "high", "--paths", "300", "--comp-rays", "3"}, 300, 3}};
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path out = dir / std::string("o").append(std::to_string(i));  // append: GCC 12 warns falsely on "o" + string
    std::vector<std::string> args{"bake", scene, "-o", out.string(), "--texels-per-unit", "10", "--backend", "embree",
                                  "--comp-ray-budget", "0", "--quiet"};
    args.insert(args.end(), cases[i].extra.begin(), cases[i].extra.end());
    const IrbakeRun run = runIrbake(args, dir / "log.txt");
    ASSERT_EQ(run.code, 0) << run.output;
    const nlohmann::json r = report(out);
    EXPECT_EQ(r["vpls"]["paths"].get<int>(), cases[i].paths) << i;
    EXPECT_EQ(r["compensation"]["raysPerSample"].get<int>(), cases[i].compRays) << i;
  }
  const IrbakeRun bad = runIrbake({"bake", scene, "-o", (dir / "bad").string(), "--quality", "ultra"}, dir / "bad.txt");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--quality"), std::string::npos) << bad.output;
}

// A config file gives the command line's bake, byte for byte; the command line wins over it; --dump-config
// writes a file that reads back (from another folder) to the same bake.
TEST(BakeOptions, ConfigFileGivesTheSameBakeAndTheCommandLineWins) {
  const fs::path dir = scratch("config");
  fs::create_directories(dir / "level");
  fs::copy(samples(), dir / "level" / "samples");
  std::ofstream(dir / "level" / "bake.toml") << "# the level's bake\n[bake]\nscene = \"samples/cornell_box.gltf\"  # beside this file\n"
                                                "output = \"baked\"\ntexels-per-unit = 12\npaths = 256\nbackend = \"embree\"\n"
                                                "seed = 4\nquiet = true\n";
  const IrbakeRun fromFile = runIrbake({"bake", "--config", (dir / "level" / "bake.toml").string(), "--dump-config",
                                        (dir / "dumped.toml").string()}, dir / "file.txt");
  ASSERT_EQ(fromFile.code, 0) << fromFile.output;
  const IrbakeRun plain = runIrbake({"bake", (samples() / "cornell_box.gltf").string(), "-o", (dir / "plain").string(),
                                     "--texels-per-unit", "12", "--paths", "256", "--backend", "embree", "--seed", "4", "--quiet"},
                                    dir / "plain.txt");
  ASSERT_EQ(plain.code, 0) << plain.output;
  const std::string exr = fileText(dir / "plain" / "lightmap_0.exr");
  EXPECT_EQ(fileText(dir / "level" / "baked" / "lightmap_0.exr"), exr);
  EXPECT_EQ(report(dir / "level" / "baked")["options"]["seed"], "4");

  const std::string dumped = fileText(dir / "dumped.toml");
  EXPECT_NE(dumped.find("\nseed = 4\n"), std::string::npos) << dumped;
  EXPECT_NE(dumped.find("# gather-rays = 16 (--quality default)"), std::string::npos) << dumped;
  // What the bake chose where the options said auto: as entries that replay it, or stay auto with the choice.
  EXPECT_NE(dumped.find("\ninterleave = "), std::string::npos) << dumped;
  EXPECT_NE(dumped.find("\nclamp-k = 256\n"), std::string::npos) << dumped;  // the sample box has an emitter
  EXPECT_NE(dumped.find("\n# bounces = auto (chose "), std::string::npos) << dumped;
  EXPECT_EQ(dumped.find("\npaths = 256\npaths"), std::string::npos) << dumped;  // given once, not again
  fs::create_directories(dir / "elsewhere");
  fs::copy_file(dir / "dumped.toml", dir / "elsewhere" / "again.toml");
  fs::remove_all(dir / "level" / "baked");
  const IrbakeRun again = runIrbake({"bake", "--config", (dir / "elsewhere" / "again.toml").string()}, dir / "again.txt");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(fileText(dir / "level" / "baked" / "lightmap_0.exr"), exr);

  const IrbakeRun wins = runIrbake({"bake", "--config", (dir / "level" / "bake.toml").string(), "--seed", "0", "-o",
                                    (dir / "seed0").string()}, dir / "wins.txt");
  ASSERT_EQ(wins.code, 0) << wins.output;
  EXPECT_NE(fileText(dir / "seed0" / "lightmap_0.exr"), exr);
  EXPECT_FALSE(report(dir / "seed0")["options"].contains("seed"));
}

TEST(BakeOptions, BadConfigIsRefusedNamingFileLineAndKey) {
  const fs::path dir = scratch("bad_config");
  const std::string scene = (samples() / "cornell_box.gltf").string();
  struct Case {
    std::string line, expect;
    int code;
  };
  const std::vector<Case> cases = {{"colour = 3", "key 'colour': not an option", 2},
                                   {"paths = \"many\"", "key 'paths'", 2},
                                   {"paths = 0", "key 'paths'", 2},
                                   {"seed = -1", "key 'seed'", 2},
                                   {"directional = 3", "key 'directional': a flag takes true or false", 2},
                                   {"sun = \"0,-1\"", "key 'sun'", 2},
                                   {"texels-per-unit = twelve", "key 'texels-per-unit': the value must be", 4},
                                   {"just words", "expected key = value", 4},
                                   {"[render]", "only a [bake] table", 4}};
  for (const Case& c : cases) {
    const fs::path file = dir / "bad.toml";
    std::ofstream(file, std::ios::trunc) << "# first line\nquiet = true\n" << c.line << "\n";
    const IrbakeRun run = runIrbake({"bake", scene, "-o", (dir / "o").string(), "--config", file.string()}, dir / "log.txt");
    EXPECT_EQ(run.code, c.code) << c.line << ": " << run.output;
    EXPECT_NE(run.output.find(file.string() + ": line 3: "), std::string::npos) << c.line << ": " << run.output;
    EXPECT_NE(run.output.find(c.expect), std::string::npos) << c.line << ": " << run.output;
  }
  EXPECT_FALSE(fs::exists(dir / "o" / "scene.gltf"));
  const IrbakeRun missing = runIrbake({"bake", scene, "-o", (dir / "o").string(), "--config", (dir / "none.toml").string()},
                                      dir / "missing.txt");
  EXPECT_EQ(missing.code, 3) << missing.output;
}

// Every automatic choice is in the report's plan with its reason, and --dump-config writes each replayable one
// as an entry: the file reads back to the same bytes with nothing left to choose (the corner: a spot light, no
// emitter, so the final gather, the VPL importance pilot and the GL cube size are all chosen).
TEST(BakeOptions, DumpedConfigReplaysEveryAutomaticChoice) {
  const fs::path dir = scratch("plan");
  const std::string scene = (samples() / "corner.gltf").string();
  const IrbakeRun first = runIrbake({"bake", scene, "-o", (dir / "first").string(), "--quality", "preview", "--quiet",
                                     "--dump-config", (dir / "dumped.toml").string()}, dir / "first.txt");
  ASSERT_EQ(first.code, 0) << first.output;
  const nlohmann::json plan = report(dir / "first")["plan"];
  for (const char* key : {"backend", "final-gather", "paths", "interleave", "clamp-k", "vpl-importance", "texels-per-unit",
                          "bounces", "walk-split", "comp-refine"}) {
    ASSERT_TRUE(plan.contains(key)) << key << "\n" << plan.dump(1);
    EXPECT_TRUE(plan[key]["automatic"].get<bool>()) << key;
    EXPECT_FALSE(plan[key]["reason"].get<std::string>().empty()) << key;
  }
  EXPECT_EQ(plan["final-gather"]["value"], "on");
  EXPECT_EQ(plan["comp-refine"]["value"], 0);
  const std::string dumped = fileText(dir / "dumped.toml");
  for (const char* key : {"\nbackend = ", "\nfinal-gather = \"on\"", "\npaths = ", "\ninterleave = ", "\ntexels-per-unit = "})
    EXPECT_NE(dumped.find(key), std::string::npos) << key << "\n" << dumped;

  const IrbakeRun again = runIrbake({"bake", "--config", (dir / "dumped.toml").string(), "-o", (dir / "again").string()},
                                    dir / "again.txt");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(fileText(dir / "again" / "lightmap_0.exr"), fileText(dir / "first" / "lightmap_0.exr"));
  const nlohmann::json replayed = report(dir / "again")["plan"];
  for (const char* key : {"backend", "final-gather", "paths", "interleave", "texels-per-unit"})
    EXPECT_FALSE(replayed[key]["automatic"].get<bool>()) << key << ": given by the file";
}
