// irview: shows a baked glTF (an irbake export) in a window, or renders it headless.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/log.h"
#include "headless_viewer.h"
#include "viewer_options.h"
#include "viewer_scene.h"
#include "window_viewer.h"

int main(int argc, char** argv) {
  using namespace irbake;
  log::setProgram("irview");
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    std::optional<view::ViewerOptions> parsed = view::parseViewerOptions(args);
    if (!parsed) return 0;  // --help or --version
    const view::ViewerOptions& options = *parsed;
    view::ViewerScene scene = view::loadViewerScene(options.scene);
    for (const auto& w : scene.warnings) log::warn(w);
    if (options.headless()) {
      view::runHeadless(scene, options);
      return 0;
    }
    return view::runWindow(scene, options);
  } catch (const Error& e) {
    std::fprintf(stderr, "irview: error: %s\n", e.what());
    return exitCodeFor(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "irview: error: %s\n", e.what());
    return 1;
  }
}
