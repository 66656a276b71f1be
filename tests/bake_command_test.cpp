// `irbake bake` and `irbake diff` as a user runs them: files written, numbers in them, exit codes.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/output_lock.h"
#include "export/exr_io.h"
#include "raytrace/ray_tracer.h"
#include "scene/gltf_loader.h"
#include "scene/image_codec.h"
#include "texels/texel_samples.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
fs::path scratch(const std::string& name) {
  fs::path d = fs::current_path() / "test_scratch" / "bake_command" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Runs irbake with the arguments (already quoted where needed); returns its exit code and output.
int runIrbake(const std::string& args, std::string* output = nullptr) {
  // One log per test: ctest runs tests as parallel processes.
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path log = fs::current_path() / "test_scratch" / "bake_command" /
                 (std::string(info ? info->name() : "none") + "_output.txt");
  fs::create_directories(log.parent_path());
  std::string cmd = std::string("\"") + IRBAKE_EXE + "\" " + args + " > \"" + log.string() + "\" 2>&1";
  int status = std::system(cmd.c_str());
  if (output) {
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    *output = ss.str();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Quoted for the shell. (Built with append: GCC 12 warns falsely on "\"" + std::string.)
std::string q(const fs::path& p) {
  std::string s(1, '"');
  s.append(p.string());
  s.push_back('"');
  return s;
}

fs::path samplesDir() {
  static fs::path dir = [] {
    // Shared by parallel test processes: never emptied, and `irbake samples` writes each file
    // atomically, so a concurrent writer only ever replaces a complete file by an identical one.
    fs::path d = fs::current_path() / "test_scratch" / "bake_command" / "samples";
    fs::create_directories(d);
    return runIrbake("samples " + q(d) + " --quiet") == 0 ? d : fs::path();
  }();
  return dir;
}

// One up-facing triangle and no light at all (base64 of three float3 positions).
fs::path writeUnlitTriangle(const fs::path& dir) {
  fs::path p = dir / "unlit_triangle.gltf";
  std::ofstream(p) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/"}]})";
  return p;
}

void expectFinite(const Lightmap& m) {
  for (const auto& t : m.texels) ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z));
}
}  // namespace

TEST(BakeCommand, WritesExrGltfAndReportThatMatchTheClosedForm) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path out = scratch("point_over_plane");
  // A file named like a page of an earlier bake with more pages, which irbake did not write.
  Lightmap stale;
  stale.width = stale.height = 2;
  stale.texels.assign(4, glm::vec3(1.0f));
  writeExr(stale, out / "lightmap_1.exr");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(out) +
                       " --backend embree --texels-per-unit 4 --vpls 64 --seed 3",
                   &log),
            0)
      << log;
  ASSERT_TRUE(fs::exists(out / "lightmap_0.exr")) << log;
  ASSERT_TRUE(fs::exists(out / "scene.gltf")) << log;
  ASSERT_TRUE(fs::exists(out / "report.json")) << log;
  // Named like a page of an earlier bake, but not written by irbake (the folder's manifest does not list
  // it): left where it is, with a warning naming it.
  EXPECT_TRUE(fs::exists(out / "lightmap_1.exr"));
  EXPECT_NE(log.find("left " + (out / "lightmap_1.exr").string()), std::string::npos) << log;
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_FALSE(isIrbakeTempName(e.path().filename().string())) << "temp file left: " << e.path();

  nlohmann::json report = nlohmann::json::parse(std::ifstream(out / "report.json"));
  EXPECT_EQ(report["backend"], "embree");
  EXPECT_EQ(report["reportSchema"].get<int>(), 2);
  EXPECT_EQ(report["irbakeVersion"].get<std::string>().rfind("irbake 0.", 0), 0u) << report["irbakeVersion"];
  for (const char* stage : {"load", "atlas", "texels", "vpls", "backend", "post", "bake"})
    EXPECT_TRUE(report["timings"]["seconds"].contains(stage)) << stage;
  EXPECT_GT(report["timings"]["memoryPeakMiB"].get<double>(), 1.0);
  EXPECT_GT(report["texels"]["valid"].get<size_t>(), 1000u);

  // The exported glTF's TEXCOORD_1 and the EXR agree with the closed form I·h/(π r³) at every
  // valid texel (the plane faces nothing, so there is no bounce light).
  Scene baked = loadScene(out / "scene.gltf", LoadOptions{false, true});
  Lightmap map = readExr(out / "lightmap_0.exr");
  expectFinite(map);
  RayTracer rt(baked);
  auto texels = buildTexelSamples(baked, rt, {});
  ASSERT_GE(texels.size(), 1u);
  ASSERT_EQ(texels[0].width, map.width);
  size_t checked = 0;
  double worst = 0.0;
  for (size_t i = 0; i < texels[0].layerSize(); ++i) {
    if (!texels[0].valid[i]) continue;
    glm::vec3 p(texels[0].positionWeight[i]);
    double r = glm::length(p - glm::vec3(0, 1, 0));
    double exact = 10.0 * 1.0 / (M_PI * r * r * r);
    worst = std::max(worst, std::abs(map.texels[i].x - exact) / exact);
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
  std::printf("point over plane via irbake bake: %zu texels, worst relative error %.2e\n", checked, worst);
  EXPECT_LT(worst, 5e-3);

  // `irbake info` prints the MOZ_lightmap intensity the file holds (the specification's lux scale).
  std::string infoLog;
  ASSERT_EQ(runIrbake("info " + q(out / "scene.gltf"), &infoLog), 0) << infoLog;
  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(out / "scene.gltf"));
  const double written = gltf["materials"][0]["extensions"]["MOZ_lightmap"]["intensity"].get<double>();
  const size_t at = infoLog.find("irradiance = decoded × ");
  ASSERT_NE(at, std::string::npos) << infoLog;
  const double printed = std::stod(infoLog.substr(at + std::string("irradiance = decoded × ").size()));
  EXPECT_NEAR(printed, written, 1e-3 * written) << infoLog;
}

// -o OUT.glb: one GLB with the light-map PNG embedded (no .gltf/.bin/.png beside it), the EXR page
// and the report beside it; the embedded PNG × intensity is the EXR within the 8-bit encoding's error.
TEST(BakeCommand, GlbOutputEmbedsTheLightMap) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path out = scratch("glb");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(out / "plane.glb") +
                       " --backend embree --texels-per-unit 4 --vpls 64 --quiet",
                   &log),
            0)
      << log;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{".irbake-manifest", "lightmap_0.exr", "plane.glb", "report.json"}));
  Scene baked = loadScene(out / "plane.glb");
  Lightmap map = readExr(out / "lightmap_0.exr");
  ASSERT_FALSE(baked.primitives.empty());
  const Material& m = baked.materials.at(baked.primitives[0].material);
  ASSERT_GE(m.lightmapTexture, 0);
  const Texture& png = baked.textures.at(m.lightmapTexture);
  ASSERT_EQ(png.width, map.width);
  ASSERT_EQ(png.height, map.height);
  double sumPng = 0.0, sumExr = 0.0;
  for (size_t i = 0; i < map.texels.size(); ++i) {
    sumPng += png.texels[i].r * m.lightmapIntensity;
    sumExr += std::min(map.texels[i].r, m.lightmapIntensity);  // the PNG clips at its range
  }
  EXPECT_GT(sumExr, 0.0);
  EXPECT_NEAR(sumPng / sumExr, 1.0, 0.01);
}

// --portable: a GLB whose unlit base-colour texture, on the atlas UVs, is the plane's base colour 0.5 × the
// baked map (sRGB 8-bit), listed in the report with its page scale; the main export keeps MOZ_lightmap.
TEST(BakeCommand, PortableGlbHoldsBaseColourTimesTheMapUnlit) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path out = scratch("portable");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(out / "bake") + " --portable " +
                          q(out / "plane.glb") + " --backend embree --texels-per-unit 4 --vpls 64 --quiet",
                      &log),
            0)
      << log;
  Lightmap map = readExr(out / "bake" / "lightmap_0.exr");
  Scene portable = loadScene(out / "plane.glb");
  ASSERT_FALSE(portable.primitives.empty());
  const Material& m = portable.materials.at(portable.primitives[0].material);
  ASSERT_GE(m.baseColorTexture, 0);
  EXPECT_EQ(m.lightmapTexture, -1);
  EXPECT_EQ(m.baseColorFactor, glm::vec4(1.0f));
  const Texture& tex = portable.textures.at(m.baseColorTexture);
  ASSERT_EQ(tex.width, map.width);
  ASSERT_EQ(tex.height, map.height);
  // Valid texels: 0.5 × map over the file's range (chosen so that at most 0.1% of lit texels clip), clipped at
  // 1, rounded to the nearest 8-bit sRGB code (half a code apart); a texel whose centre lies just outside the
  // chart takes its covered neighbours' mean (within one code).
  const auto summary = nlohmann::json::parse(std::ifstream(out / "bake" / "report.json"))["portable"];
  const float range = summary["range"].get<float>();
  ASSERT_GE(range, 1.0f);
  size_t compared = 0, rounded = 0, clipped = 0;
  for (size_t i = 0; i < map.texels.size(); ++i) {
    if (!map.valid[i]) continue;
    const float want = std::min(1.0f, 0.5f * map.texels[i].r / range);
    clipped += 0.5f * map.texels[i].r > range;
    const float codes = std::abs(linearToSrgb(tex.texels[i].r) - linearToSrgb(want)) * 255.0f;
    EXPECT_LE(codes, 1.0f) << "texel " << i;
    rounded += codes <= 0.5f + 1e-3f;
    ++compared;
  }
  EXPECT_GT(compared, map.texels.size() / 4);
  EXPECT_GE(static_cast<double>(rounded) / compared, 0.98) << rounded << " of " << compared;
  EXPECT_LE(static_cast<double>(clipped) / compared, 1e-3) << clipped << " of " << compared << " clip at range " << range;
  std::ifstream portableFile(out / "plane.glb", std::ios::binary);
  std::string glb((std::istreambuf_iterator<char>(portableFile)), std::istreambuf_iterator<char>());
  EXPECT_NE(glb.find("\"extensionsUsed\":[\"KHR_materials_unlit\"]"), std::string::npos);
  EXPECT_EQ(glb.find("MOZ_lightmap"), std::string::npos);
  EXPECT_EQ(glb.find("KHR_lights_punctual"), std::string::npos);
  const auto report = nlohmann::json::parse(std::ifstream(out / "bake" / "report.json"));
  EXPECT_EQ(report["portable"]["pages"][0]["scale"], 1);
  EXPECT_EQ(report["portable"]["exposure"], 1.0);
  EXPECT_NE(std::find(report["outputs"].begin(), report["outputs"].end(), (out / "plane.glb").string()), report["outputs"].end());
  Scene baked = loadScene(out / "bake" / "scene.gltf");
  EXPECT_GE(baked.materials.at(baked.primitives[0].material).lightmapTexture, 0);
}

TEST(BakeCommand, SunFromTheCommandLineLightsAnUnlitScene) {
  fs::path dir = scratch("sun");
  fs::path scene = writeUnlitTriangle(dir);
  std::string log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "out") + " --backend embree", &log), 7) << log;  // NoLight
  EXPECT_NE(log.find("unlit_triangle.gltf"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "out" / "lightmap_0.exr"));
  // Straight down, E = 3 W/m²: map = E/π on the whole triangle.
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "out") + " --backend embree --no-gltf --sun 0,-1,0,3 "
                       "--texels-per-unit 32 --report " + q(dir / "r.json"), &log), 0) << log;
  EXPECT_TRUE(fs::exists(dir / "r.json"));
  EXPECT_FALSE(fs::exists(dir / "out" / "scene.gltf"));
  Lightmap m = readExr(dir / "out" / "lightmap_0.exr");
  expectFinite(m);
  // Every texel (valid or filled by dilation) holds E/π: one flat triangle under a sun.
  for (const auto& t : m.texels) EXPECT_NEAR(t.y, 3.0 / M_PI, 1e-4);
}

TEST(BakeCommand, BadArgumentsGiveTheUsageExitCode) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("badargs");
  fs::path scene = samplesDir() / "point_over_plane.gltf";
  std::string log;
  EXPECT_EQ(runIrbake("bake", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene), &log), 2) << log;  // no -o
  EXPECT_NE(log.find("-o"), std::string::npos) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --frobnicate", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --backend vulkan", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --vpls 0", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --bounces -3", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --final-gather sometimes", &log), 2) << log;
  EXPECT_NE(log.find("--final-gather"), std::string::npos) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --gather-rays 0", &log), 2) << log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " --sun 0,-1,0", &log), 2) << log;
  EXPECT_NE(log.find("--sun: needs 4 comma-separated numbers"), std::string::npos) << log;
  // Integers beyond int range are refused as typed, never wrapped (4294967297 used to run 1 path,
  // 4294967299 to become seed 3).
  for (const char* option : {"--vpls 4294967297", "--vpls 2147483648", "--seed 4294967299", "--bounces 1e3"}) {
    EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir) + " " + option, &log), 2) << log;
    const std::string value = std::string(option).substr(std::string(option).find(' ') + 1);
    EXPECT_NE(log.find("got '" + value + "'"), std::string::npos) << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
  EXPECT_EQ(runIrbake("diff " + q(dir), &log), 2) << log;
  // No output was left behind by any failed run.
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(BakeCommand, MissingAndBrokenFilesGiveIoAndParseExitCodes) {
  fs::path dir = scratch("badfiles");
  std::string log;
  EXPECT_EQ(runIrbake("bake " + q(dir / "missing.gltf") + " -o " + q(dir / "out"), &log), 3) << log;  // Io
  EXPECT_NE(log.find("missing.gltf"), std::string::npos) << log;
  std::ofstream(dir / "junk.gltf") << "this is not json";
  EXPECT_EQ(runIrbake("bake " + q(dir / "junk.gltf") + " -o " + q(dir / "out"), &log), 4) << log;  // Parse
  EXPECT_NE(log.find("junk.gltf"), std::string::npos) << log;
  EXPECT_EQ(runIrbake("diff " + q(dir / "a") + " " + q(dir / "b"), &log), 3) << log;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(BakeCommand, DiffScoresTwoBakesOfTheSameAtlas) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("diff");
  fs::path scene = samplesDir() / "corner.gltf";
  std::string log;
  const std::string common = " --backend embree --texels-per-unit 6 --bounces 1 ";
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "a") + common + "--vpls 64 --seed 1", &log), 0) << log;
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "b") + common + "--vpls 512 --seed 2", &log), 0) << log;
  ASSERT_EQ(runIrbake("diff " + q(dir / "a") + " " + q(dir / "a") + " --json", &log), 0) << log;
  nlohmann::json same = nlohmann::json::parse(log);
  EXPECT_EQ(same["relativeRmse"].get<double>(), 0.0);
  EXPECT_EQ(same["maxError"].get<double>(), 0.0);
  EXPECT_TRUE(same["areaWeighted"].get<bool>());
  // The corner's floor and wall are 3 × 3 m each: the area weights add up to the 18 m² lightmapped.
  EXPECT_NEAR(same["weightSum"].get<double>(), 18.0, 0.5);
  ASSERT_EQ(runIrbake("diff " + q(dir / "a") + " " + q(dir / "b") + " --json", &log), 0) << log;
  nlohmann::json d = nlohmann::json::parse(log);
  std::printf("corner, 64 vs 512 paths: relative RMSE %.4f, bias %.4f%%\n", d["relativeRmse"].get<double>(),
              100.0 * d["relativeBias"].get<double>());
  EXPECT_GT(d["relativeRmse"].get<double>(), 0.0);
  EXPECT_LT(d["relativeRmse"].get<double>(), 0.2);  // same atlas, same direct light: only VPL noise differs
  ASSERT_EQ(runIrbake("diff " + q(dir / "a" / "lightmap_0.exr") + " " + q(dir / "b" / "lightmap_0.exr"), &log), 0) << log;
  EXPECT_NE(log.find("relative RMSE"), std::string::npos) << log;
}

TEST(BakeCommand, DefaultBackendIsGlAndAgreesWithEmbree) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("default_gl");
  fs::path scene = samplesDir() / "point_over_plane.gltf";
  std::string log;
  const std::string common = " --texels-per-unit 4 --vpls 64 --seed 5";
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "gl") + common, &log), 0) << log;
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "embree") + " --backend embree" + common, &log), 0) << log;
  nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "gl" / "report.json"));
  EXPECT_EQ(report["backend"], "gl");
  EXPECT_FALSE(report["renderer"].get<std::string>().empty());
  ASSERT_EQ(runIrbake("diff " + q(dir / "gl") + " " + q(dir / "embree") + " --json", &log), 0) << log;
  nlohmann::json d = nlohmann::json::parse(log);
  std::printf("point over plane, GL vs Embree: relative RMSE %.3g, max error %.3g\n", d["relativeRmse"].get<double>(),
              d["maxError"].get<double>());
  EXPECT_LT(d["relativeRmse"].get<double>(), 1e-3);  // direct light only: both exact up to shadow-map bias
}

// --cube-face sets the GL backend's VPL cube face size; by default it follows the light map (128..256).
TEST(BakeCommand, CubeFaceSizeIsAutomaticOrSet) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("cube_face");
  fs::path scene = samplesDir() / "cornell_box.gltf";
  std::string log;
  const std::string common = " --texels-per-unit 20 --vpls 64";
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "auto") + common, &log), 0) << log;
  ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "set") + common + " --cube-face 96", &log), 0) << log;
  const int automatic = nlohmann::json::parse(std::ifstream(dir / "auto" / "report.json"))["gl"]["cubeFaceSize"];
  const int set = nlohmann::json::parse(std::ifstream(dir / "set" / "report.json"))["gl"]["cubeFaceSize"];
  EXPECT_GE(automatic, 128);
  EXPECT_LE(automatic, 256);
  EXPECT_EQ(set, 96);
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "bad") + " --cube-face 4", &log), 2) << log;
  EXPECT_NE(log.find("--cube-face"), std::string::npos) << log;
}

// --clamp 0 is no clamp, --clamp B that bound, none derives it; --bounces N is exactly N, auto follows the energy.
TEST(BakeCommand, ClampAndBouncesAreAutomaticOffOrSet) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("clamp_modes");
  fs::path scene = samplesDir() / "cornell_box.gltf";
  std::string log;
  const std::string common = " --backend embree --texels-per-unit 4 --vpls 64 --no-gltf";
  auto report = [&](const std::string& name, const std::string& options) {
    EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / name) + common + options, &log), 0) << log;
    return nlohmann::json::parse(std::ifstream(dir / name / "report.json"));
  };
  const nlohmann::json derived = report("derived", ""), off = report("off", " --clamp 0 --bounces 1"),
                       fixed = report("fixed", " --clamp 2.5 --bounces auto");
  EXPECT_TRUE(derived["eval"]["clampDerived"].get<bool>());
  EXPECT_GT(derived["eval"]["clampBound"].get<double>(), 0.0);
  EXPECT_FALSE(off["eval"]["clampDerived"].get<bool>());
  EXPECT_EQ(off["eval"]["clampBound"].get<double>(), 0.0);
  EXPECT_FALSE(fixed["eval"]["clampDerived"].get<bool>());
  EXPECT_EQ(fixed["eval"]["clampBound"].get<double>(), 2.5);
  EXPECT_EQ(off["vpls"]["bounces"].get<int>(), 1);
  EXPECT_GT(derived["vpls"]["bounces"].get<int>(), 1);  // the box's ρ̄ ≈ 0.67 walks deeper than one bounce
  EXPECT_EQ(fixed["vpls"]["bounces"], derived["vpls"]["bounces"]);
}

TEST(BakeCommand, ReferenceBackendReportsItsSamplesAndMatchesTheClosedForm) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("reference");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(dir) +
                          " --backend reference --spp 4 --texels-per-unit 2 --no-gltf",
                      &log),
            0)
      << log;
  nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "report.json"));
  EXPECT_EQ(report["backend"], "reference");
  EXPECT_EQ(report["reference"]["spp"].get<int>(), 4);
  // Nothing faces the plane: every path's light is the exact next-event term, so no noise.
  EXPECT_LT(report["reference"]["relativeStandardError"].get<double>(), 1e-4);
  Lightmap m = readExr(dir / "lightmap_0.exr");
  expectFinite(m);
  double peak = 0.0;
  for (const auto& t : m.texels) peak = std::max(peak, double(t.x));
  // The brightest texel centre is within half a texel (s) of the foot of the light on each axis:
  // between I·h/(π r³) at r = sqrt(1 + 2 s²) and the value right under the light, I/π.
  double s = 0.5 / report["atlas"]["texelsPerUnit"].get<double>();
  EXPECT_LE(peak, 10.0 / M_PI * 1.0001);
  EXPECT_GE(peak, 10.0 / (M_PI * std::pow(1.0 + 2 * s * s, 1.5)) * 0.9999);
}

// --help is generated (every option, the exit codes); --version names the version and commit.
TEST(BakeCommand, HelpListsOptionsAndExitCodesAndVersionIsPrinted) {
  std::string log;
  ASSERT_EQ(runIrbake("bake --help-all", &log), 0) << log;
  for (const char* option : {"--vpls", "--bounces", "--texels-per-unit", "--max-texels", "--seed", "--sun", "--quiet"})
    EXPECT_NE(log.find(option), std::string::npos) << option;
  EXPECT_NE(log.find("exit codes:"), std::string::npos) << log;
  EXPECT_NE(log.find("  2  usage error"), std::string::npos) << log;
  EXPECT_NE(log.find("  7  no light"), std::string::npos) << log;
  ASSERT_EQ(runIrbake("--help", &log), 0) << log;
  EXPECT_NE(log.find("  3  I/O error"), std::string::npos) << log;
  ASSERT_EQ(runIrbake("--version", &log), 0) << log;
  EXPECT_EQ(log.rfind("irbake 0.", 0), 0u) << log;
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
}

// --texels-per-unit 1e6 on the Cornell box (570 MB and 16 warnings before) fails at once against the
// texel budget, naming a density that fits; that density then passes the same budget.
TEST(BakeCommand, TexelBudgetRefusesAnAtlasTooLargeAndNamesTheDensityThatFits) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("texel_budget");
  fs::path scene = samplesDir() / "cornell_box.gltf";
  std::string log;
  EXPECT_EQ(runIrbake("bake " + q(scene) + " -o " + q(dir / "out") + " --texels-per-unit 1e6", &log), 2) << log;
  EXPECT_NE(log.find("cornell_box.gltf"), std::string::npos) << log;
  EXPECT_NE(log.find("over the budget of 16.78 M (--max-texels 16777216)"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "out" / "lightmap_0.exr"));
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));

  const std::string budget = " --max-texels 100000";
  EXPECT_EQ(runIrbake("unwrap " + q(scene) + " -o " + q(dir / "u.gltf") + " --texels-per-unit 1e6" + budget, &log), 2)
      << log;
  const std::string marker = "use --texels-per-unit ";
  const size_t at = log.find(marker);
  ASSERT_NE(at, std::string::npos) << log;
  const double fits = std::stod(log.substr(at + marker.size()));
  // Cornell box: 5 walls of 0.555² m² plus two blocks ≈ 2.1 m²; 1e5 × 0.6 / 2.1 m² → about 170 texels/m.
  EXPECT_GT(fits, 100.0);
  EXPECT_LT(fits, 250.0);
  ASSERT_EQ(runIrbake("unwrap " + q(scene) + " -o " + q(dir / "u.gltf") + " --texels-per-unit " + std::to_string(fits) +
                          budget + " --report " + q(dir / "u.json"),
                      &log),
            0)
      << log;
  nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "u.json"));
  size_t texels = 0;
  for (const auto& p : report["pages"]) texels += p["width"].get<size_t>() * p["height"].get<size_t>();
  EXPECT_LE(texels, 100000u);
  EXPECT_GT(texels, 30000u);  // the named density uses the budget, not a small part of it
}

// A bake into a folder another bake holds fails at once (exit 3, the folder named) and writes nothing;
// once the holder is gone the same command bakes and leaves no lock file.
TEST(BakeCommand, SecondBakeIntoABusyFolderFailsAtOnce) {
  ASSERT_FALSE(samplesDir().empty());
  fs::path dir = scratch("busy");
  fs::path out = dir / "out";
  fs::path scene = samplesDir() / "point_over_plane.gltf";
  const std::string command = "bake " + q(scene) + " -o " + q(out) + " --backend embree --texels-per-unit 2 --vpls 16";
  std::string log;
  {
    OutputFolderLock holder(out);  // stands for a bake in progress (flock conflicts across processes)
    EXPECT_EQ(runIrbake(command, &log), 3) << log;
    EXPECT_NE(log.find(out.string()), std::string::npos) << log;
    EXPECT_NE(log.find("output folder is busy"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(out / "lightmap_0.exr"));
    EXPECT_FALSE(fs::exists(out / "report.json"));
  }
  ASSERT_EQ(runIrbake(command, &log), 0) << log;
  EXPECT_TRUE(fs::exists(out / "lightmap_0.exr"));
  EXPECT_FALSE(fs::exists(out / OutputFolderLock::kFileName));
}

// On a terminal (a pty from `script`): a bar for each stage, through compensation, post and writing,
// and every log line starts at the beginning of a line, never glued onto a bar. --quiet draws none.
TEST(BakeCommand, ProgressBarsOnATerminalNeverGlueLogLinesAndQuietDrawsNone) {
  ASSERT_FALSE(samplesDir().empty());
  if (std::system("command -v script > /dev/null 2>&1") != 0) GTEST_SKIP() << "no `script` (util-linux) to give irbake a terminal";
  fs::path dir = scratch("terminal");
  auto runOnTerminal = [&](const std::string& args) {
    fs::path log = dir / "terminal.txt";
    std::string inner = std::string(IRBAKE_EXE) + " bake '" + (samplesDir() / "cornell_box.gltf").string() + "' -o '" +
                        (dir / "out").string() + "' --texels-per-unit 8 --vpls 32 " + args;
    std::string cmd = "script -qec \"" + inner + "\" /dev/null > \"" + log.string() + "\" 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream in(log);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string shown = runOnTerminal("");
  for (const char* stage : {"atlas", "compensate", "post", "write"})
    EXPECT_NE(shown.find(std::string("\r") + stage), std::string::npos) << stage << " has no bar in:\n" << shown;
  size_t lines = 0;
  for (size_t at = shown.find("irbake: "); at != std::string::npos; at = shown.find("irbake: ", at + 1), ++lines) {
    const bool fresh = at == 0 || shown[at - 1] == '\n' || shown.compare(at >= 4 ? at - 4 : 0, 4, "\r\033[K") == 0;
    EXPECT_TRUE(fresh) << "log line glued onto a bar at byte " << at << ":\n" << shown;
  }
  EXPECT_GE(lines, 2u) << shown;  // "GL backend: ..." (during the bars) and "baked ..."
  const std::string quiet = runOnTerminal("--quiet");
  EXPECT_EQ(quiet.find("ETA"), std::string::npos) << quiet;
  EXPECT_NE(quiet.find("lightmap_0.exr"), std::string::npos) << quiet;
}

// The same scene, options and seed give byte-identical EXR pages, glTF, .bin and PNGs on either backend
// and any thread count (twice each); the geometry (.bin) does not depend on the backend.
TEST(BakeCommand, IdenticalBytesForAnyThreadCountAndRun) {
  const fs::path scene = samplesDir() / "cornell_box.gltf";
  const fs::path dir = scratch("identical_bytes");
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  std::map<std::string, std::string> firstBin;
  for (const char* backend : {"gl", "embree"}) {
    std::vector<fs::path> runs;
    for (int threads : {1, 2})
      for (int again = 0; again < 2; ++again) {
        const fs::path out = dir / (std::string(backend) + "_t" + std::to_string(threads) + "_" + std::to_string(again));
        std::string log;
        ASSERT_EQ(runIrbake("bake " + q(scene) + " -o " + q(out) + " --backend " + backend +
                                " --vpls 96 --texels-per-unit 60 --seed 5 --quiet --threads " + std::to_string(threads),
                            &log),
                  0)
            << log;
        runs.push_back(out);
      }
    std::vector<std::string> files;  // every output but the report (its timings differ) and the manifest (its hash)
    for (const auto& entry : fs::directory_iterator(runs[0]))
      if (entry.path().filename() != "report.json" && entry.path().filename() != ".irbake-manifest")
        files.push_back(entry.path().filename().string());
    EXPECT_GE(files.size(), 4u);  // EXR page, glTF, .bin, light-map PNG
    for (const std::string& file : files) {
      const std::string reference = bytes(runs[0] / file);
      ASSERT_FALSE(reference.empty()) << file;
      for (size_t r = 1; r < runs.size(); ++r) EXPECT_TRUE(bytes(runs[r] / file) == reference) << runs[r] / file;
    }
    // The report too, once its "timings" object (all that may differ between runs) is set aside.
    auto reportWithoutTimings = [&](const fs::path& run) {
      nlohmann::json r = nlohmann::json::parse(bytes(run / "report.json"));
      EXPECT_TRUE(r.contains("timings"));
      r.erase("timings");
      r.erase("outputs");  // the paths written: each run has its own folder
      // The prediction's time weighs the rays by the ray pilot, timed in each run; its memory must not change.
      r["prediction"] = nlohmann::json{{"memoryPeakMiB", r["prediction"]["memoryPeakMiB"]}};
      return r.dump();
    };
    for (size_t r = 1; r < runs.size(); ++r) EXPECT_EQ(reportWithoutTimings(runs[r]), reportWithoutTimings(runs[0]));
    // The geometry: buffer 0 up to the probes' views, appended last (the probes read each backend's map).
    const nlohmann::json doc = nlohmann::json::parse(bytes(runs[0] / "scene.gltf"));
    size_t geometryEnd = std::string::npos;
    for (const char* key : {"coefficients", "offsets", "valid"}) {
      const int accessor = doc["extensions"]["IRBAKE_light_probes"][key];
      const int view = doc["accessors"][accessor]["bufferView"];
      geometryEnd = std::min(geometryEnd, doc["bufferViews"][view].value("byteOffset", size_t(0)));
    }
    firstBin[backend] = bytes(runs[0] / "scene.bin").substr(0, geometryEnd);
    EXPECT_GT(firstBin[backend].size(), 1000u);
  }
  EXPECT_TRUE(firstBin["gl"] == firstBin["embree"]);  // the geometry written does not depend on the backend
}

// --sky lights a bake and travels with the export (root extras "irbakeSky"), so the loader (and
// irview, which draws it behind the scene) get it back.
TEST(BakeCommand, SkyTravelsWithTheExport) {
  const fs::path dir = scratch("sky_export");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(dir) +
                          " --vpls 64 --texels-per-unit 2 --quiet --sky 0.25,0.5,1",
                      &log),
            0)
      << log;
  const Scene back = loadScene(dir / "scene.gltf");
  ASSERT_TRUE(back.environment.present());
  ASSERT_TRUE(back.environment.isUniform());
  EXPECT_EQ(back.environment.uniformRadiance(), glm::vec3(0.25f, 0.5f, 1.0f));
  EXPECT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(dir / "bad") + " --sky 1,-1,1", &log), 2)
      << log;
}

// An environment map travels as its file, mean radiance and rotation; the loader reads the file back
// with the bake's --env-intensity (recovered from the recorded mean) and rotation, so irview draws the sky the bake
// saw: every texel centre's direction returns intensity × the file's texel.
TEST(BakeCommand, EnvironmentMapTravelsWithTheExport) {
  const fs::path dir = scratch("env_export");
  Lightmap map;
  map.width = 8;
  map.height = 4;
  for (int i = 0; i < 32; ++i) map.texels.push_back(glm::vec3(0.1f + 0.05f * i, 0.2f + 0.02f * (i % 8), 0.3f));
  map.valid.assign(32, 1);
  writeExr(map, dir / "sky.exr");
  std::string log;
  ASSERT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(dir / "out") +
                          " --vpls 64 --texels-per-unit 2 --quiet --env " + q(dir / "sky.exr") +
                          " --env-intensity 2.5 --env-rotation 30",
                      &log),
            0)
      << log;
  const Scene back = loadScene(dir / "out" / "scene.gltf");
  ASSERT_TRUE(back.environment.present());
  ASSERT_FALSE(back.environment.isUniform());
  EXPECT_NEAR(back.environment.rotation(), 30.0 * M_PI / 180.0, 1e-6);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const double theta = M_PI * (y + 0.5) / 4, phi = 2 * M_PI * (x + 0.5) / 8 - M_PI, r = 30.0 * M_PI / 180.0;
      const glm::dvec3 m(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const glm::vec3 d(std::cos(r) * m.x + std::sin(r) * m.z, m.y, -std::sin(r) * m.x + std::cos(r) * m.z);
      const glm::vec3 expected = 2.5f * map.texels[size_t(y) * 8 + x], got = back.environment.radiance(d);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5f * expected[c]) << x << "," << y;
    }
}

// The report is part of the all-or-nothing set: when it cannot be written, neither are the glTF,
// its .bin and PNG, nor the EXR pages.
TEST(BakeCommand, ReportIsWrittenWithTheOutputsOrNotAtAll) {
  const fs::path dir = scratch("report_atomic");
  fs::create_directories(dir / "a_folder" / "r.json");  // the report's name is taken by a folder
  std::string log;
  EXPECT_EQ(runIrbake("bake " + q(samplesDir() / "point_over_plane.gltf") + " -o " + q(dir / "out") +
                          " --vpls 32 --texels-per-unit 2 --quiet --report " + q(dir / "a_folder" / "r.json"),
                      &log),
            2)
      << log;  // refused before any work
  EXPECT_NE(log.find("r.json"), std::string::npos) << log;
  for (const char* file : {"scene.gltf", "scene.bin", "lightmap_0.exr", "lightmap_0.png"})
    EXPECT_FALSE(fs::exists(dir / "out" / file)) << file;
}
