#include "viewer_options.h"

#include <algorithm>
#include <cmath>

#include "common/command_line.h"
#include "common/error.h"
#include "common/version.h"

namespace irbake::view {

namespace {

const char* kWindowKeys =
    "window keys: mouse drag look, WASD/QE fly (shift: faster), 1-9 glTF cameras, V view mode,\n"
    "  L light map SH/L0, +/- exposure, F12 screenshot, Esc quit\n";

// The option values as typed on the command line, before the checks that need several of them.
struct RawOptions {
  std::vector<std::string> scenes;
  std::string eye, target, view, screenshot, lightmapMode;
  std::vector<std::string> probeObjects;
};

// "X,Y,Z[,R]": a sphere's centre and radius (default 0.1 m), finite, R > 0.
glm::vec4 parseProbeObject(const std::string& text) {
  std::vector<double> v;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(x))
      throw Error(ErrorCode::Usage, "", "--probe-object: '" + text + "' is not X,Y,Z or X,Y,Z,R (finite numbers)");
    v.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 3 && v.size() != 4)
    throw Error(ErrorCode::Usage, "", "--probe-object: '" + text + "' needs 3 or 4 numbers (X,Y,Z[,R])");
  const double radius = v.size() == 4 ? v[3] : 0.1;
  if (!(radius > 0.0)) throw Error(ErrorCode::Usage, "", "--probe-object: the radius must be positive (got '" + text + "')");
  return glm::vec4(v[0], v[1], v[2], radius);
}

std::unique_ptr<CLI::App> viewerApp(ViewerOptions& o, RawOptions& raw) {
  auto app = cli::makeApp("irview", "Shows a baked glTF (an irbake export) in a window, or renders it headless.");
  app->footer(std::string(kWindowKeys) + exitCodeHelp());
  app->set_version_flag("--version", versionLine("irview"), "print the version and exit");
  app->add_option("SCENE", raw.scenes, "the glTF/GLB to show")->type_name("SCENE.gltf|.glb");
  app->add_option("--camera", o.camera, "start at glTF camera N (0-based; default: the first, else an overview)")
      ->transform(cli::integerIn(0, 1 << 20))->type_name("N");
  app->add_option("--eye", raw.eye, "a look-at view from here (with --target)")->transform(cli::numberList(3))->type_name("X,Y,Z");
  app->add_option("--target", raw.target, "a look-at view towards here (with --eye)")
      ->transform(cli::numberList(3))->type_name("X,Y,Z");
  app->add_option("--fov", o.fovDegrees, "vertical field of view of --eye/--target in degrees (default 50)")
      ->transform(cli::numberIn(1e-3, 179.999))->type_name("DEG");
  app->add_option("--screenshot", raw.screenshot, "render headless (EGL) and exit; EXR is linear radiance")
      ->type_name("OUT.png|OUT.exr");
  app->add_option("--width", o.width, "image or window width (default 1280)")->transform(cli::integerIn(1, 16384))->type_name("W");
  app->add_option("--height", o.height, "image or window height (default 720)")->transform(cli::integerIn(1, 16384))->type_name("H");
  app->add_option("--walkthrough", o.walkthrough, "N frames OUT_0000.png.. along the glTF cameras (or an orbit)")
      ->transform(cli::integerIn(0, 100000))->type_name("N");
  app->add_option("--view", raw.view, "view mode")
      ->check(CLI::IsMember({"lit", "lightmap", "albedo", "charts", "density", "wireframe", "probes"}));
  app->add_option("--probe-object", raw.probeObjects,
                  "a matte white sphere (albedo 1) lit by the baked probes (IRBAKE_light_probes) at its centre; "
                  "repeatable; R default 0.1 m")
      ->type_name("X,Y,Z[,R]")->allow_extra_args(false);
  app->add_option("--lightmap-mode", raw.lightmapMode,
                  "directional maps (IRBAKE_lightmap_directional): sh = L1 with the normal map (default), l0 = the "
                  "plain map only")
      ->check(CLI::IsMember({"sh", "l0"}));
  app->add_option("--exposure", o.exposure, "display exposure in stops (PNG and window)")
      ->transform(cli::numberIn(-64.0, 64.0))->type_name("EV");
  app->add_flag("--window", o.window, "open the window even with --screenshot");
  app->add_option("--frames", o.frames, "window: close after N frames (default 0: until closed)")
      ->transform(cli::integerIn(0, 1 << 30))->type_name("N");
  return app;
}

}  // namespace

std::string viewerUsage() {
  ViewerOptions o;
  RawOptions raw;
  return viewerApp(o, raw)->help();
}

std::optional<ViewerOptions> parseViewerOptions(const std::vector<std::string>& args) {
  ViewerOptions o;
  RawOptions raw;
  auto app = viewerApp(o, raw);
  if (!cli::parse(*app, args)) return std::nullopt;
  if (raw.scenes.size() != 1) throw Error(ErrorCode::Usage, "", "expected exactly one scene file (see 'irview --help')");
  o.scene = raw.scenes[0];
  o.screenshot = raw.screenshot;
  if (!raw.eye.empty() || !raw.target.empty()) {
    if (raw.eye.empty() || raw.target.empty()) throw Error(ErrorCode::Usage, "", "--eye and --target go together");
    auto e = cli::parseNumberList(raw.eye), t = cli::parseNumberList(raw.target);
    o.eye = glm::vec3(e[0], e[1], e[2]);
    o.target = glm::vec3(t[0], t[1], t[2]);
    const glm::dvec3 gap = glm::dvec3(t[0] - e[0], t[1] - e[1], t[2] - e[2]);
    if (!(glm::length(gap) > 1e-6 * std::max({1.0, std::abs(e[0]), std::abs(e[1]), std::abs(e[2])})))
      throw Error(ErrorCode::Usage, "", "--eye and --target are the same point: the view has no direction");
  }
  if (o.walkthrough > 0 && o.screenshot.empty())
    throw Error(ErrorCode::Usage, "", "--walkthrough needs --screenshot OUT.png|OUT.exr (frames are OUT_0000...)");
  if (raw.view == "probes")
    o.showProbes = true;  // the lit view, with the probe grid drawn over it
  else if (!raw.view.empty())
    o.mode = parseViewMode(raw.view);
  for (const std::string& object : raw.probeObjects) o.probeObjects.push_back(parseProbeObject(object));
  if (!raw.lightmapMode.empty()) o.lightmapMode = parseLightmapMode(raw.lightmapMode);
  return o;
}

namespace {
// A glTF camera the viewer can draw from: yfov in (0, π) (glTF: > 0, and a projection needs < π).
ViewCamera usableCamera(const ViewerOptions& o, const Scene& scene, int index, const Bounds3& b) {
  const float yfov = scene.cameras[index].yfov;
  if (!(yfov > 0.0f && yfov < 3.14159f))
    throw Error(ErrorCode::InvalidData, o.scene.string(),
                "camera " + std::to_string(index) + " has yfov " + std::to_string(yfov) +
                    " rad: a perspective view needs 0 < yfov < π (use --eye/--target or another --camera)");
  return fromGltfCamera(scene.cameras[index], b);
}
}  // namespace

ViewCamera startCamera(const ViewerOptions& o, const Scene& scene) {
  const Bounds3 b = scene.bounds();
  if (o.eye) return lookAt(*o.eye, *o.target, o.fovDegrees, b);
  if (o.camera >= 0) {
    if (o.camera >= static_cast<int>(scene.cameras.size()))
      throw Error(ErrorCode::Usage, o.scene.string(),
                  "camera " + std::to_string(o.camera) + " does not exist: the scene has " +
                      std::to_string(scene.cameras.size()) + " camera(s)");
    return usableCamera(o, scene, o.camera, b);
  }
  if (!scene.cameras.empty()) return usableCamera(o, scene, 0, b);
  return overview(b);
}

}  // namespace irbake::view
