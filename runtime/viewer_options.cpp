#include "viewer_options.h"

#include "common/args.h"
#include "common/error.h"

namespace irbake::view {

std::string viewerUsage() {
  return "usage: irview SCENE.gltf|.glb [options]\n"
         "  --camera N             start at glTF camera N (0-based; default: the first, else an overview)\n"
         "  --eye x,y,z --target x,y,z [--fov deg]   a look-at view instead\n"
         "  --screenshot OUT.png|OUT.exr   render headless (EGL) and exit; EXR is linear radiance\n"
         "  --width W --height H   image or window size (default 1280x720)\n"
         "  --walkthrough N        N frames OUT_0000.png.. along the glTF cameras (or an orbit)\n"
         "  --view MODE            lit | lightmap | albedo | charts | density | wireframe\n"
         "  --exposure EV          display exposure in stops (PNG and window)\n"
         "  --window [--frames N]  open the window even with --screenshot; close after N frames\n"
         "window keys: mouse drag look, WASD/QE fly (shift: faster), 1-9 glTF cameras, V view mode,\n"
         "  +/- exposure, F12 screenshot, Esc quit\n";
}

ViewerOptions parseViewerOptions(const std::vector<std::string>& args) {
  ArgParser p(args,
              {"--camera", "--eye", "--target", "--fov", "--screenshot", "--width", "--height", "--walkthrough",
               "--view", "--exposure", "--frames"},
              {"--window", "--help", "-h"});
  if (p.flag("--help") || p.flag("-h")) throw Error(ErrorCode::Usage, "", viewerUsage());
  if (p.positionals().size() != 1)
    throw Error(ErrorCode::Usage, "", "expected exactly one scene file\n" + viewerUsage());
  ViewerOptions o;
  o.scene = p.positionals()[0];
  o.camera = p.intOr("--camera", -1);
  if (p.value("--camera") && o.camera < 0) throw Error(ErrorCode::Usage, "", "--camera needs an index ≥ 0");
  if (p.value("--eye") || p.value("--target")) {
    if (!p.value("--eye") || !p.value("--target"))
      throw Error(ErrorCode::Usage, "", "--eye and --target go together");
    auto e = p.numberList("--eye", 3), t = p.numberList("--target", 3);
    o.eye = glm::vec3(e[0], e[1], e[2]);
    o.target = glm::vec3(t[0], t[1], t[2]);
  }
  o.fovDegrees = static_cast<float>(p.doubleOr("--fov", o.fovDegrees));
  if (o.fovDegrees <= 0.0f || o.fovDegrees >= 180.0f) throw Error(ErrorCode::Usage, "", "--fov must be in (0, 180)");
  o.screenshot = p.valueOr("--screenshot", "");
  o.width = p.intOr("--width", o.width);
  o.height = p.intOr("--height", o.height);
  if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
    throw Error(ErrorCode::Usage, "", "--width/--height must be in 1..16384");
  o.walkthrough = p.intOr("--walkthrough", 0);
  if (o.walkthrough < 0 || o.walkthrough > 100000) throw Error(ErrorCode::Usage, "", "--walkthrough must be in 0..100000");
  if (o.walkthrough > 0 && o.screenshot.empty())
    throw Error(ErrorCode::Usage, "", "--walkthrough needs --screenshot OUT.png|OUT.exr (frames are OUT_0000...)");
  if (auto v = p.value("--view")) o.mode = parseViewMode(*v);
  o.exposure = static_cast<float>(p.doubleOr("--exposure", 0.0));
  o.window = p.flag("--window");
  o.frames = p.intOr("--frames", 0);
  if (o.frames < 0) throw Error(ErrorCode::Usage, "", "--frames must be ≥ 0");
  return o;
}

ViewCamera startCamera(const ViewerOptions& o, const Scene& scene) {
  const Bounds3 b = scene.bounds();
  if (o.eye) return lookAt(*o.eye, *o.target, o.fovDegrees, b);
  if (o.camera >= 0) {
    if (o.camera >= static_cast<int>(scene.cameras.size()))
      throw Error(ErrorCode::Usage, o.scene.string(),
                  "camera " + std::to_string(o.camera) + " does not exist: the scene has " +
                      std::to_string(scene.cameras.size()) + " camera(s)");
    return fromGltfCamera(scene.cameras[o.camera], b);
  }
  if (!scene.cameras.empty()) return fromGltfCamera(scene.cameras[0], b);
  return overview(b);
}

}  // namespace irbake::view
