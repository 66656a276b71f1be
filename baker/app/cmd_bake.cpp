// irbake bake SCENE -o OUTDIR [options]: the whole bake, outputs in OUTDIR; or one shard of it (--shard),
// or the rest of one that was killed (--resume).
#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <memory>
#include <string>
#include <type_traits>

#include <tbb/global_control.h>

#include "app/bake_command.h"
#include "app/bake_config.h"
#include "app/bake_option_table.h"
#include "app/quality.h"
#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "common/excerpt.h"
#include "common/file_paths.h"
#include "common/log.h"
#include "common/output_guard.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "pipeline/backend_choice.h"
#include "pipeline/bake.h"
#include "pipeline/light_groups.h"
#include "pipeline/only_group.h"
#include "export/light_layers.h"
#include "pipeline/vpl_sum_file.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/interleave/interleaved_sampling.h"
#include "transport/geometry_term.h"
#include "common/atomic_file.h"
#include "scene/gltf_loader.h"
#include "scene/scene_files.h"
#include "scene/scene_limits.h"

namespace irbake::app {

namespace {

// The smallest --clamp bound: below it the bound is 0 in single precision.
constexpr double kSmallestClamp = 1e-30;
// --sun, --sky and --env as light a bake can use: a direction that is not zero (any length), amounts in
// [0, kLargestLight], not both a sky and a map. Throws Error(Usage) naming the option.
LightAdditions lightArguments(const BakeArguments& a) {
  LightAdditions lights;
  if (!a.sun.empty()) {
    const std::vector<double> d = cli::parseNumberList(a.sun);
    const double longest = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
    if (!(longest > 0.0)) throw Error(ErrorCode::Usage, "", "--sun needs a non-zero direction DX,DY,DZ (got '" + a.sun + "')");
    if (!(d[3] > 0.0) || d[3] > kLargestLight)
      throw Error(ErrorCode::Usage, "", "--sun needs an irradiance E in (0, 1e20] W/m² (got '" + a.sun + "')");
    const glm::dvec3 direction = glm::normalize(glm::dvec3(d[0], d[1], d[2]) / longest);
    lights.sun = directionalLight(glm::vec3(direction), static_cast<float>(d[3]));
  }
  if (!a.sky.empty()) {
    const std::vector<double> L = cli::parseNumberList(a.sky);
    for (double v : L)
      if (!(v >= 0.0) || v > kLargestLight)
        throw Error(ErrorCode::Usage, "", "--sky needs three radiances in [0, 1e20] W/(m² sr) (got '" + a.sky + "')");
    lights.sky = glm::vec3(L[0], L[1], L[2]);
  }
  if (!a.env.empty() && lights.sky) throw Error(ErrorCode::Usage, "", "--sky and --env exclude each other");
  lights.environment = a.env;
  lights.environmentIntensity = static_cast<float>(a.envIntensity);
  lights.environmentRotation = static_cast<float>(a.envRotation);
  return lights;
}

// --probes auto|off|SPACING and --probe-box into the probe stage's options. Throws Error(Usage) naming the option.
void probeArguments(const BakeArguments& a, ProbeOptions& o) {
  o.enabled = a.probes != "off";
  if (o.enabled && a.probes != "auto") {
    char* end = nullptr;
    const double spacing = std::strtod(a.probes.c_str(), &end);
    if (a.probes.empty() || *end != '\0' || !(static_cast<float>(spacing) >= kMinProbeSpacing) || !(spacing <= 1e6))
      throw Error(ErrorCode::Usage, "", "--probes needs auto, off or a spacing in metres from 0.01 to 1e6 (got '" + a.probes + "')");
    o.spacing = static_cast<float>(spacing);
  }
  if (!a.probeBox.empty()) {
    // Checked in double before the conversion to float: 1e300 would become Inf, and a box beyond the scene's
    // coordinates would start the probes' rays where Embree aborts.
    const std::vector<double> b = cli::parseNumberList(a.probeBox);
    for (double v : b)
      if (!(std::abs(v) <= kMaxSceneCoordinate))
        throw Error(ErrorCode::Usage, "", "--probe-box needs coordinates within the supported ±1e9 m (got '" + a.probeBox + "')");
    Bounds3 box;
    box.min = glm::vec3(b[0], b[1], b[2]);
    box.max = glm::vec3(b[3], b[4], b[5]);
    if (!(box.min.x <= box.max.x && box.min.y <= box.max.y && box.min.z <= box.max.z))
      throw Error(ErrorCode::Usage, "", "--probe-box needs X0,Y0,Z0,X1,Y1,Z1 with each minimum ≤ its maximum (got '" + a.probeBox + "')");
    if (!(box.min.x < box.max.x && box.min.y < box.max.y && box.min.z < box.max.z))
      throw Error(ErrorCode::Usage, "", "--probe-box needs a size on every axis (got '" + a.probeBox +
                                            "'): a size below the spacing gives one layer of probes there");
    o.box = box;
  }
}

bool sameValue(const std::string& a, const std::string& b) {
  if (a == b) return true;
  char* endA = nullptr;
  char* endB = nullptr;
  const double x = std::strtod(a.c_str(), &endA), y = std::strtod(b.c_str(), &endB);
  return !a.empty() && !b.empty() && *endA == 0 && *endB == 0 && x == y;
}

// The options that change the result, as name -> value: what CLI11 parsed (the validators write numbers
// canonically), less any option given at its default, so "--seed 0" or "--vpls auto" is the bake without
// it. Partials and checkpoints carry it and its hash; a refused resume names the options that differ.
nlohmann::json resultOptions(const CLI::App& app) {
  nlohmann::json options = nlohmann::json::object();
  for (const OptionDescriptor& d : bakeOptionTable()) {
    const CLI::Option* option = givenOption(app, d);
    if (option->count() == 0 || d.has(kNotResult)) continue;
    const std::string value = d.isFlag() ? "true" : joinedResults(*option);
    if (!d.has(kPresence) && !d.isFlag() && sameValue(value, defaultText(d))) continue;
    options[d.name] = value;
  }
  return options;
}

// The checks of single option values that CLI11 cannot make (--shard, --clamp, --sun, --sky, --probes,
// --probe-box, --light-mode), their results into the command. Throws Error(Usage) naming the option; a config
// file's entry is checked with them on its own, so that its refusal names the file, the line and the key.
void checkOptionValues(BakeCommand& command, const BakeArguments& a) {
  BakeOptions& o = command.options;
  if (a.shardOption->count() > 0) {
    long long k = 0, n = 0;
    const size_t slash = a.shard.find('/');
    const bool parsed = slash != std::string::npos && cli::parseWholeNumber(a.shard.substr(0, slash), k) &&
                        cli::parseWholeNumber(a.shard.substr(slash + 1), n);
    if (!parsed || n < 1 || n > 1000000 || k < 1 || k > n)
      throw Error(ErrorCode::Usage, "", "--shard needs K/N with 1 ≤ K ≤ N ≤ 1000000 (got '" + a.shard + "')");
    command.shardIndex = static_cast<int>(k);
    command.shardCount = static_cast<int>(n);
  }
  if (a.clampOption->count() > 0 && a.clamp > 0.0 && a.clamp < kSmallestClamp)
    throw Error(ErrorCode::Usage, "", "--clamp needs 0 (no clamp) or a bound in [1e-30, 1e30] 1/m² (got " + a.clampText() + ")");
  command.lights = lightArguments(a);
  probeArguments(a, o.probes);
  for (const std::string& entry : a.lightModes) {
    const size_t eq = entry.rfind('=');
    LightModeRequest request;
    if (eq == std::string::npos || eq == 0 || !parseLightMode(entry.substr(eq + 1), request.mode))
      throw Error(ErrorCode::Usage, "", "--light-mode needs NAME=MODE with MODE baked, indirect or shadowmask (got " +
                                            quotedExcerpt(entry) + ")");
    request.light = entry.substr(0, eq);
    request.origin = a.lightModeOrigin;
    o.lightModes.push_back(request);
  }
  for (const std::string& entry : a.lightGroups) {
    const size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size())
      throw Error(ErrorCode::Usage, "", "--light-group needs NAME=LIGHTS, LIGHTS comma-separated (got " + quotedExcerpt(entry) + ")");
    LightGroupRequest request;
    request.name = entry.substr(0, eq);
    for (size_t at = eq + 1; at <= entry.size();) {
      const size_t comma = std::min(entry.find(',', at), entry.size());
      if (comma == at) throw Error(ErrorCode::Usage, "", "--light-group " + quotedExcerpt(entry) + ": an empty light name");
      request.sources.push_back(entry.substr(at, comma - at));
      at = comma + 1;
    }
    o.lightGroups.push_back(request);
  }
  if (!o.onlyGroup.empty() && !validLayerName(o.onlyGroup))
    throw Error(ErrorCode::Usage, "", "--only-group " + quotedExcerpt(o.onlyGroup) + ": a group name is 1 to 64 of A-Z a-z 0-9 _ -");
  if (!o.lightGroups.empty() && command.shardIndex > 0)
    throw Error(ErrorCode::Usage, "", "--light-group bakes each group apart: --shard does not split them yet");
}

// The parsed arguments as options; throws Error(Usage) for values and combinations CLI11 cannot check.
void applyArguments(BakeCommand& command, const BakeArguments& a) {
  BakeOptions& o = command.options;
  checkOptionValues(command, a);
  if (command.noGltf) o.probes.enabled = false;  // the probes live in the glTF: none to write them to
  if (a.scenes.size() != 1)
    throw Error(ErrorCode::Usage, "", "bake needs exactly one SCENE (got " + std::to_string(a.scenes.size()) +
                                          "); see 'irbake bake --help'");
  if (command.out.empty()) throw Error(ErrorCode::Usage, "", "bake needs -o OUTDIR");
  command.scene = a.scenes[0];
  o.backend = parseBackend(a.backend);
  o.finalGather = a.finalGather == "on"     ? FinalGatherMode::On
                  : a.finalGather == "auto" ? FinalGatherMode::Auto
                                            : FinalGatherMode::Off;
  o.walk.seed = static_cast<uint32_t>(a.seed);
  o.atlas.texelsPerUnit = a.tpu;
  o.texels.leakControl = !a.noLeakControl;
  if (a.bounces >= 0) o.walk.maxBounces = a.bounces;
  if (a.walkSplit > 0) o.walk.split = a.walkSplit;
  if (a.vplImportance >= 1.0) o.vplImportance.candidateFactor = a.vplImportance;
  else o.vplImportance.candidateFactor.reset();  // auto
  if (a.interleave > 0) o.interleave = a.interleave;
  if (a.compFilter >= 0) o.compensation.filterRadius = a.compFilter;
  if (a.cubeFace > 0) o.gl.cubeFaceSize = a.cubeFace;
  // Where the final gather runs, the preset's pathsUnderGather (app/quality.cpp).
  const QualityPreset& preset = *findQualityPreset(a.quality);
  o.walk.paths = a.paths > 0 ? a.paths : preset.paths;
  if (a.paths == 0) o.finalGatherPaths = preset.pathsUnderGather;
  if (a.clampOption->count() > 0) {  // --clamp 0: no clamp; none given: derived
    o.clamp = a.clamp > 0.0 ? ClampMode::Fixed : ClampMode::Off;
    o.clampBound = static_cast<float>(a.clamp);
  }
  o.eval.biasCompensation = !a.noBiasCompensation;  // on by default; --bias-compensation kept
  o.postDilate = !a.noDilate;
  o.postSeams = !a.noSeams;
  if (command.shardIndex > 0 && !command.portable.empty())
    throw Error(ErrorCode::Usage, "", "--shard writes only a partial: give --portable to 'irbake merge'");
  if (command.shardIndex > 0 && namesGltfFile(command.out))
    throw Error(ErrorCode::Usage, "", "--shard writes a partial into a folder: give -o OUTDIR, not a glTF name");
  if (o.directional && o.backend == BackendKind::Reference)
    throw Error(ErrorCode::Usage, "", "--directional needs a VPL backend (gl, embree or auto), not reference");
  if (command.shardIndex > 0 && o.backend == BackendKind::Reference)
    throw Error(ErrorCode::Usage, "", "--shard splits the VPLs: the reference backend has none (use gl, embree or auto)");
  if (o.errorEstimate.targetError > 0.0 || o.errorEstimate.errorMap) o.errorEstimate.enabled = true;
  if (o.errorEstimate.enabled && (command.shardIndex > 0 || command.resume))
    throw Error(ErrorCode::Usage, "", "--estimate-error and --target-error need the whole bake in one process "
                                      "(the halves' sums are not in partials or checkpoints): drop --shard / --resume");
}

}  // namespace

namespace {

// "--name value" or "--name=value" in args: the value ("" when absent).
std::string argumentValue(const Args& args, const std::string& name) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == name && i + 1 < args.size()) return args[i + 1];
    if (args[i].rfind(name + "=", 0) == 0) return args[i].substr(name.size() + 1);
  }
  return {};
}

std::string withExcerpt(std::string message, const std::string& value) {
  const std::string shown = quotedExcerpt(value);
  if (!value.empty() && shown != "'" + value + "'")
    for (size_t at = message.find(value); at != std::string::npos; at = message.find(value, at)) {
      size_t begin = at, end = at + value.size();
      if (begin > 0 && message[begin - 1] == '\'' && end < message.size() && message[end] == '\'') --begin, ++end;
      message.replace(begin, end - begin, shown);
      at = begin + shown.size();
    }
  return printableExcerpt(message, 400);
}

// Arguments for a config file's entries, each checked alone against the options and irbake's own checks of
// their values (unknown keys, wrong types, out-of-range and refused values name the file, the line and the
// key); entries the command line also sets are left out (the command line wins). lightModeOrigin: where the
// file's light-mode entry is, when it is used.
Args configArguments(const std::filesystem::path& file, const Args& commandLine, std::string& lightModeOrigin) {
  const std::vector<ConfigEntry> entries = readConfigFile(file);
  BakeCommand probeCommand;
  BakeArguments probeArguments;
  std::unique_ptr<CLI::App> given = bakeApp(probeCommand, probeArguments);
  cli::parse(*given, commandLine);
  const std::filesystem::path folder = file.parent_path();
  Args out;
  for (const ConfigEntry& e : entries) {
    const std::string line = "line " + std::to_string(e.line) + ": key " + quotedExcerpt(e.key);
    auto fail = [&](const std::string& what) { throw Error(ErrorCode::Usage, file.string(), line + ": " + what); };
    const OptionDescriptor* d = findBakeOption(e.key);
    if (!d || d->has(kNotInConfig)) fail("not an option of 'irbake bake' (see 'irbake bake --help-all')");
    if (givenOption(*given, *d)->count() > 0) continue;
    if (e.array && d->kind != OptionKind::Repeated) fail("takes one value, not an array (only light-mode and light-group are repeated)");
    const bool positional = d->name == "SCENE";
    const std::string name = positional ? d->name : "--" + d->name;
    Args words;
    for (std::string value : e.array ? e.items : std::vector<std::string>{e.value}) {
      if (d->has(kPath) && !value.empty() && std::filesystem::path(value).is_relative())
        value = (folder / value).lexically_normal().string();
      if (d->isFlag()) {
        if (value != "true" && value != "false") fail("a flag takes true or false, got " + quotedExcerpt(value));
        if (value == "true") words.push_back(name);
      } else {
        words.push_back(positional ? value : name + "=" + value);  // one word: a value may start with '-'
      }
    }
    BakeCommand checkCommand;
    BakeArguments checkArguments;
    std::unique_ptr<CLI::App> check = bakeApp(checkCommand, checkArguments);
    try {
      cli::parse(*check, words);
      checkOptionValues(checkCommand, checkArguments);
    } catch (const Error& error) {
      std::string message = error.what();
      for (const std::string& value : e.array ? e.items : std::vector<std::string>{e.value}) message = withExcerpt(message, value);
      fail(message);
    }
    if (d->name == "light-mode") lightModeOrigin = file.string() + ": " + line;
    out.insert(out.end(), words.begin(), words.end());
  }
  return out;
}

// An option not given, as a dump's comment shows it: the value the bake uses, "auto" where it decides.
std::string unsetValue(const OptionDescriptor& d, const QualityPreset& preset, BakeCommand& command, BakeArguments& a) {
  if (d.name == "paths")
    return "auto (" + std::to_string(preset.paths) + ", or " + std::to_string(preset.pathsUnderGather) +
           " under the final gather, or " + std::to_string(preset.paths / 2) + " evaluated of 8x as many walked without it)";
  if (d.name == "clamp") return "derived from the scene (0: no clamp)";
  if (d.preset) {
    std::string value;
    std::visit(
        [&value](auto* target) {
          using T = std::remove_pointer_t<decltype(target)>;
          if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) value = std::to_string(*target);
        },
        d.field(command, a));
    return value + " (--quality " + preset.name + ")";
  }
  if (d.has(kAutomatic)) return "auto";
  if (d.isFlag()) return "false";
  const std::string value = defaultText(d);
  return value.empty() ? "none" : value;
}

// Every option of the parsed bake as config entries: the given ones as entries (paths absolute), the rest
// as comments with the value the bake uses ("auto" where it decides, the --quality preset's knobs), so the
// file reads back to the same bake and still shows every knob.
std::vector<ConfigEntry> effectiveOptions(const CLI::App& app, BakeCommand& command, BakeArguments& a) {
  const QualityPreset& preset = *findQualityPreset(a.quality);
  std::vector<ConfigEntry> entries;
  for (const OptionDescriptor& d : bakeOptionTable()) {
    if (d.has(kNotInConfig) || d.has(kNotDumped)) continue;
    const CLI::Option* option = givenOption(app, d);
    if (option->count() > 0) {
      if (d.kind == OptionKind::Repeated) {
        entries.push_back({d.configKey(), "", 0, true, option->results()});  // one item per time it was given
        continue;
      }
      std::string value = d.isFlag() ? "true" : joinedResults(*option);
      if (d.name == "portable") value = portableOutputPath(command.out, value).string();  // where it is written
      if (d.has(kPath)) value = std::filesystem::absolute(value).lexically_normal().string();
      entries.push_back({d.configKey(), value, 0, false, {}});
      continue;
    }
    entries.push_back({"# " + d.name, unsetValue(d, preset, command, a), 0, false, {}});
  }
  return entries;
}

}  // namespace

PendingFile dumpedConfigFile(const std::string& file, const std::string& text) {
  return {file, [file, text](const std::filesystem::path& temp) {
            std::ofstream out(temp, std::ios::binary);
            out << text;
            out.close();
            if (!out) throw Error(ErrorCode::Io, file, "cannot write the config");
          }};
}

std::string automaticChoices(const nlohmann::json& report) {
  // Options whose chosen value, given explicitly, makes the same bake (kReplayable); the other automatic choices
  // (the walk's depth and split, the compensation's per-page filter) follow the scene and stay auto, with what
  // they chose.
  std::vector<ConfigEntry> entries, comments;
  const nlohmann::json plan = report.value("plan", nlohmann::json::object());
  for (auto it = plan.begin(); it != plan.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& choice = it.value();
    if (!choice.value("automatic", false)) continue;
    const nlohmann::json& v = choice["value"];
    const std::string value = v.is_string() ? v.get<std::string>() : v.is_number_float() ? cli::canonicalNumber(v.get<double>()) : v.dump();
    const OptionDescriptor* option = findBakeOption(key);
    if (option && option->has(kReplayable))
      entries.push_back({key, value, 0, false, {}});
    else
      comments.push_back({"# " + key, "auto (chose " + value + ": " + choice.value("reason", "") + ")", 0, false, {}});
  }
  std::string text = "# what this bake chose where its options said auto (the same scene and options choose the same):\n";
  const std::string body = configText(entries, "") + configText(comments, "");
  std::istringstream lines(body);
  for (std::string line; std::getline(lines, line);)
    if (line != "# " && line != "[bake]") text += line + "\n";
  return text;
}

std::optional<BakeCommand> parseBakeCommand(const Args& givenArgs) {
  Args args = givenArgs;
  // --help shows the common options; --help-all every one, grouped by stage.
  const bool helpAll = std::find(args.begin(), args.end(), "--help-all") != args.end();
  const bool help = helpAll || std::find(args.begin(), args.end(), "--help") != args.end() ||
                    std::find(args.begin(), args.end(), "-h") != args.end();
  const std::string config = argumentValue(args, "--config");
  std::string lightModeOrigin;
  if (!config.empty() && !help) {
    Args fromFile = configArguments(config, args, lightModeOrigin);
    fromFile.insert(fromFile.end(), args.begin(), args.end());
    args = fromFile;
  }
  BakeCommand command;
  BakeArguments arguments;
  const std::unique_ptr<CLI::App> app = bakeApp(command, arguments);
  if (help) {
    if (!helpAll)
      for (CLI::Option* option : app->get_options())
        if (option->get_group() != "Options") option->group("");
    std::fputs(app->help().c_str(), stdout);
    if (!helpAll) std::fputs("every option, grouped by stage: irbake bake --help-all\n", stdout);
    return std::nullopt;
  }
  if (!cli::parse(*app, args)) return std::nullopt;
  command.resultOptions = resultOptions(*app);
  command.optionsHash = hashText(command.resultOptions.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  // What a merge or resume re-parses: the config's entries are in `args` already, so the file is not needed.
  for (size_t i = 0; i < args.size(); ++i) {
    if ((args[i] == "--config" || args[i] == "--dump-config") && i + 1 < args.size()) {
      ++i;
      continue;
    }
    if (args[i].rfind("--config=", 0) == 0 || args[i].rfind("--dump-config=", 0) == 0) continue;
    command.arguments.push_back(args[i]);
  }
  arguments.lightModeOrigin = lightModeOrigin;
  applyArguments(command, arguments);
  applyQuality(*app, *findQualityPreset(arguments.quality), command, arguments);
  if (!arguments.dumpConfig.empty()) {
    command.dumpConfig = arguments.dumpConfig;
    command.dumpText = configText(effectiveOptions(*app, command, arguments),
                                  "irbake bake options (read back with --config FILE)");
  }
  return command;
}

Scene loadBakeScene(const BakeCommand& command) {
  const std::filesystem::path scenePath = command.scene;
  Scene scene = loadScene(scenePath);
  addLights(scene, command.lights);
  requireLight(scene, scenePath);
  return scene;
}

namespace {

namespace fs = std::filesystem;

// The checkpoint of a bake under way (removed when it finishes) and a shard's share, inside OUTDIR.
constexpr const char* kCheckpointName = ".irbake.checkpoint";
std::string partialName(int k, int n) {
  return "partial_" + std::to_string(k) + "_of_" + std::to_string(n) + ".vplsum";
}

// The scene's identity: its files, the environment map's when --env names one, and --atlas-from's bake's.
std::string sceneIdentity(const BakeCommand& c) {
  std::string hash = hashSceneFiles(c.scene);
  if (!c.lights.environment.empty()) hash = hashText(hash + hashSceneFiles(c.lights.environment));
  if (!c.options.atlasFrom.empty()) hash = hashText(hash + hashSceneFiles(c.options.atlasFrom));
  return hash;
}

// The checkpoint goes when the bake is done: when the folder's manifest proves irbake wrote it, or when it
// is an irbake VPL sum file whose checksum holds (a copied shard's partial resumed from); else it stays.
void removeCheckpoint(const fs::path& checkpoint, const OutputGuard& guard) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(checkpoint, ec)) || guard.removeIfOurs(checkpoint)) return;
  try {
    if (!fs::is_regular_file(fs::symlink_status(checkpoint, ec))) throw Error(ErrorCode::Io, "", "not a file");
    readVplSumFile(checkpoint);
  } catch (const Error&) {
    log::warn("left " + checkpoint.string() + " as it is: irbake did not write it");
    return;
  }
  fs::remove(checkpoint, ec);
}

}  // namespace

std::string bakeSceneIdentity(const BakeCommand& c) { return sceneIdentity(c); }

namespace {

// lightmap_<page>.exr/.png and the directional lightmap_<page>_l1x|y|z.exr: names a bake writes.
bool isPageName(const std::string& name) {
  const std::string prefix = "lightmap_";
  if (name.rfind(prefix, 0) != 0) return false;
  size_t at = prefix.size(), digits = 0;
  while (at < name.size() && std::isdigit(static_cast<unsigned char>(name[at]))) ++at, ++digits;
  if (digits == 0) return false;
  const std::string rest = name.substr(at);
  // A light group's layer: lightmap_<page>_<group>.exr / .png.
  const size_t dot = rest.rfind('.');
  if (rest.size() > 1 && rest[0] == '_' && dot != std::string::npos && (rest.substr(dot) == ".exr" || rest.substr(dot) == ".png") &&
      validLayerName(rest.substr(1, dot - 1)))
    return true;
  return rest == ".exr" || rest == ".png" || rest == "_l1x.exr" || rest == "_l1y.exr" || rest == "_l1z.exr" ||
         rest == "_l1x.png" || rest == "_l1y.png" || rest == "_l1z.png" || rest == "_shadowmask.exr" ||
         rest == "_shadowmask.png";
}

// error_<page>.exr (--error-map) is a page too.
bool isPageOrErrorName(const std::string& name) {
  if (isPageName(name)) return true;
  const std::string prefix = "error_";
  if (name.rfind(prefix, 0) != 0 || name.size() <= prefix.size() + 4) return false;
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 4);
  return name.substr(name.size() - 4) == ".exr" &&
         digits.find_first_not_of("0123456789") == std::string::npos;
}

// The files a bake keeps in OUTDIR while it runs: its lock, its checkpoint and a shard's partial.
bool isBakeStateName(const std::string& name) {
  return name == OutputFolderLock::kFileName || name == ".irbake.checkpoint" ||
         (name.rfind("partial_", 0) == 0 && name.size() > 15 && name.substr(name.size() - 7) == ".vplsum");
}

}  // namespace

fs::path portableOutputPath(const std::string& out, const std::string& given) {
  if (given.empty()) return {};
  const fs::path path(given);
  return path.has_parent_path() ? path : outputFolderOf(out) / path;
}

std::shared_ptr<OutputGuard> bakeOutputGuard(BakeCommand& c, const std::vector<fs::path>& moreInputs) {
  auto guard = std::make_shared<OutputGuard>();
  const fs::path outDir = outputFolderOf(c.out);
  const bool gltfNamed = namesGltfFile(c.out);
  const fs::path gltf = gltfNamed ? fs::path(c.out) : outDir / "scene.gltf";
  c.portable = portableOutputPath(c.out, c.portable).string();
  if (!c.portable.empty() && !hasExtension(c.portable, ".glb"))
    throw Error(ErrorCode::Usage, c.portable, "--portable writes one GLB: give a .glb file name");
  // Inputs first: the scene and its files, --env's map, and what the command reads besides (merge's partials).
  std::vector<fs::path> inputs = sceneInputFiles(c.scene);
  if (!c.lights.environment.empty()) inputs.push_back(c.lights.environment);
  // --atlas-from's bake and its files: a bake into its own folder would overwrite what it reads.
  if (!c.options.atlasFrom.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(c.options.atlasFrom, ec)) throw Error(ErrorCode::Io, c.options.atlasFrom, "--atlas-from: no such file");
    const std::vector<fs::path> baked = sceneInputFiles(c.options.atlasFrom);
    inputs.insert(inputs.end(), baked.begin(), baked.end());
    if (!c.options.onlyGroup.empty()) {  // its layers' pages and its report, read back
      const std::vector<fs::path> layers = onlyGroupInputs(c.options.atlasFrom);
      inputs.insert(inputs.end(), layers.begin(), layers.end());
    }
  }
  inputs.insert(inputs.end(), moreInputs.begin(), moreInputs.end());
  guard->addInputs(inputs);
  // The names the bake picks in OUTDIR (pages, its lock, checkpoint and partials), then each named output.
  guard->keepManifest(outDir);
  guard->addOutputNames(outDir, isPageOrErrorName, "a light-map page of this bake");
  guard->addOutputNames(outDir, isBakeStateName, "the bake's own state (lock, checkpoint, partials)");
  if (!c.noGltf) {
    guard->addOutput(gltf, "the glTF output");
    if (!hasExtension(gltf, ".glb")) guard->addOutput(outDir / (gltf.stem().string() + ".bin"), "the glTF's .bin output");
  }
  guard->addOutput(c.report.empty() ? outDir / "report.json" : fs::path(c.report), c.report.empty() ? "the report" : "--report");
  if (!c.portable.empty()) guard->addOutput(c.portable, "--portable");
  if (!c.dumpConfig.empty()) guard->addOutput(c.dumpConfig, "--dump-config");
  c.inputs = inputs;
  return guard;
}

std::unique_ptr<OutputFolderLock> lockReportFolder(const BakeCommand& c) {
  if (c.report.empty()) return nullptr;
  const fs::path folder = folderOf(c.report);
  if (sameFile(folder, outputFolderOf(c.out))) return nullptr;
  return std::make_unique<OutputFolderLock>(folder);
}

namespace {
// A bake with light groups (pipeline/light_groups.h): each group baked apart, in one process, no checkpoint.
int runGroupedBake(BakeCommand& c, Scene scene, TerminalProgress& progress, const OutputGuard& guard, double loadSeconds,
                   double loadCpuSeconds) {
  if (c.shardIndex > 0 || c.resume)
    throw Error(ErrorCode::Usage, c.scene, "light groups bake each group apart in one run: --shard and --resume do not split them yet");
  BakeResult result = c.options.onlyGroup.empty() ? bakeLightGroups(std::move(scene), c.options) : bakeOnlyGroup(std::move(scene), c.options);
  result.report["timings"]["seconds"]["load"] = loadSeconds;
  result.report["timings"]["cpuSeconds"]["load"] = loadCpuSeconds;
  result.report["options"] = c.resultOptions;
  writeFinishedBake(c, result, progress, guard);
  return 0;
}
}  // namespace

int runBake(const Args& args) {
  std::optional<BakeCommand> parsed = parseBakeCommand(args);
  if (!parsed) return 0;
  BakeCommand& c = *parsed;
  if (c.quiet) log::setLevel(log::Level::Warn);
  else if (c.verbose) log::setLevel(log::Level::Debug);
  std::unique_ptr<tbb::global_control> threadLimit;
  if (c.threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, c.threads);

  const fs::path outDir = outputFolderOf(c.out);
  const std::shared_ptr<OutputGuard> guard = bakeOutputGuard(c, {});
  const OutputFolderLock lock(outDir);  // before any work: a second bake into OUTDIR fails at once
  const std::unique_ptr<OutputFolderLock> reportLock = lockReportFolder(c);
  removeStaleTemps(outDir);
  Stopwatch loadTime;
  Scene scene = loadBakeScene(c);
  const double loadSeconds = loadTime.seconds(), loadCpuSeconds = loadTime.cpuSeconds();

  TerminalProgress progress;
  c.options.progress = progress.callback();
  if (!c.options.onlyGroup.empty() || !resolveLightGroups(scene, c.options.lightGroups).empty()) return runGroupedBake(c, std::move(scene), progress, *guard, loadSeconds, loadCpuSeconds);
  StagedBake staged(std::move(scene), c.options);

  // The blocks this process adds: all, or share K of N.
  const size_t blocks = staged.blockCount();
  const size_t begin = c.shardIndex ? blocks * (c.shardIndex - 1) / c.shardCount : 0;
  const size_t end = c.shardIndex ? blocks * c.shardIndex / c.shardCount : blocks;
  VplSumHeader header;
  header.sceneHash = sceneIdentity(c);
  header.optionsHash = c.optionsHash;
  header.options = c.resultOptions;
  header.seed = c.options.walk.seed;
  header.backend = toString(staged.backend());
  header.blockCount = blocks;
  header.firstBlock = begin;
  header.shardIndex = c.shardIndex;
  header.shardCount = c.shardCount;
  header.command = {{"scene", fs::absolute(c.scene).string()},
                    {"env", c.lights.environment.empty() ? std::string() : fs::absolute(c.lights.environment).string()},
                    {"atlasFrom", c.options.atlasFrom.empty() ? std::string() : fs::absolute(c.options.atlasFrom).string()},
                    {"args", c.arguments}};

  ExactVplSums sums = staged.emptySums();
  size_t next = begin;
  const fs::path checkpoint = outDir / kCheckpointName;
  if (fs::exists(checkpoint)) {
    if (c.resume) {
      VplSumFile saved = readVplSumFile(checkpoint);
      std::string differs = header.mismatch(saved.header);
      if (differs.empty() && (saved.header.firstBlock != begin || saved.header.endBlock > end))
        differs = "share of the VPL blocks";
      if (differs.empty() && saved.sums.coefficients != sums.coefficients)  // a version-1 --directional checkpoint
        differs = "coefficients per texel: " + std::to_string(saved.sums.coefficients) + " saved, " +
                  std::to_string(sums.coefficients) + " needed";
      if (differs.empty() && !saved.sums.sameLayout(sums)) differs = "page layout";
      if (!differs.empty())
        throw Error(ErrorCode::Usage, checkpoint.string(),
                    "this checkpoint belongs to another bake (different " + differs +
                        "): delete it, or bake without --resume");
      sums = std::move(saved.sums);
      next = saved.header.endBlock;
      staged.addBackendCounts(saved.header.backendCounts);
      log::info("resuming at VPL block " + std::to_string(next) + " of " + std::to_string(end) + " (" +
                checkpoint.string() + ")");
    } else {
      log::warn("ignoring the checkpoint " + checkpoint.string() + " of an earlier bake (--resume would continue it)");
    }
  } else if (c.resume) {
    log::info("no checkpoint in " + outDir.string() + ": baking from the start");
  }

  Stopwatch sinceCheckpoint;
  const bool checkpoints = !c.options.errorEstimate.enabled;  // the halves' sums are not in a checkpoint
  staged.evaluateBlocks(next, end, sums, [&](size_t done) {
    if (!checkpoints || done >= end || sinceCheckpoint.seconds() < c.checkpointSeconds) return;
    VplSumHeader h = header;
    h.kind = "checkpoint";
    h.endBlock = done;
    h.backendCounts = staged.backendCounts();
    writeVplSumFile(checkpoint, h, sums, guard.get());
    sinceCheckpoint.reset();
  });

  std::error_code ec;
  if (c.shardIndex > 0) {
    header.kind = "partial";
    header.endBlock = end;
    header.backendCounts = staged.backendCounts();
    const fs::path partial = outDir / partialName(c.shardIndex, c.shardCount);
    if (c.dumpConfig.empty()) writeVplSumFile(partial, header, sums, guard.get());
    else  // the partial and the config it was baked with, together or not at all
      guard->write({PendingFile{partial, [&](const fs::path& temp) { writeVplSumFile(temp, header, sums); }},
                    dumpedConfigFile(c.dumpConfig, c.dumpText)});
    removeCheckpoint(checkpoint, *guard);
    progress.finish();
    log::info("shard " + std::to_string(c.shardIndex) + "/" + std::to_string(c.shardCount) + ": VPL blocks " +
              std::to_string(begin) + ".." + std::to_string(end) + " of " + std::to_string(blocks));
    std::printf("%s\n", partial.string().c_str());
    return 0;
  }

  staged.refineToTarget(sums);
  BakeResult result = staged.finish(std::move(sums));
  result.report["timings"]["seconds"]["load"] = loadSeconds;
  result.report["timings"]["cpuSeconds"]["load"] = loadCpuSeconds;
  result.report["options"] = c.resultOptions;
  writeFinishedBake(c, result, progress, *guard);
  removeCheckpoint(checkpoint, *guard);
  return 0;
}

namespace {
// "2.00%"
std::string percentText(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f%%", 100.0 * x);
  return text;
}
}  // namespace

// ", estimated error 2.10%" (and what stopped --target-error: the target, or a cap above it) for the final
// log line; "" without an estimate.
std::string estimatedErrorText(const nlohmann::json& report) {
  if (!report.contains("estimatedError")) return "";
  const nlohmann::json& e = report["estimatedError"];
  char text[96];
  std::snprintf(text, sizeof text, ", estimated error %.2f%%", 100.0 * e.value("relative", 0.0));
  std::string line = text;
  if (!e.contains("stoppedBy")) return line;
  const std::string stoppedBy = e["stoppedBy"].get<std::string>();
  if (stoppedBy == "target") return line + " (target " + percentText(e.value("targetError", 0.0)) + " reached)";
  return line + " (stopped by " + stoppedBy + ", above the target " + percentText(e.value("targetError", 0.0)) + ")";
}

void writeFinishedBake(const BakeCommand& c, const BakeResult& result, TerminalProgress& progress, const OutputGuard& guard) {
  OutputOptions outputOptions;
  outputOptions.guard = &guard;
  // --dump-config: the options, then what the bake chose where they said auto; written with the outputs.
  if (!c.dumpConfig.empty()) outputOptions.alsoWrite.push_back(dumpedConfigFile(c.dumpConfig, c.dumpText + automaticChoices(result.report)));
  outputOptions.outDir = c.out;
  outputOptions.reportPath = c.report;
  outputOptions.writeGltf = !c.noGltf;
  outputOptions.portablePath = c.portable;
  outputOptions.portable.exposure = c.portableExposure;
  outputOptions.portable.maxTextureSize = c.portableMaxSize;
  outputOptions.inputs = c.inputs;
  Stopwatch writeTime;
  c.options.progress("write", 0.0);  // coarse: EXR pages, glTF and report are written one after another
  auto files = writeBakeOutputs(result, outputOptions);
  c.options.progress("write", 1.0);
  progress.finish();
  log::info("baked " + std::to_string(result.maps.size()) + " page(s) with " + result.report["backend"].get<std::string>() +
            " in " + std::to_string(result.report["timings"]["seconds"]["bake"].get<double>()) + " s (+ " +
            std::to_string(writeTime.seconds()) + " s writing)" + estimatedErrorText(result.report));
  for (const auto& f : files) std::printf("%s\n", f.string().c_str());
}
}  // namespace irbake::app
