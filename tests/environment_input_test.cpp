// --env's pixels are checked on load: a pixel whose radiance × --env-intensity passes the 1e20 W/(m² sr) that
// --sky allows (beyond it the bake's sums leave float) is refused naming the image and the pixel, before the
// bake, and --env-intensity has --sky's cap.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "export/exr_io.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using irbake::testing::IrbakeRun;

namespace {

// An 8×4 environment of radiance 0.5 with pixel (1, 0) at `bright`.
fs::path environment(const fs::path& file, float bright) {
  irbake::Lightmap map;
  map.width = 8;
  map.height = 4;
  map.texels.assign(32, glm::vec3(0.5f));
  map.texels[1] = glm::vec3(bright);
  map.valid.assign(32, 1);
  irbake::writeExr(map, file);
  return file;
}

IrbakeRun bake(const fs::path& dir, const std::string& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args{"bake", (irbake::testing::sampleScenes("environment_input") / "point_over_plane.gltf").string(),
                                "-o", (dir / out).string(), "--texels-per-unit", "2", "--vpls", "16", "--backend",
                                "embree", "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  return irbake::testing::runIrbakeLogged(args, dir / (out + ".txt"));
}

}  // namespace

TEST(EnvironmentInput, PixelsBeyondWhatFloatSumsHoldAreRefusedNamingTheImage) {
  const fs::path dir = irbake::testing::scratchFolder("environment_input", "bright");
  const fs::path huge = environment(dir / "huge.exr", 3e38f);
  const IrbakeRun refused = bake(dir, "huge", {"--env", huge.string()});
  EXPECT_EQ(refused.code, 5) << refused.output;
  EXPECT_NE(refused.output.find(huge.string() + ": environment pixel 1,0 is 3e+38 W/(m² sr) × --env-intensity 1, above "
                                                "the 1e20 W/(m² sr) whose sums a bake keeps finite in float"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(fs::exists(dir / "huge" / "report.json"));
  // 1e19 is within the bound alone and beyond it × 100.
  const fs::path bright = environment(dir / "bright.exr", 1e19f);
  const IrbakeRun scaled = bake(dir, "scaled", {"--env", bright.string(), "--env-intensity", "100"});
  EXPECT_EQ(scaled.code, 5) << scaled.output;
  EXPECT_NE(scaled.output.find(bright.string() + ": environment pixel 1,0 is 1e+19 W/(m² sr) × --env-intensity 100"),
            std::string::npos)
      << scaled.output;
  const IrbakeRun intensity = bake(dir, "intensity", {"--env", environment(dir / "plain.exr", 1.0f).string(),
                                                      "--env-intensity", "1e30"});
  EXPECT_EQ(intensity.code, 2) << intensity.output;
  EXPECT_NE(intensity.output.find("--env-intensity: must be a finite number in [0, 1e+20], got '1e30'"), std::string::npos)
      << intensity.output;
}
