// Every option of `irbake bake` in one table: its names, kind, range, group, help, where its value goes and
// which --quality knob it is. The table builds the command line (CLI11), applies the presets, reads and writes
// config files (--config, --dump-config), picks the options that go into the report and the options hash, and
// lends `irbake unwrap` the options it shares with the bake. A new option is one row here.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/bake_command.h"
#include "app/quality.h"

namespace irbake::app {

// What CLI11 writes that is not a BakeCommand field as such (turned into options by applyArguments).
struct BakeArguments {
  std::vector<std::string> scenes;
  std::string backend = "auto", shard, finalGather = "auto", quality = "default";
  std::string config, dumpConfig;  // --config FILE (read before parsing), --dump-config FILE
  std::string sun, sky, env;       // --sun, --sky, --env as given (BakeCommand::lights once checked)
  std::string probes = "auto", probeBox;  // --probes auto|off|SPACING, --probe-box as given
  std::vector<std::string> lightModes;  // --light-mode NAME=MODE as given
  std::vector<std::string> lightGroups;  // --light-group NAME=LIGHTS as given
  std::string lightModeOrigin;          // "FILE: line N: key 'light-mode'" when the config file gave them
  double envIntensity = 1.0, envRotation = 0.0;
  bool helpAll = false;
  long long seed = 0;
  double tpu = 0.0, clamp = 0.0, vplImportance = 0.0;  // 0: auto
  int bounces = -1, interleave = 0, cubeFace = 0, compFilter = -1, walkSplit = 0, paths = 0;  // "auto" as cli::integerOrAuto writes it (kept for the options hash)
  bool noLeakControl = false, noDilate = false, noSeams = false;
  bool noBiasCompensation = false, biasCompensation = false;
  CLI::Option* shardOption = nullptr;  // set by bakeApp: whether --shard and --clamp were given
  CLI::Option* clampOption = nullptr;
  std::string clampText() const { return clampOption && !clampOption->results().empty() ? clampOption->results()[0] : ""; }
};

// --portable given without a file name: this name in OUTDIR.
constexpr const char* kPortableName = "portable.glb";

// Light from the command line: at most this much (W/m², W/(m² sr)), so sums over the bake stay finite in float.
constexpr double kLargestLight = 1e20;

// Where CLI11 writes a parsed value.
using OptionField =
    std::variant<int*, long long*, size_t*, double*, float*, bool*, std::string*, std::vector<std::string>*>;

enum class OptionKind {
  Flag,       // no value: true when given
  Integer,    // an integer in [lo, hi]
  Number,     // a finite number in [lo, hi]
  Choice,     // one of choices
  NumberList, // listLength numbers, "x,y,z"
  Text,       // any text (a path, or a value irbake checks itself)
  Repeated,   // text, once per time the option is given (an array in a config file)
};

enum OptionTraits : unsigned {
  kNoTraits = 0,
  kAutomatic = 1u << 0,    // takes "auto" (the bake decides): a dump shows its default as auto
  kPath = 1u << 1,         // a file: read from the config file's folder when relative, dumped absolute
  kNotResult = 1u << 2,    // says where or how to write, not what: not in the result options or their hash
  kPresence = 1u << 3,     // given at all changes the result, even at the default value (--clamp 0: no clamp)
  kNotInConfig = 1u << 4,  // refused in a config file and not dumped (--config, --help-all)
  kNotDumped = 1u << 5,    // read from a config file but not written to a dump (--dump-config)
  kReplayable = 1u << 6,   // what the bake chose for auto, given explicitly, makes the same bake: a dump's tail
                           // sets it (automaticChoices)
};

struct OptionDescriptor {
  std::string names;     // as CLI11 takes them: "--paths,--vpls", "-o,--output", "SCENE"
  std::string name;      // the long name without dashes, as a config file and the report use it ("SCENE": scene)
  OptionKind kind = OptionKind::Text;
  double lo = 0.0, hi = 0.0;         // Integer and Number: the range
  double autoValue = 0.0;            // with kAutomatic: what "auto" is written as (Integer and Number)
  std::vector<std::string> choices;  // Choice
  size_t listLength = 0;             // NumberList
  std::string group;                 // "Options" (the short --help) or the stage's group in --help-all
  std::string help;
  std::string typeName;              // the value's placeholder in the help ("" for CLI11's own)
  unsigned traits = kNoTraits;
  std::function<OptionField(BakeCommand&, BakeArguments&)> field;  // where the value goes; its initial value
                                                                    // is the default
  std::function<long long(const QualityPreset&)> preset;  // the --quality knob it overrides (empty: none)
  std::string valueWhenBare;  // Text: may be given without a value, which then is this ("": a value is needed)

  bool has(OptionTraits t) const { return (traits & t) != 0; }
  bool isFlag() const { return kind == OptionKind::Flag; }
  // The key of a config file and of the report's options: name, "scene" for SCENE.
  std::string configKey() const { return name == "SCENE" ? "scene" : name; }
};

// Every option of `irbake bake`, in the order --help lists them.
const std::vector<OptionDescriptor>& bakeOptionTable();
// The option of that name (without dashes; "SCENE" or "scene" for the scene); nullptr when there is none.
const OptionDescriptor* findBakeOption(const std::string& name);

// Adds the option to app with its names, help, range and placeholder, its value written to field.
CLI::Option* addOption(CLI::App& app, const OptionDescriptor& option, OptionField field);

// The option's default: its field's initial value as CLI11 writes it ("" for an empty text).
std::string defaultText(const OptionDescriptor& option);
// The option in an app bakeApp made.
const CLI::Option* givenOption(const CLI::App& app, const OptionDescriptor& option);
// What the option was given as: its values, comma-separated.
std::string joinedResults(const CLI::Option& option);

// Every option of `irbake bake`, grouped, written into command and arguments.
std::unique_ptr<CLI::App> bakeApp(BakeCommand& command, BakeArguments& arguments);

// The knobs the --quality preset sets, where their own option is not given.
void applyQuality(const CLI::App& app, const QualityPreset& preset, BakeCommand& command, BakeArguments& arguments);

}  // namespace irbake::app
