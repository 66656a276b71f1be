#include "headless_viewer.h"

#include "common/log.h"
#include "common/progress.h"
#include "glcontext/gl_context.h"
#include "probe_view.h"
#include "screenshot.h"
#include "view_renderer.h"

namespace irbake::view {

std::vector<std::filesystem::path> runHeadless(const ViewerScene& v, const ViewerOptions& o) {
  // Check the output name before any GL work, so a typo fails fast.
  imageFormatFor(o.screenshot);
  // Every output declared before any GL work: never onto the scene's files (its pages), a folder or /proc.
  OutputGuard guard = viewerOutputGuard(v);
  if (o.walkthrough > 0)
    for (int i = 0; i < o.walkthrough; ++i)
      guard.addOutput(frameName(o.screenshot, i), "--walkthrough frame " + std::to_string(i));
  else
    guard.addOutput(o.screenshot, "--screenshot");
  ProbeSphereSun probeSun;
  std::vector<ProbeSphere> probes = probeSpheresFor(o, &probeSun);
  GlContext gl;
  ViewRenderer renderer(v);
  addProbeOverlay(renderer, std::move(probes), probeSun);
  DrawSettings settings;
  settings.mode = o.mode;
  settings.lightmapMode = o.lightmapMode;
  settings.exposure = o.exposure;
  settings.background = skyBackground(v.scene);
  std::vector<std::filesystem::path> written;
  if (o.walkthrough > 0) {
    for (int i = 0; i < o.walkthrough; ++i) {
      RgbaImage img = renderer.render(walkthroughFrame(v.scene, i, o.walkthrough), o.width, o.height, settings);
      written.push_back(frameName(o.screenshot, i));
      writeScreenshot(img, written.back(), o.exposure, guard);
    }
    log::info("wrote " + std::to_string(written.size()) + " walkthrough frames " +
              frameName(o.screenshot, 0).string() + " ..");
    return written;
  }
  RgbaImage img = renderer.render(startCamera(o, v.scene), o.width, o.height, settings);
  writeScreenshot(img, o.screenshot, o.exposure, guard);
  log::info("wrote " + o.screenshot.string() + " (" + std::to_string(o.width) + "x" +
            std::to_string(o.height) + ", " + toString(o.mode) +
            (renderer.directionalPrimitiveCount() ? std::string(", light map ") + toString(o.lightmapMode) : "") + ", " +
            gl.renderer() + ")");
  written.push_back(o.screenshot);
  return written;
}

}  // namespace irbake::view
