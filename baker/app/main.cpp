// irbake: command-line entry. Dispatches to one subcommand; every error becomes one line on stderr
// and a non-zero exit code (see common/error.h).
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "app/commands.h"
#include "common/error.h"
#include "common/version.h"

namespace {
const char* kUsage =
    "usage: irbake <command> [options]\n"
    "commands:\n"
    "  info SCENE                       print a summary of a glTF scene\n"
    "  unwrap IN -o OUT [options]       add a lightmap UV set (TEXCOORD_1)\n"
    "  plan SCENE [options]             predict a bake (atlas, choices, time, memory) without baking\n"
    "  bake SCENE -o OUTDIR [options]   bake light maps (EXR) and export glTF with MOZ_lightmap\n"
    "  merge DIR... -o OUTDIR           finish a bake from its shards (bake --shard K/N)\n"
    "  diff A B                         compare two bakes of the same atlas\n"
    "  samples OUTDIR                   write the built-in sample scenes\n"
    "  probe GLTF --at X,Y,Z            the baked irradiance probes read at a point (JSON)\n"
    "  relight BAKED --group N=W -o OUT a bake with light groups with other weights, no ray traced\n"
    "  --version                        print the version and exit\n"
    "run 'irbake <command> --help' for a command's options\n";
}

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::FILE* to = argc < 2 ? stderr : stdout;
    std::fputs(kUsage, to);
    std::fputs(irbake::exitCodeHelp().c_str(), to);
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::printf("%s\n", irbake::versionLine("irbake").c_str());
    return 0;
  }
  std::string cmd = argv[1];
  irbake::app::Args args(argv + 2, argv + argc);
  try {
    if (cmd == "info") return irbake::app::runInfo(args);
    if (cmd == "unwrap") return irbake::app::runUnwrap(args);
    if (cmd == "plan") return irbake::app::runPlan(args);
    if (cmd == "bake") return irbake::app::runBake(args);
    if (cmd == "merge") return irbake::app::runMerge(args);
    if (cmd == "diff") return irbake::app::runDiff(args);
    if (cmd == "samples") return irbake::app::runSamples(args);
    if (cmd == "probe") return irbake::app::runProbe(args);
    if (cmd == "relight") return irbake::app::runRelight(args);
    std::fprintf(stderr, "irbake: error: unknown command '%s'\n%s", cmd.c_str(), kUsage);
    return 2;
  } catch (const irbake::Error& e) {
    std::fprintf(stderr, "irbake: error: %s\n", e.what());
    return irbake::exitCodeFor(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "irbake: error: %s\n", e.what());
    return 1;
  }
}
