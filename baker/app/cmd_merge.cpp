// irbake merge DIR1 DIR2 ... -o OUTDIR: adds the shards' exact VPL sums (irbake bake --shard K/N) and
// finishes the bake (punctual lights, sky, clamp compensation, post, export): the same bytes as the bake
// on one machine. Every share must be there exactly once, all of the same scene, options and seed.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "app/bake_command.h"
#include "app/bake_option_table.h"
#include "app/commands.h"
#include "common/command_line.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/log.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "pipeline/bake.h"
#include "pipeline/vpl_sum_file.h"

namespace irbake::app {

namespace {

namespace fs = std::filesystem;

// The partial files named: a file as itself, a folder as every partial_*.vplsum in it (sorted).
std::vector<fs::path> partialFiles(const std::vector<std::string>& inputs) {
  std::vector<fs::path> files;
  for (const std::string& input : inputs) {
    const fs::path p = input;
    if (!fs::exists(p)) throw Error(ErrorCode::Io, input, "no such file or folder");
    if (!fs::is_directory(p)) {
      files.push_back(p);
      continue;
    }
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(p)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("partial_", 0) == 0 && entry.path().extension() == ".vplsum") found.push_back(entry.path());
    }
    if (found.empty())
      throw Error(ErrorCode::Io, input, "no partial_K_of_N.vplsum here (written by irbake bake --shard K/N)");
    std::sort(found.begin(), found.end());
    files.insert(files.end(), found.begin(), found.end());
  }
  return files;
}

// Every share 1..N exactly once, all of one bake; throws naming the files otherwise.
void checkShares(const std::vector<fs::path>& files, const std::vector<VplSumFile>& partials) {
  const VplSumHeader& first = partials[0].header;
  std::map<int, fs::path> byShare;
  for (size_t i = 0; i < partials.size(); ++i) {
    const VplSumHeader& h = partials[i].header;
    if (h.kind != "partial" || h.shardIndex < 1 || h.shardCount < 1)
      throw Error(ErrorCode::InvalidData, files[i].string(), "not a shard's partial (it is a " + h.kind + ")");
    if (std::string differs = first.mismatch(h); !differs.empty())
      throw Error(ErrorCode::InvalidData, files[i].string(),
                  "partial of another bake than " + files[0].string() + " (different " + differs + ")");
    if (h.shardCount != first.shardCount)
      throw Error(ErrorCode::InvalidData, files[i].string(),
                  "share of " + std::to_string(h.shardCount) + " shards, but " + files[0].string() + " is one of " +
                      std::to_string(first.shardCount));
    const uint64_t b = h.blockCount, k = static_cast<uint64_t>(h.shardIndex), n = static_cast<uint64_t>(h.shardCount);
    if (h.firstBlock != b * (k - 1) / n || h.endBlock != b * k / n)
      throw Error(ErrorCode::InvalidData, files[i].string(), "its VPL blocks are not those of share " +
                                                                 std::to_string(k) + "/" + std::to_string(n));
    auto [at, inserted] = byShare.emplace(h.shardIndex, files[i]);
    if (!inserted)
      throw Error(ErrorCode::Usage, files[i].string(),
                  "share " + std::to_string(h.shardIndex) + "/" + std::to_string(h.shardCount) + " given twice (also " +
                      at->second.string() + ")");
  }
  std::string missing;
  for (int k = 1; k <= first.shardCount; ++k)
    if (!byShare.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(first.shardCount);
  if (!missing.empty())
    throw Error(ErrorCode::Usage, files[0].string(), "missing share(s) " + missing + " of this bake");
}

}  // namespace

int runMerge(const Args& args) {
  std::vector<std::string> inputs;
  std::string out, report;
  int threads = 0;
  bool quiet = false, noGltf = false;
  std::string portable;
  double portableExposure = PortableOptions{}.exposure;
  int portableMaxSize = PortableOptions{}.maxTextureSize;
  auto app = cli::makeApp("irbake merge",
                          "Adds the partial VPL sums of 'irbake bake --shard K/N' (every share once) and\n"
                          "finishes the bake: the same outputs, byte for byte, as the bake on one machine.");
  app->add_option("DIR", inputs, "shard output folders (or partial_K_of_N.vplsum files)");
  app->add_option("-o,--output", out, "output folder (OUTDIR), or OUT.glb / OUT.gltf")->type_name("OUTDIR");
  app->add_option("--report", report, "report path (default OUTDIR/report.json)")->type_name("R.json");
  app->add_flag("--no-gltf", noGltf, "write only the EXR pages and the report");
  app->add_option("--portable", portable, "also write FILE.glb, the unlit core-glTF bake (as irbake bake --portable:\n"
                  "in OUTDIR unless it names a folder; alone: OUTDIR/" + std::string(kPortableName) + ")")
      ->type_name("[FILE.glb]")->expected(0, 1)->default_str(kPortableName);
  app->add_option("--portable-exposure", portableExposure, "--portable: scale on the shown values (default 1)")
      ->transform(cli::numberIn(1e-6, 1e6))->type_name("X");
  app->add_option("--portable-max-size", portableMaxSize,
                  "--portable: at most N texels a side per texture (default " + std::to_string(portableMaxSize) + ")")
      ->transform(cli::integerIn(64, 16384))->type_name("N");
  app->add_option("--threads", threads, "worker threads (default 0: every core)")
      ->transform(cli::integerIn(0, 1024))->type_name("N");
  app->add_flag("--quiet", quiet, "warnings and errors only, no progress bars");
  if (!cli::parse(*app, args)) return 0;
  if (inputs.empty()) throw Error(ErrorCode::Usage, "", "merge needs the shards' folders; see 'irbake merge --help'");
  if (out.empty()) throw Error(ErrorCode::Usage, "", "merge needs -o OUTDIR");
  if (quiet) log::setLevel(log::Level::Warn);
  std::unique_ptr<tbb::global_control> threadLimit;
  if (threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  const std::vector<fs::path> files = partialFiles(inputs);
  std::vector<VplSumFile> partials;
  for (const fs::path& f : files) partials.push_back(readVplSumFile(f));
  checkShares(files, partials);
  const VplSumHeader& first = partials[0].header;

  // The bake the shards ran, rebuilt from the arguments they stored; the backend they used, not a new
  // automatic choice (this machine may have no GL).
  std::optional<BakeCommand> parsed;
  try {
    parsed = parseBakeCommand(first.command.at("args").get<Args>());
  } catch (const nlohmann::json::exception&) {
    throw Error(ErrorCode::Parse, files[0].string(), "the partial's bake arguments are unreadable");
  }
  if (!parsed) throw Error(ErrorCode::InvalidData, files[0].string(), "the partial's bake arguments ask for --help");
  BakeCommand& c = *parsed;
  c.scene = first.command.value("scene", c.scene);
  if (!c.lights.environment.empty())
    c.lights.environment = first.command.value("env", c.lights.environment.string());
  if (!c.options.atlasFrom.empty()) c.options.atlasFrom = first.command.value("atlasFrom", c.options.atlasFrom);
  c.out = out;
  c.report = report;
  c.noGltf = noGltf;
  c.portable = portable;  // where and how to write, never the shards' own arguments
  c.portableExposure = portableExposure;
  c.portableMaxSize = portableMaxSize;
  c.options.backend = parseBackend(first.backend);
  if (c.optionsHash != first.optionsHash)
    throw Error(ErrorCode::InvalidData, files[0].string(), "the stored arguments do not give the options hashed");

  const std::shared_ptr<OutputGuard> guard = bakeOutputGuard(c, files);
  const OutputFolderLock lock(outputFolderOf(out));
  const std::unique_ptr<OutputFolderLock> reportLock = lockReportFolder(c);
  removeStaleTemps(outputFolderOf(out));
  Scene scene = loadBakeScene(c);  // first: the loader refuses what the hash's JSON parse should not see
  if (bakeSceneIdentity(c) != first.sceneHash)
    throw Error(ErrorCode::InvalidData, c.scene, "the scene changed since the shards baked it (" + files[0].string() + ")");
  TerminalProgress progress;
  c.options.progress = progress.callback();
  StagedBake staged(std::move(scene), c.options);
  if (staged.blockCount() != first.blockCount)
    throw Error(ErrorCode::InvalidData, files[0].string(),
                "the shards had " + std::to_string(first.blockCount) + " VPL blocks, this bake " +
                    std::to_string(staged.blockCount()));
  ExactVplSums sums = staged.emptySums();
  for (size_t i = 0; i < partials.size(); ++i) {
    if (partials[i].sums.coefficients != sums.coefficients)  // e.g. a --directional partial of version 1: L0 only
      throw Error(ErrorCode::InvalidData, files[i].string(),
                  "its sums hold " + std::to_string(partials[i].sums.coefficients) +
                      " coefficient(s) per texel, this bake needs " + std::to_string(sums.coefficients) +
                      " (a partial written before irbake summed the directional pages: bake the shard again)");
    if (!partials[i].sums.sameLayout(sums))
      throw Error(ErrorCode::InvalidData, files[i].string(), "its pages are not this bake's pages");
    sums.add(partials[i].sums);
    staged.addBackendCounts(partials[i].header.backendCounts);
  }
  partials.clear();
  BakeResult result = staged.finish(std::move(sums));
  result.report["shards"] = first.shardCount;
  result.report["options"] = c.resultOptions;
  writeFinishedBake(c, result, progress, *guard);
  return 0;
}

}  // namespace irbake::app
