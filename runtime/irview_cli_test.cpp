// The irview command end to end: bad input, headless PNG/EXR, walkthrough frames, and a windowed run
// under Xvfb. Scenes are the project's own samples written to the build folder.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "samples/sample_scenes.h"

namespace fs = std::filesystem;

namespace {

fs::path workDir() {
  fs::path d = fs::path(std::getenv("IRBAKE_BINARY_DIR") ? std::getenv("IRBAKE_BINARY_DIR") : ".") / "runtime_cli_test";
  fs::create_directories(d);
  return d;
}

// The samples as glTF (no light maps), written once.
fs::path sampleFile(const std::string& name) {
  static fs::path dir = [] {
    fs::path d = workDir() / "samples";
    irbake::samples::writeSamples(d);
    return d;
  }();
  return dir / (name + ".gltf");
}

struct RunResult {
  int status = -1;
  std::string output;  // stdout + stderr
};

RunResult run(const std::string& args, const std::string& prefix = "") {
  static int counter = 0;
  // One log per process and call: ctest runs the tests of this file as parallel processes.
  fs::path log = workDir() / ("run_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".log");
  std::string cmd = prefix + "\"" IRVIEW_EXE "\" " + args + " > \"" + log.string() + "\" 2>&1";
  int raw = std::system(cmd.c_str());
  RunResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  return r;
}

// Reads an image as float RGB (row 0 at the top).
std::vector<float> readImage(const fs::path& path, int& w, int& h) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return {};
  const auto& spec = in->spec();
  w = spec.width;
  h = spec.height;
  std::vector<float> px(static_cast<size_t>(w) * h * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data());
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = px[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
  return rgb;
}

TEST(IrviewCli, MissingSceneIsAnErrorNamingTheFile) {
  RunResult r = run("no_such_scene.glb --screenshot x.png");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("no_such_scene.glb"), std::string::npos) << r.output;
}

TEST(IrviewCli, GarbageSceneIsAnErrorNamingTheFile) {
  fs::path bad = workDir() / "garbage.gltf";
  std::ofstream(bad) << "{ this is not json";
  RunResult r = run(bad.string() + " --screenshot " + (workDir() / "never.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("garbage.gltf"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(workDir() / "never.png"));
}

TEST(IrviewCli, BadOptionsAreUsageErrors) {
  const std::string scene = sampleFile("furnace").string();
  for (const std::string& opts : {std::string("--view shiny --screenshot a.png"), std::string("--screenshot a.jpg"),
                                  std::string("--camera 7 --screenshot a.png"), std::string("--width 0 --screenshot a.png"),
                                  std::string("--eye 1,2 --target 0,0,0 --screenshot a.png")}) {
    RunResult r = run(scene + " " + opts);
    EXPECT_NE(r.status, 0) << opts;
    EXPECT_NE(r.output.find("error"), std::string::npos) << opts << ": " << r.output;
  }
}

// Without light maps the viewer shows albedo (+ emission) and says so: furnace ρ = 0.5, Le = 1 → 1.5.
TEST(IrviewCli, UnbakedSceneShowsAlbedoWithAWarning) {
  fs::path out = workDir() / "furnace_unbaked.exr";
  fs::remove(out);
  RunResult r = run(sampleFile("furnace").string() + " --eye 0.1,0.2,0.3 --target 1,0.2,0.3 --fov 90 --width 64 --height 48 --screenshot " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("albedo only"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("irview: warning: "), 0u) << r.output;  // its own name, not irbake's
  EXPECT_EQ(r.output.find("irbake:"), std::string::npos) << r.output;
  int w = 0, h = 0;
  auto px = readImage(out, w, h);
  ASSERT_EQ(w, 64);
  ASSERT_EQ(h, 48);
  for (float v : px) ASSERT_NEAR(v, 1.5f, 0.01f);
}

TEST(IrviewCli, WalkthroughWritesNumberedFrames) {
  fs::path out = workDir() / "walk.png";
  RunResult r = run(sampleFile("cornell_box").string() + " --walkthrough 3 --width 48 --height 32 --screenshot " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(fs::exists(workDir() / ("walk_000" + std::to_string(i) + ".png"))) << i;
  EXPECT_FALSE(fs::exists(workDir() / "walk_0003.png"));
}

TEST(IrviewCli, WindowUnderXvfbRendersTenFramesAndWritesAScreenshot) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) GTEST_SKIP() << "xvfb-run not installed (package xvfb)";
  fs::path out = workDir() / "window.png";
  fs::remove(out);
  RunResult r = run(sampleFile("cornell_box").string() + " --window --frames 10 --width 160 --height 120 --screenshot " +
                        out.string(),
                    "xvfb-run -a ");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("after 10 frames"), std::string::npos) << r.output;
  int w = 0, h = 0;
  auto px = readImage(out, w, h);
  ASSERT_EQ(w, 160);
  ASSERT_EQ(h, 120);
  double sum = 0;
  for (float v : px) sum += v;
  EXPECT_GT(sum / px.size(), 0.05) << "screenshot is black";
}

}  // namespace

// Options are checked by range as typed; --help lists them with the exit codes; --version prints one line.
TEST(IrviewCli, OptionRangesHelpAndVersion) {
  const std::string scene = sampleFile("furnace").string();
  for (const char* bad : {"--width 4294967297", "--camera -1", "--fov 180", "--eye 1,2 --target 0,0,0", "--view shiny",
                          "--lightmap-mode l2"}) {
    RunResult r = run(scene + " " + bad + " --screenshot never.png");
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_EQ(r.output.rfind("irview: error: ", 0), 0u) << bad << ": " << r.output;
  }
  RunResult help = run("--help");
  EXPECT_EQ(help.status, 0);
  for (const char* text : {"--screenshot", "--walkthrough", "exit codes:", "  5  invalid data"})
    EXPECT_NE(help.output.find(text), std::string::npos) << text << " missing from:\n" << help.output;
  RunResult version = run("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_EQ(version.output.rfind("irview 0.", 0), 0u) << version.output;
}

// A view that cannot show anything is an error, never a black image with exit 0: --eye equal to
// --target, or a glTF camera whose yfov is π or more.
TEST(IrviewCli, DegenerateViewsAreRefused) {
  const std::string scene = sampleFile("furnace").string();
  const fs::path shot = workDir() / "degenerate.png";
  fs::remove(shot);
  RunResult same = run(scene + " --eye 0.1,0.2,0.3 --target 0.1,0.2,0.3 --screenshot " + shot.string());
  EXPECT_EQ(same.status, 2) << same.output;
  EXPECT_NE(same.output.find("--eye and --target are the same point"), std::string::npos) << same.output;
  for (double yfov : {M_PI, 4.0}) {
    // The sample with one camera node added at its centre (the furnace has none): yfov as given.
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(scene));
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.01}}}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0.1, 0.2, 0.3}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    const fs::path wide = fs::path(scene).parent_path() / "furnace_wide.gltf";  // beside its .bin
    std::ofstream(wide) << doc.dump();
    RunResult r = run(wide.string() + " --camera 0 --width 32 --height 32 --screenshot " + shot.string());
    EXPECT_EQ(r.status, 5) << yfov << ": " << r.output;
    EXPECT_NE(r.output.find("yfov"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(shot));
  }
}

// glTF 2.0's camera rules: yfov in (0, π), znear > 0, zfar > znear when present, aspectRatio > 0 when present, all
// finite 32-bit floats. A camera that breaks one is refused at load with exit 5, naming the file, the camera and
// the field, whichever view is asked for; the same camera written well renders.
TEST(IrviewCli, GltfCameraOutsideTheSpecIsRefusedNamingTheCamera) {
  const std::string scene = sampleFile("furnace").string();
  const fs::path shot = workDir() / "camera_rules.png";
  auto withCamera = [&](const nlohmann::json& perspective, const std::string& name) {
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(scene));
    doc["cameras"] = {{{"type", "perspective"}, {"name", "lens"}, {"perspective", perspective}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0.1, 0.2, 0.3}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    const fs::path file = fs::path(scene).parent_path() / ("furnace_camera_" + name + ".gltf");  // beside its .bin
    std::ofstream(file) << doc.dump();
    return file.string();
  };
  struct Case {
    const char* name;
    nlohmann::json perspective;
    const char* message;
  };
  const Case cases[] = {
      {"yfov_zero", {{"yfov", 0.0}, {"znear", 0.01}}, "camera 0 ('lens'): perspective.yfov 0.0 rad: a perspective view needs 0 < yfov < π"},
      {"yfov_negative", {{"yfov", -0.5}, {"znear", 0.01}}, "camera 0 ('lens'): perspective.yfov -0.5 rad"},
      {"yfov_overflow", {{"yfov", 1e39}, {"znear", 0.01}}, "camera 0 ('lens'): perspective.yfov 1e+39 is not a finite number"},
      {"yfov_string", {{"yfov", "NaN"}, {"znear", 0.01}}, "camera 0 ('lens'): perspective.yfov \"NaN\" is not a finite number"},
      {"znear_zero", {{"yfov", 0.8}, {"znear", 0.0}}, "camera 0 ('lens'): perspective.znear 0.0 must be greater than 0"},
      {"znear_negative", {{"yfov", 0.8}, {"znear", -1.0}}, "camera 0 ('lens'): perspective.znear -1.0 must be greater than 0"},
      {"znear_tiny", {{"yfov", 0.8}, {"znear", 1e-50}}, "camera 0 ('lens'): perspective.znear 1e-50 must be greater than 0"},
      {"zfar_below", {{"yfov", 0.8}, {"znear", 10.0}, {"zfar", 1.0}},
       "camera 0 ('lens'): perspective.zfar 1.0 must be greater than znear 10.0"},
      {"zfar_equal", {{"yfov", 0.8}, {"znear", 0.5}, {"zfar", 0.5}}, "perspective.zfar 0.5 must be greater than znear 0.5"},
      {"aspect_zero", {{"yfov", 0.8}, {"znear", 0.01}, {"aspectRatio", 0.0}}, "perspective.aspectRatio 0.0 must be greater than 0"},
      {"aspect_negative", {{"yfov", 0.8}, {"znear", 0.01}, {"aspectRatio", -1.5}}, "perspective.aspectRatio -1.5 must be greater than 0"},
  };
  for (const Case& c : cases) {
    const std::string file = withCamera(c.perspective, c.name);
    for (const char* view : {"--camera 0", "", "--eye 0.1,0.2,0.3 --target 0,0,0"}) {
      fs::remove(shot);
      RunResult r = run(file + " " + view + " --width 16 --height 16 --screenshot " + shot.string());
      EXPECT_EQ(r.status, 5) << c.name << " " << view << ": " << r.output;
      EXPECT_NE(r.output.find(file + ": camera 0 ('lens'): perspective."), std::string::npos) << r.output;
      EXPECT_NE(r.output.find(c.message), std::string::npos) << c.name << ": " << r.output;
      EXPECT_FALSE(fs::exists(shot)) << c.name;
    }
  }
  // Within the rules (a finite zfar beyond znear, an aspect ratio): the view renders, and it is not black.
  const std::string good = withCamera({{"yfov", 0.8}, {"znear", 0.01}, {"zfar", 100.0}, {"aspectRatio", 1.0}}, "good");
  fs::remove(shot);
  RunResult r = run(good + " --camera 0 --width 16 --height 16 --screenshot " + shot.string());
  ASSERT_EQ(r.status, 0) << r.output;
  int w = 0, h = 0;
  const std::vector<float> pixels = readImage(shot, w, h);
  ASSERT_EQ(w, 16);
  double sum = 0.0;
  for (float v : pixels) sum += v;
  EXPECT_GT(sum / pixels.size(), 0.05) << "the furnace seen from inside is lit";
}

// A MOZ_lightmap irview cannot show as written is refused with exit 5 and the material named: a texture that
// does not exist, a texCoord other than 1, an intensity that is negative or not a number (JSON has no NaN:
// a string or null stands for it). The same extension written well renders.
TEST(IrviewCli, BadMozLightmapIsRefusedNamingTheMaterial) {
  const std::string scene = sampleFile("furnace").string();
  const fs::path png = fs::path(scene).parent_path() / "moz_grey.png";  // beside the scene: URIs stay inside
  {
    auto out = OIIO::ImageOutput::create(png.string());
    ASSERT_TRUE(out);
    const unsigned char grey[4 * 4 * 3] = {128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128,
                                           128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128,
                                           128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128,
                                           128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128, 128};
    ASSERT_TRUE(out->open(png.string(), OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, grey));
    out->close();
  }
  // The sample with a texture and MOZ_lightmap = moz on material 0, beside its .bin.
  auto withLightmap = [&](const std::string& name, const nlohmann::json& moz) {
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(scene));
    doc["images"] = {{{"uri", png.filename().string()}}};
    doc["textures"] = {{{"source", 0}}};
    doc["materials"][0]["name"] = "lit_wall";
    doc["materials"][0]["extensions"]["MOZ_lightmap"] = moz;
    doc["extensionsUsed"].push_back("MOZ_lightmap");
    const fs::path file = fs::path(scene).parent_path() / (name + ".gltf");
    std::ofstream(file) << doc.dump();
    return file.string();
  };
  const fs::path shot = workDir() / "moz_refused.png";
  struct Case {
    const char* name;
    nlohmann::json moz;
    const char* says;
  };
  const Case cases[] = {
      {"moz_missing_texture", {{"index", 3}, {"texCoord", 1}, {"intensity", 1.0}}, "names texture 3, which does not exist"},
      {"moz_texcoord_0", {{"index", 0}, {"texCoord", 0}, {"intensity", 1.0}}, "texCoord 0, but light maps use TEXCOORD_1"},
      {"moz_negative", {{"index", 0}, {"texCoord", 1}, {"intensity", -0.5}}, "intensity -0.5 must be a finite number"},
      {"moz_nan_string", {{"index", 0}, {"texCoord", 1}, {"intensity", "NaN"}}, "intensity \"NaN\" must be a finite number"},
      {"moz_null", {{"index", 0}, {"texCoord", 1}, {"intensity", nullptr}}, "intensity null must be a finite number"},
  };
  for (const Case& c : cases) {
    fs::remove(shot);
    RunResult r = run(withLightmap(c.name, c.moz) + " --width 16 --height 16 --screenshot " + shot.string());
    EXPECT_EQ(r.status, 5) << c.name << ": " << r.output;
    EXPECT_NE(r.output.find("material 0 ('lit_wall')"), std::string::npos) << c.name << ": " << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.name << ": " << r.output;
    EXPECT_FALSE(fs::exists(shot)) << c.name;
  }
  RunResult good = run(withLightmap("moz_good", {{"index", 0}, {"texCoord", 1}, {"intensity", 2.0}}) +
                       " --width 16 --height 16 --screenshot " + shot.string());
  EXPECT_EQ(good.status, 0) << good.output;
  EXPECT_TRUE(fs::exists(shot));
}
