// A bake answers for the light that reaches the scene, at any supported scale: light that never enters
// changes nothing inside, and the same scene in millimetres or in kilometres bakes the same map.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/exr_io.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

fs::path scratch(const std::string& name) { return irbake::testing::scratchFolder("scene_invariance", name); }

IrbakeRun runIrbake(const std::vector<std::string>& args, const fs::path& log) {
  return irbake::testing::runIrbakeLogged(args, log);
}

fs::path samples() { return irbake::testing::sampleScenes("scene_invariance"); }

// Mean of every valid texel of every page (R, G, B averaged).
double mapMean(const fs::path& out) {
  double sum = 0.0;
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("lightmap_", 0) != 0 || e.path().extension() != ".exr") continue;
    const irbake::Lightmap m = irbake::readExr(e.path());
    for (const auto& t : m.texels)
      if (t.x + t.y + t.z > 0.0f) sum += (t.x + t.y + t.z) / 3.0, ++n;
  }
  return n ? sum / n : 0.0;
}

}  // namespace

// The sample Cornell box is closed: a sun 1000 W/m² from above never enters. Its paths would take the
// walk's whole budget from the light inside; with budgets by reached light the map keeps its mean.
TEST(SceneInvariance, ASunThatCannotEnterChangesNothingInside) {
  const fs::path dir = scratch("sun_outside");
  const std::string scene = (samples() / "cornell_box.gltf").string();
  const std::vector<std::string> options = {"--texels-per-unit", "40", "--seed", "2", "--quiet"};
  std::vector<std::string> plain{"bake", scene, "-o", (dir / "plain").string()}, sun = plain;
  plain.insert(plain.end(), options.begin(), options.end());
  sun[3] = (dir / "sun").string();
  sun.insert(sun.end(), options.begin(), options.end());
  sun.insert(sun.end(), {"--sun", "0,-1,0,1000"});
  const IrbakeRun a = runIrbake(plain, dir / "plain.txt"), b = runIrbake(sun, dir / "sun.txt");
  ASSERT_EQ(a.code, 0) << a.output;
  ASSERT_EQ(b.code, 0) << b.output;
  const double without = mapMean(dir / "plain"), with = mapMean(dir / "sun");
  ASSERT_GT(without, 0.0);
  EXPECT_NEAR(with / without, 1.0, 0.01) << "map mean " << with << " with the sun, " << without << " without";
  const nlohmann::json report = nlohmann::json::parse(fileText(dir / "sun" / "report.json"));
  EXPECT_EQ(report["vpls"]["lightReach"][0].get<double>(), 0.0);
  const nlohmann::json plainReport = nlohmann::json::parse(fileText(dir / "plain" / "report.json"));
  EXPECT_EQ(report["vpls"]["bounces"], plainReport["vpls"]["bounces"]);
}

// The sample box under a parent node scaled by 1e-3, 1 and 1e6: its emitter is a radiance, so the map is
// the same at every scale. The density rule counts texels per metre, so the test gives each scale the same
// texels per box (60 per metre of the unscaled box).
TEST(SceneInvariance, TheSameBoxInMillimetresOrKilometresBakesTheSameMap) {
  const fs::path dir = scratch("scales");
  nlohmann::json doc = nlohmann::json::parse(fileText(samples() / "cornell_box.gltf"));
  for (auto& b : doc["buffers"])
    if (b.contains("uri")) fs::copy_file(samples() / b["uri"].get<std::string>(), dir / b["uri"].get<std::string>());
  std::vector<double> means;
  for (double scale : {1.0, 1e-3, 1e6}) {
    nlohmann::json scaled = doc;
    nlohmann::json parent = {{"name", "scale"}, {"scale", {scale, scale, scale}}, {"children", scaled["scenes"][0]["nodes"]}};
    scaled["nodes"].push_back(parent);
    scaled["scenes"][0]["nodes"] = {scaled["nodes"].size() - 1};
    const fs::path file = dir / ("box_" + std::to_string(means.size()) + ".gltf");
    std::ofstream(file) << scaled.dump();
    const fs::path out = dir / ("out_" + std::to_string(means.size()));
    const IrbakeRun run = runIrbake({"bake", file.string(), "-o", out.string(), "--vpls", "1024", "--backend", "embree",
                                     "--texels-per-unit", std::to_string(60.0 / scale), "--quiet"}, out.string() + ".txt");
    ASSERT_EQ(run.code, 0) << scale << ": " << run.output;
    means.push_back(mapMean(out));
  }
  ASSERT_GT(means[0], 0.0);
  EXPECT_NEAR(means[1] / means[0], 1.0, 0.01) << "1e-3";
  EXPECT_NEAR(means[2] / means[0], 1.0, 0.01) << "1e6";
}
