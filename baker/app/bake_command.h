// `irbake bake`'s command line as a value: parsed once for a bake, and again at `irbake merge` from the
// arguments a shard stored in its partial, so both rebuild the same bake.
#pragma once
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "common/output_guard.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "pipeline/bake.h"
#include "scene/light_additions.h"
#include "scene/scene.h"

namespace irbake::app {

struct BakeCommand {
  BakeOptions options;             // everything the pipeline reads
  std::string scene;               // SCENE as given
  std::string out;                 // -o OUTDIR | OUT.glb | OUT.gltf
  std::string report;              // --report (empty: OUTDIR/report.json)
  LightAdditions lights;           // --sun, --sky, --env (+ --env-intensity, --env-rotation), checked
  int threads = 0;                 // --threads (0: every core)
  bool quiet = false;              // --quiet
  bool verbose = false;            // --verbose
  bool noGltf = false;             // --no-gltf
  std::string portable;            // --portable [FILE.glb]: also the unlit core-glTF bake (empty: none; a bare
                                   // name: in OUTDIR; resolved by bakeOutputGuard)
  double portableExposure = PortableOptions{}.exposure;   // --portable-exposure: scale on the shown values
  int portableMaxSize = PortableOptions{}.maxTextureSize;  // --portable-max-size: texels a side per texture
  int shardIndex = 0;              // --shard K/N: K (1-based), 0 without --shard
  int shardCount = 0;              // N
  bool resume = false;             // --resume: continue from OUTDIR's checkpoint when it matches
  double checkpointSeconds = 5.0;  // --checkpoint-seconds: at most this long between checkpoints (0: every block)
  Args arguments;                  // the arguments parsed: the command line after --config's entries
  std::vector<std::filesystem::path> inputs;  // the scene's files and --env's map (bakeOutputGuard)
  std::string dumpConfig;          // --dump-config FILE ("" without it)
  std::string dumpText;            // that file's text as parsed (what the bake decides is appended after it)
  nlohmann::json resultOptions;    // every option that changes the result, given at other than its default
  std::string optionsHash;         // hash of resultOptions (not -o, --threads, ...)
};

// Where --portable writes: `given` as it is when it names a folder, else in -o's folder (OUTDIR, or the
// folder of OUT.glb / OUT.gltf); "" without --portable.
std::filesystem::path portableOutputPath(const std::string& out, const std::string& given);

// Parses the arguments after "bake"; nullopt when --help was printed. Throws Error(Usage).
std::optional<BakeCommand> parseBakeCommand(const Args& args);

// Loads SCENE with the command's light additions (--sun, --sky, --env) and checks it has light.
Scene loadBakeScene(const BakeCommand& command);

// The scene's identity for partials and checkpoints: hashes of its files (and of --env's map).
std::string bakeSceneIdentity(const BakeCommand& command);

// The bake's output guard (common/output_guard.h): its inputs (the scene, its .bin and textures, --env, and
// `moreInputs`, e.g. merge's partials) and its outputs (glTF, .bin, report, --portable, --dump-config, the page
// and state names it picks in OUTDIR). Refuses (Error(Usage), exit 2) an output that is an input, another
// output, a folder or a pseudo-file, before any work. Sets command.inputs, which the export never overwrites.
std::shared_ptr<OutputGuard> bakeOutputGuard(BakeCommand& command, const std::vector<std::filesystem::path>& moreInputs);
// The --dump-config file as one more file of a set the guard writes.
PendingFile dumpedConfigFile(const std::string& file, const std::string& text);
// Locks --report's folder when it is not OUTDIR, so a report never lands in another bake's folder while
// that bake runs (nullptr when no second lock is needed). Throws Error(Io) when that folder is busy.
std::unique_ptr<OutputFolderLock> lockReportFolder(const BakeCommand& command);

// "# key = value" lines of what the bake decided where its options said auto (backend, paths, bounces,
// interleave, clamp, final gather), from its report: the tail of a --dump-config file.
std::string automaticChoices(const nlohmann::json& report);

// Writes a finished bake's outputs where the command says (the all-or-nothing set) and lists them.
void writeFinishedBake(const BakeCommand& command, const BakeResult& result, TerminalProgress& progress,
                       const OutputGuard& guard);

}  // namespace irbake::app
