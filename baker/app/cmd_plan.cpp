// irbake plan SCENE [the bake's options] [--json]: the preflight. Predicts the bake without baking anything:
// the atlas, the plan with each choice's reason, the peak memory, the time per stage and the warnings.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "app/bake_command.h"
#include "app/commands.h"
#include "common/error.h"
#include "common/log.h"
#include "pipeline/bake_prediction.h"

namespace irbake::app {

namespace {

const char* kPlanUsage =
    "usage: irbake plan SCENE [bake options] [--json]\n"
    "Predicts the bake of SCENE with the bake's options (irbake bake --help) without baking anything: the atlas\n"
    "(pages, texels, texels per metre), every automatic choice with its reason (those the bake settles from\n"
    "what it builds are marked \"settled at bake\"), the peak memory and the time per stage on an idle machine\n"
    "with this machine's cores (or --threads), and the warnings the bake would give. -o is accepted and ignored;\n"
    "nothing is written. With --max-memory GB a bake predicted over it is refused (exit 2), as bake does.\n"
    "  --json    the prediction as one JSON object (atlas, plan, inputs, prediction, warnings)\n";

std::string number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string choiceText(const nlohmann::json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

void printPlan(const Scene& scene, const BakePrediction& p) {
  std::printf("scene: %s: %zu triangles, %zu primitives, %zu lights%s\n", scene.sourcePath.c_str(), scene.triangleCount(),
              scene.primitives.size(), scene.lights.size(), scene.environment.present() ? ", a sky" : "");
  std::printf("atlas (predicted): %d page(s) of up to %d x %d, %s texels in charts, %s page texels, %s texels per metre\n",
              p.atlas.pages, p.atlas.pageSize, p.atlas.pageSize, number("%.4g", p.atlas.texels).c_str(),
              number("%.4g", p.atlas.pageTexels).c_str(), number("%.4g", p.atlas.texelsPerUnit).c_str());
  std::printf("plan:\n");
  for (const auto& [key, c] : p.plan.choices)
    std::printf("  %s = %s (%s%s)\n", key.c_str(), choiceText(c.value).c_str(), c.automatic ? "" : "fixed: ", c.reason.c_str());
  std::printf("prediction (an idle machine, %g cores): %s s, %s CPU s, peak memory %s MiB\n", p.inputs.cores,
              number("%.3g", p.cost.seconds).c_str(), number("%.3g", p.cost.cpuSeconds).c_str(),
              number("%.4g", p.cost.memoryPeakMiB).c_str());
  for (const auto& [stage, seconds] : p.cost.perStage) std::printf("  %-14s %s s\n", stage.c_str(), number("%.3g", seconds).c_str());
  std::printf("warnings:%s\n", p.warnings.empty() ? " none" : "");
  for (const std::string& w : p.warnings) std::printf("  %s\n", w.c_str());
}

}  // namespace

int runPlan(const Args& given) {
  if (std::find(given.begin(), given.end(), "--help") != given.end() || std::find(given.begin(), given.end(), "-h") != given.end()) {
    std::fputs(kPlanUsage, stdout);
    return 0;
  }
  Args args;
  bool json = false, output = false;
  for (const std::string& a : given) {
    if (a == "--json") json = true;
    else args.push_back(a);
    output |= a == "-o" || a == "--output" || a.rfind("--output=", 0) == 0;
  }
  if (!output) args.insert(args.end(), {"-o", "plan-writes-nothing"});  // bake's parser needs one; never used
  std::optional<BakeCommand> parsed = parseBakeCommand(args);
  if (!parsed) return 0;
  BakeCommand& c = *parsed;
  log::setLevel(log::Level::Warn);  // the scene's own warnings still show; the prediction lists the bake's
  std::unique_ptr<tbb::global_control> threadLimit;
  if (c.threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, c.threads);
  const Scene scene = loadBakeScene(c);
  const BakePrediction prediction = predictBake(scene, c.options, bakeCores());
  if (json) {
    nlohmann::json j = prediction.toJson();
    j["scene"] = {{"source", scene.sourcePath}, {"triangles", scene.triangleCount()}, {"lights", scene.lights.size()}};
    std::printf("%s\n", j.dump(1).c_str());
  } else {
    printPlan(scene, prediction);
  }
  checkMemoryLimit(prediction, c.options.maxMemoryGB, c.scene);
  return 0;
}

}  // namespace irbake::app
