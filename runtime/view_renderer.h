// Draws a ViewerScene with OpenGL (3.3 core or later, current context required): one textured draw
// per primitive, since the baked light is view-independent. Offscreen renders are linear radiance.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "view_camera.h"
#include "viewer_scene.h"

namespace irbake::view {

// A light-map-like page (format GL_RGB or GL_RGBA, float texels) as an RGBA16F texture: bilinear, no mipmaps,
// clamped at the edge (the maps, directional maps and shadow masks).
unsigned uploadLightmap(int width, int height, unsigned format, const void* data);

enum class ViewMode { Lit, Lightmap, Albedo, Charts, TexelDensity, Wireframe };
const char* toString(ViewMode mode);
// "lit", "lightmap", "albedo", "charts", "density", "wireframe"; throws Error(Usage) otherwise.
ViewMode parseViewMode(const std::string& name);

// How a directional light map (IRBAKE_lightmap_directional) is shaded: the L1 reconstruction for the normal
// map's normal, or L0 alone (the plain map, for comparison). Without directional maps both are the plain map.
enum class LightmapMode { Sh, L0 };
const char* toString(LightmapMode mode);
// "sh", "l0"; throws Error(Usage) otherwise.
LightmapMode parseLightmapMode(const std::string& name);

struct DrawSettings {
  ViewMode mode = ViewMode::Lit;   // what to show
  LightmapMode lightmapMode = LightmapMode::Sh;  // lit and lightmap views: L1 SH with the normal map, or L0 only
  float exposure = 0.0f;           // EV stops, display only (×2^EV before the sRGB encode)
  bool encodeSrgb = false;         // true: exposure + sRGB in the shader (window); false: linear out
  glm::vec3 background{0.0f};      // clear colour (linear radiance; exposed and encoded like the scene)
  bool drawEnvironment = true;     // a scene with an environment map shows the map behind it (else background)
};

// Linear RGBA float image, row 0 at the top.
struct RgbaImage {
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
  const glm::vec4& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// An offscreen framebuffer: one colour and one 24-bit depth renderbuffer (current context required).
// Throws Error(Gl) when the framebuffer is incomplete.
class RenderTarget {
 public:
  RenderTarget(int width, int height, unsigned colorFormat);  // e.g. GL_RGBA8, GL_RGBA32F
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;
  unsigned framebuffer() const { return fbo_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void release();
  unsigned fbo_ = 0, color_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
};

class ViewRenderer {
 public:
  // Uploads every primitive and texture to the current context.
  explicit ViewRenderer(const ViewerScene& scene);
  ~ViewRenderer();
  ViewRenderer(const ViewRenderer&) = delete;
  ViewRenderer& operator=(const ViewRenderer&) = delete;

  // Draws into the bound framebuffer (viewport = width × height).
  void draw(const ViewCamera& camera, int width, int height, const DrawSettings& settings);
  // Renders into an offscreen float framebuffer and reads it back; settings.encodeSrgb is ignored
  // (always linear), so the pixels are radiance in the scene's units.
  RgbaImage render(const ViewCamera& camera, int width, int height, DrawSettings settings);
  size_t triangleCount() const { return triangles_; }
  // Primitives shaded with directional maps and a normal map in LightmapMode::Sh (0: the mode changes nothing).
  size_t directionalPrimitiveCount() const { return directionalPrimitives_; }
  // Something drawn after the scene in every draw(), depth test on against the scene's depth (the probe
  // spheres, probe_view.h); it gets the camera, its view-projection and the frame's settings.
  using Overlay = std::function<void(const ViewCamera&, const glm::mat4& viewProjection, const DrawSettings&)>;
  void addOverlay(Overlay overlay) { overlays_.push_back(std::move(overlay)); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  size_t triangles_ = 0;
  size_t directionalPrimitives_ = 0;
  std::vector<Overlay> overlays_;
};

// The background colour for a scene: its sky's radiance (a map's mean radiance: the renderer draws the map itself
// over it, DrawSettings::drawEnvironment), black without a sky.
inline glm::vec3 skyBackground(const Scene& scene) {
  if (!scene.environment.present()) return glm::vec3(0.0f);
  if (scene.environment.isUniform()) return scene.environment.uniformRadiance();
  return glm::vec3(scene.environment.integral() / (4.0 * glm::pi<double>()));
}

}  // namespace irbake::view
