// The bake's option table (app/bake_option_table.h) against the config files: every option, set to a value
// other than its default, is dumped by --dump-config, read back by --config and dumped again to the same
// text. The cases come from the table, so a new option is covered without a new test.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/bake_command.h"
#include "app/bake_option_table.h"
#include "common/command_line.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::app::OptionDescriptor;
using irbake::app::OptionKind;

namespace {

bool sameNumber(const std::string& a, const std::string& b) {
  return !a.empty() && !b.empty() && std::strtod(a.c_str(), nullptr) == std::strtod(b.c_str(), nullptr);
}

// Values of the text options, which the table gives no range for (SCENE and --output are in every case).
const std::map<std::string, std::vector<std::string>> kTextExamples = {
    {"report", {"elsewhere/report.json"}}, {"env", {"sky.hdr"}},  {"portable", {"portable.glb"}},
    {"probes", {"0.5"}},                   {"shard", {"1/2"}},    {"light-mode", {"sun=shadowmask", "*=indirect"}},
    {"atlas-from", {"day/scene.gltf"}},    {"light-group", {"day=sun,sky", "street=*"}}, {"only-group", {"street"}},
};

// A value the option accepts that is not its default: the range's ends, a choice, a list, or the examples
// above. Empty for SCENE and --output, which every case gives.
std::vector<std::string> nonDefaultValues(const OptionDescriptor& d) {
  const std::string fallback = irbake::app::defaultText(d);
  switch (d.kind) {
    case OptionKind::Flag: return {"true"};
    case OptionKind::Integer:
    case OptionKind::Number:
      for (double v : {d.lo, d.hi, d.lo + 1.0}) {
        const std::string text = irbake::cli::canonicalNumber(v);
        if (!sameNumber(text, fallback)) return {text};
      }
      break;
    case OptionKind::Choice:
      for (const std::string& c : d.choices)
        if (c != fallback) return {c};
      break;
    case OptionKind::NumberList: {  // 0,…,0,1,…,1: a direction, a colour and a box alike
      std::string list;
      for (size_t i = 0; i < d.listLength; ++i) list += std::string(i ? "," : "") + (i < d.listLength / 2 ? "0" : "1");
      return {list};
    }
    default:
      if (d.name == "SCENE" || d.name == "output") return {};
      if (auto it = kTextExamples.find(d.name); it != kTextExamples.end()) return it->second;
      break;
  }
  ADD_FAILURE() << "no value other than the default for --" << d.name << ": give it one in kTextExamples";
  return {};
}

std::string dumpOf(const irbake::app::Args& args) {
  const std::optional<irbake::app::BakeCommand> command = irbake::app::parseBakeCommand(args);
  EXPECT_TRUE(command.has_value());
  return command ? command->dumpText : "";
}

}  // namespace

TEST(Config, EveryOptionRoundTripsThroughDumpConfig) {
  const fs::path dir = irbake::testing::scratchFolder("option_table", "round_trip");
  const std::string scene = (dir / "scene.gltf").string(), out = (dir / "out").string();
  const std::string dumpFile = (dir / "dumped.toml").string();
  size_t cases = 0;
  for (const OptionDescriptor& d : irbake::app::bakeOptionTable()) {
    if (d.has(irbake::app::kNotInConfig) || d.has(irbake::app::kNotDumped)) continue;  // --config, --help-all, --dump-config
    SCOPED_TRACE("--" + d.name);
    irbake::app::Args args{scene, "-o", out, "--dump-config", dumpFile};
    for (const std::string& value : nonDefaultValues(d)) {
      if (d.kind == OptionKind::Flag) args.push_back("--" + d.name);
      else args.push_back("--" + d.name + "=" + value);
    }
    const std::string first = dumpOf(args);
    EXPECT_NE(first.find("\n" + d.configKey() + " = "), std::string::npos) << "not dumped as set:\n" << first;
    const fs::path file = dir / (d.name + ".toml");
    std::ofstream(file, std::ios::binary | std::ios::trunc) << first;
    const std::string second = dumpOf({"--config", file.string(), "--dump-config", dumpFile});
    EXPECT_EQ(second, first);
    ++cases;
  }
  EXPECT_GT(cases, 50u);
}

// Each --quality knob is an option of its own, and an option given on its own wins over the preset.
TEST(Config, EveryPresetKnobIsAnOptionThatWins) {
  size_t knobs = 0;
  for (const OptionDescriptor& d : irbake::app::bakeOptionTable()) {
    if (!d.preset) continue;
    ++knobs;
    SCOPED_TRACE("--" + d.name);
    const std::string value = nonDefaultValues(d).at(0);
    const std::string dump = dumpOf({"s.gltf", "-o", "out", "--quality", "high", "--" + d.name + "=" + value, "--dump-config", "d.toml"});
    EXPECT_NE(dump.find("\n" + d.name + " = " + value + "\n"), std::string::npos) << dump;
    const std::string preset = dumpOf({"s.gltf", "-o", "out", "--quality", "high", "--dump-config", "d.toml"});
    EXPECT_NE(preset.find("\n# " + d.name + " = "), std::string::npos) << preset;
    EXPECT_NE(preset.find(" (--quality high)"), std::string::npos) << preset;
  }
  EXPECT_EQ(knobs, 8u);
}
