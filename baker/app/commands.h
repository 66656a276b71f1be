// The irbake subcommands, one file each (cmd_<name>.cpp). Each returns the process exit code and
// may throw irbake::Error, which main() turns into "irbake: error: <file>: <message>".
#pragma once
#include <string>
#include <vector>

namespace irbake::app {
using Args = std::vector<std::string>;  // arguments after the subcommand name
int runInfo(const Args& args);
int runUnwrap(const Args& args);
int runBake(const Args& args);
int runMerge(const Args& args);
int runDiff(const Args& args);
int runSamples(const Args& args);
int runProbe(const Args& args);
int runPlan(const Args& args);
int runRelight(const Args& args);
}  // namespace irbake::app
