#include "window_viewer.h"

#include <algorithm>
#include <cstdio>
#include <memory>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "common/error.h"
#include "common/log.h"
#include "probe_view.h"
#include "screenshot.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

constexpr ViewMode kModes[] = {ViewMode::Lit, ViewMode::Lightmap, ViewMode::Albedo,
                               ViewMode::Charts, ViewMode::TexelDensity, ViewMode::Wireframe};

struct WindowState {
  const ViewerScene* scene = nullptr;
  const ViewerOptions* options = nullptr;
  ViewRenderer* renderer = nullptr;
  FlyCamera fly;
  DrawSettings settings;
  float speed = 1.0f;  // m/s, from the scene size
  bool dragging = false;
  double lastX = 0, lastY = 0;
  int screenshotCount = 0;
  bool screenshotRequested = false;
  OutputGuard guard;  // the scene's files are its inputs; each screenshot is declared when first taken
  std::vector<std::filesystem::path> declared;
};

// Screenshot of what the window shows, rendered offscreen at the framebuffer size (PNG: exposure + sRGB).
void takeScreenshot(GLFWwindow* w, WindowState& s, const std::filesystem::path& path) {
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(w, &fw, &fh);
  // A refused name (an input, a folder, one already written) is said and the window goes on.
  try {
    if (std::find(s.declared.begin(), s.declared.end(), path) == s.declared.end()) {
      s.guard.addOutput(path, "screenshot");
      s.declared.push_back(path);
    }
  } catch (const Error& e) {
    log::warn(std::string("screenshot not written: ") + e.what());
    return;
  }
  RgbaImage img = s.renderer->render(s.fly.camera(), std::max(fw, 1), std::max(fh, 1), s.settings);
  writeScreenshot(img, path, s.settings.exposure, s.guard);
  log::info("wrote " + path.string());
}

void onKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  auto& s = *static_cast<WindowState*>(glfwGetWindowUserPointer(w));
  const Scene& scene = s.scene->scene;
  if (key == GLFW_KEY_ESCAPE) {
    glfwSetWindowShouldClose(w, GLFW_TRUE);
  } else if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) {
    size_t i = static_cast<size_t>(key - GLFW_KEY_1);
    if (i < scene.cameras.size()) s.fly.setFrom(fromGltfCamera(scene.cameras[i], scene.bounds()));
  } else if (key == GLFW_KEY_V) {
    auto it = std::find(std::begin(kModes), std::end(kModes), s.settings.mode);
    s.settings.mode = kModes[(it - std::begin(kModes) + 1) % std::size(kModes)];
  } else if (key == GLFW_KEY_L) {
    s.settings.lightmapMode = s.settings.lightmapMode == LightmapMode::Sh ? LightmapMode::L0 : LightmapMode::Sh;
  } else if (key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD) {
    s.settings.exposure += 0.5f;
  } else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) {
    s.settings.exposure -= 0.5f;
  } else if (key == GLFW_KEY_F12) {
    s.screenshotRequested = true;
  }
}

void onMouseButton(GLFWwindow* w, int button, int action, int) {
  auto& s = *static_cast<WindowState*>(glfwGetWindowUserPointer(w));
  if (button == GLFW_MOUSE_BUTTON_LEFT || button == GLFW_MOUSE_BUTTON_RIGHT) {
    s.dragging = action == GLFW_PRESS;
    glfwGetCursorPos(w, &s.lastX, &s.lastY);
  }
}

void onCursor(GLFWwindow* w, double x, double y) {
  auto& s = *static_cast<WindowState*>(glfwGetWindowUserPointer(w));
  if (!s.dragging) return;
  const float radiansPerPixel = 0.004f;
  s.fly.look(-static_cast<float>(x - s.lastX) * radiansPerPixel, -static_cast<float>(y - s.lastY) * radiansPerPixel);
  s.lastX = x;
  s.lastY = y;
}

void onGlfwError(int code, const char* message) { log::debug("glfw error " + std::to_string(code) + ": " + message); }

struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback(onGlfwError);
    if (!glfwInit())
      throw Error(ErrorCode::Gl, "", "cannot open a window (no display?); use --screenshot OUT.png to render headless");
  }
  ~GlfwSession() { glfwTerminate(); }
};

}  // namespace

int runWindow(const ViewerScene& v, const ViewerOptions& o) {
  ProbeSphereSun probeSun;
  std::vector<ProbeSphere> probes = probeSpheresFor(o, &probeSun);  // a bad probe grid fails before the window opens
  OutputGuard guard = viewerOutputGuard(v);
  if (!o.screenshot.empty()) {
    imageFormatFor(o.screenshot);
    guard.addOutput(o.screenshot, "--screenshot");  // a refused name fails before the window opens
  }
  GlfwSession glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE);  // the shader encodes sRGB itself (cheaper than GL's on llvmpipe)
  glfwWindowHint(GLFW_STENCIL_BITS, 0);           // depth only, as viewer_bench measures: no stencil to preserve
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, ("irview - " + o.scene.filename().string()).c_str(),
                                        nullptr, nullptr);
  if (!window)
    throw Error(ErrorCode::Gl, "", "cannot create a window with an OpenGL 3.3 core context; use --screenshot to render headless");
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);  // frame time shows the renderer, not the display's refresh

  WindowState s;
  s.guard = std::move(guard);
  if (!o.screenshot.empty()) s.declared.push_back(o.screenshot);
  s.scene = &v;
  s.options = &o;
  s.settings.mode = o.mode;
  s.settings.lightmapMode = o.lightmapMode;
  s.settings.exposure = o.exposure;
  s.settings.background = skyBackground(v.scene);
  s.settings.encodeSrgb = true;
  s.fly.setFrom(startCamera(o, v.scene));
  s.speed = std::max(0.25f * v.scene.bounds().diagonal(), 1e-3f);
  glfwSetWindowUserPointer(window, &s);
  glfwSetKeyCallback(window, onKey);
  glfwSetMouseButtonCallback(window, onMouseButton);
  glfwSetCursorPosCallback(window, onCursor);

  int status = 0;
  {
    // The renderer's GL objects must go before the context does.
    ViewRenderer renderer(v);
    addProbeOverlay(renderer, std::move(probes), probeSun);
    s.renderer = &renderer;
    double last = glfwGetTime(), titleTime = last, frameSum = 0.0;
    int frame = 0, titleFrames = 0;
    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      const double now = glfwGetTime();
      const float dt = static_cast<float>(std::min(now - last, 0.25));
      last = now;
      glm::vec3 move(0.0f);
      auto down = [&](int k) { return glfwGetKey(window, k) == GLFW_PRESS; };
      if (down(GLFW_KEY_W)) move.z += 1;
      if (down(GLFW_KEY_S)) move.z -= 1;
      if (down(GLFW_KEY_D)) move.x += 1;
      if (down(GLFW_KEY_A)) move.x -= 1;
      if (down(GLFW_KEY_E)) move.y += 1;
      if (down(GLFW_KEY_Q)) move.y -= 1;
      const float boost = down(GLFW_KEY_LEFT_SHIFT) || down(GLFW_KEY_RIGHT_SHIFT) ? 4.0f : 1.0f;
      s.fly.move(move * (s.speed * boost * dt));

      int fw = 0, fh = 0;
      glfwGetFramebufferSize(window, &fw, &fh);
      const double t0 = glfwGetTime();
      if (fw > 0 && fh > 0) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        renderer.draw(s.fly.camera(), fw, fh, s.settings);
      }
      glfwSwapBuffers(window);
      frameSum += glfwGetTime() - t0;
      ++frame;
      ++titleFrames;
      if (now - titleTime > 0.5) {
        char title[256];
        std::snprintf(title, sizeof title, "irview - %s - %.2f ms/frame - %s%s%s - EV %+.1f",
                      o.scene.filename().string().c_str(), 1000.0 * frameSum / titleFrames,
                      toString(s.settings.mode), renderer.directionalPrimitiveCount() ? " - light map " : "",
                      renderer.directionalPrimitiveCount() ? toString(s.settings.lightmapMode) : "",
                      s.settings.exposure);
        glfwSetWindowTitle(window, title);
        titleTime = now;
        titleFrames = 0;
        frameSum = 0.0;
      }
      if (s.screenshotRequested) {
        s.screenshotRequested = false;
        std::filesystem::path path = o.screenshot.empty()
                                         ? std::filesystem::path("irview_" + std::to_string(s.screenshotCount) + ".png")
                                         : (s.screenshotCount == 0 ? o.screenshot : frameName(o.screenshot, s.screenshotCount));
        ++s.screenshotCount;
        takeScreenshot(window, s, path);
      }
      if (o.frames > 0 && frame >= o.frames) {
        if (!o.screenshot.empty()) takeScreenshot(window, s, o.screenshot);
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      }
    }
    log::info("window closed after " + std::to_string(frame) + " frames");
  }
  glfwDestroyWindow(window);
  return status;
}

}  // namespace irbake::view
