// irview's command line. Headless when --screenshot or --walkthrough is given (unless --window).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "view_camera.h"
#include "view_renderer.h"

namespace irbake::view {

struct ViewerOptions {
  std::filesystem::path scene;              // the glTF/GLB to show
  int camera = -1;                          // glTF camera index (0-based); -1: the first camera, else an overview
  std::optional<glm::vec3> eye, target;     // --eye/--target: a look-at view instead of a glTF camera
  float fovDegrees = 50.0f;                 // vertical fov for --eye/--target
  std::filesystem::path screenshot;         // .png (exposure + sRGB) or .exr (linear radiance)
  int width = 1280, height = 720;           // image / window size in pixels
  int walkthrough = 0;                      // N > 0: N frames along the glTF cameras or an orbit
  ViewMode mode = ViewMode::Lit;            // --view
  LightmapMode lightmapMode = LightmapMode::Sh;  // --lightmap-mode: directional maps shaded (sh) or L0 only (l0)
  float exposure = 0.0f;                    // EV stops for PNG and the window
  bool window = false;                      // --window: open a window even when a screenshot is asked for
  int frames = 0;                           // window: close after this many frames (0: until closed)
  std::vector<glm::vec4> probeObjects;      // --probe-object: white spheres lit by the probes (centre xyz, radius w)
  bool showProbes = false;                  // --view probes: the lit view with a sphere at each probe
  bool headless() const { return !window && (!screenshot.empty() || walkthrough > 0); }
};

// Throws Error(Usage) naming the option for bad arguments; nullopt when --help was printed.
std::optional<ViewerOptions> parseViewerOptions(const std::vector<std::string>& args);
std::string viewerUsage();  // the generated --help text

// The starting view: --eye/--target, else --camera (or the first glTF camera), else an overview.
// Throws Error(Usage, scene path) when --camera is out of range.
ViewCamera startCamera(const ViewerOptions& options, const Scene& scene);

}  // namespace irbake::view
