// `irbake plan` as a user runs it: the sections it prints, its JSON, --max-memory's refusal (plan and bake,
// writing nothing), and the prediction a bake writes into report.json beside its timings.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"

namespace fs = std::filesystem;
using namespace irbake::testing;
using json = nlohmann::json;

namespace {

bool finitePositive(const json& v) { return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() > 0.0; }

}  // namespace

TEST(PlanCommand, PrintsTheAtlasThePlanThePredictionAndTheWarnings) {
  const fs::path dir = scratchFolder("plan_command", "sections");
  const fs::path scene = sampleScenes("plan_command") / "cornell_box.gltf";
  const IrbakeRun r = runIrbakeIn(dir, {"plan", scene.string(), "--quality", "preview"});
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* section : {"atlas (predicted): 1 page(s)", "texels per metre", "\nplan:\n", "  backend = ",
                              "  clamp = settled at bake", "prediction (an idle machine", "peak memory", "  backend ",
                              "warnings:"})
    EXPECT_NE(r.output.find(section), std::string::npos) << section << "\n" << r.output;
  EXPECT_FALSE(fs::exists(dir / "plan-writes-nothing"));

  const IrbakeRun j = runIrbakeIn(dir, {"plan", scene.string(), "--json"});
  ASSERT_EQ(j.code, 0) << j.output;
  const json plan = json::parse(j.output.substr(j.output.find('{')));
  EXPECT_EQ(plan["atlas"]["pages"], 1);
  EXPECT_TRUE(finitePositive(plan["prediction"]["seconds"]));
  EXPECT_TRUE(finitePositive(plan["prediction"]["memoryPeakMiB"]));
  EXPECT_EQ(plan["scene"]["triangles"], 32);
  EXPECT_EQ(plan["inputs"]["triangles"], 32);
  EXPECT_TRUE(plan["plan"].contains("backend"));
}

TEST(PlanCommand, MaxMemoryRefusesUpFrontWritingNothing) {
  const fs::path dir = scratchFolder("plan_command", "max_memory");
  const fs::path scene = sampleScenes("plan_command") / "cornell_box.gltf";
  const IrbakeRun plan = runIrbakeIn(dir, {"plan", scene.string(), "--max-memory", "0.001"});
  EXPECT_EQ(plan.code, 2) << plan.output;
  EXPECT_NE(plan.output.find("over --max-memory 0.001 GB"), std::string::npos) << plan.output;
  const fs::path out = dir / "out";
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", scene.string(), "-o", out.string(), "--max-memory", "0.001", "--quiet"});
  EXPECT_EQ(bake.code, 2) << bake.output;
  EXPECT_NE(bake.output.find("irbake: error: "), std::string::npos) << bake.output;
  EXPECT_NE(bake.output.find("predicted to need"), std::string::npos) << bake.output;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "a refused bake wrote into " << out;
}

TEST(PlanCommand, TheBakesReportHoldsThePredictionBesideTheTimings) {
  const fs::path dir = scratchFolder("plan_command", "report");
  const fs::path scene = sampleScenes("plan_command") / "cornell_box.gltf";
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", scene.string(), "-o", (dir / "out").string(), "--quality", "preview",
                                           "--max-memory", "1000", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const json report = json::parse(fileText(dir / "out" / "report.json"));
  ASSERT_TRUE(report.contains("prediction"));
  const json& p = report["prediction"];
  EXPECT_TRUE(finitePositive(p["seconds"]));
  EXPECT_TRUE(finitePositive(p["memoryPeakMiB"]));
  ASSERT_TRUE(p["perStage"].is_object());
  for (const auto& [stage, seconds] : p["perStage"].items()) {
    EXPECT_TRUE(seconds.is_number() && std::isfinite(seconds.get<double>()) && seconds.get<double>() >= 0.0) << stage;
    if (stage != "write") {
      EXPECT_TRUE(report["timings"]["seconds"].contains(stage)) << stage << " is no stage of the bake";
    }
  }
  EXPECT_TRUE(finitePositive(p["perStage"]["backend"]));
  // Each stage's CPU seconds beside its wall seconds; the whole bake's take some.
  const json& cpu = report["timings"]["cpuSeconds"];
  for (const auto& [stage, seconds] : report["timings"]["seconds"].items())
    if (stage != "load" && stage != "compensationTrace") {
      ASSERT_TRUE(cpu.contains(stage)) << stage;
      EXPECT_TRUE(cpu[stage].is_number() && cpu[stage].get<double>() >= 0.0) << stage;
    }
  EXPECT_TRUE(finitePositive(cpu["bake"]));
  EXPECT_TRUE(cpu.contains("load"));
  // The same prediction as the preflight's, on the same machine and options: the same memory and the same
  // untraced stages (the traced ones weigh their rays by the ray pilot, timed in each run).
  const IrbakeRun plan = runIrbakeIn(dir, {"plan", scene.string(), "--quality", "preview", "--json"});
  ASSERT_EQ(plan.code, 0) << plan.output;
  const json predicted = json::parse(plan.output.substr(plan.output.find('{')))["prediction"];
  EXPECT_DOUBLE_EQ(predicted["memoryPeakMiB"].get<double>(), p["memoryPeakMiB"].get<double>());
  for (const char* stage : {"load", "atlas", "raytrace", "vpls", "post", "write"})
    EXPECT_DOUBLE_EQ(predicted["perStage"][stage].get<double>(), p["perStage"][stage].get<double>()) << stage;
}
