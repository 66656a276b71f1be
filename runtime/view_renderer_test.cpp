// Renderer tests on scenes built in code with closed-form light maps: pixels are compared with
// baseColor × map + emissive evaluated on the CPU at the surface point each pixel sees.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "common/error.h"
#include "glcontext/gl_context.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

constexpr float kPi = 3.14159265358979f;

// A quad p0,p1,p2,p3 (counter-clockwise seen from the side it faces), uv0 and uv1 = the unit square.
void addQuad(Scene& s, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, int material, int page,
             int pageSize) {
  Primitive p;
  p.positions = {p0, p1, p2, p3};
  glm::vec3 n = glm::normalize(glm::cross(p1 - p0, p3 - p0));
  p.normals.assign(4, n);
  p.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  p.uv1 = p.uv0;
  p.indices = {0, 1, 2, 0, 2, 3};
  p.material = material;
  p.lightmap = {page, pageSize, pageSize};
  s.primitives.push_back(p);
}

Lightmap constantPage(int page, int size, glm::vec3 value) {
  Lightmap m;
  m.page = page;
  m.width = m.height = size;
  m.texels.assign(m.size(), value);
  m.valid.assign(m.size(), 1);
  return m;
}

// Inside a closed cube of albedo ρ = 0.5 and emission Le = 0.5: the converged radiance is
// Le/(1−ρ) = 1 everywhere, so the map (irradiance/π = incident radiance) is 1 and every pixel shows
// ρ·1 + Le = 1.
ViewerScene furnaceInside() {
  Scene s;
  Material m;
  m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  m.emissiveFactor = glm::vec3(0.5f);
  s.materials.push_back(m);
  const float a = 1.0f;
  std::vector<Lightmap> pages;
  auto face = [&](glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3) {
    int page = static_cast<int>(pages.size());
    addQuad(s, p0, p1, p2, p3, 0, page, 8);
    pages.push_back(constantPage(page, 8, glm::vec3(1.0f)));
  };
  // Faces wound to face the inside.
  face({-a, -a, -a}, {a, -a, -a}, {a, -a, a}, {-a, -a, a});    // floor, normal +y
  face({-a, a, -a}, {-a, a, a}, {a, a, a}, {a, a, -a});        // ceiling, normal -y
  face({-a, -a, -a}, {-a, -a, a}, {-a, a, a}, {-a, a, -a});    // x = -a, normal +x
  face({a, -a, -a}, {a, a, -a}, {a, a, a}, {a, -a, a});        // x = +a, normal -x
  face({-a, -a, -a}, {-a, a, -a}, {a, a, -a}, {a, -a, -a});    // z = -a, normal +z
  face({-a, -a, a}, {a, -a, a}, {a, a, a}, {-a, a, a});        // z = +a, normal -z
  return makeViewerScene(std::move(s), std::move(pages));
}

TEST(ViewRenderer, FurnaceSeenFromInsideIsOneEverywhere) {
  GlContext gl;
  ViewerScene v = furnaceInside();
  EXPECT_TRUE(v.warnings.empty());
  ViewRenderer r(v);
  EXPECT_EQ(r.triangleCount(), 12u);
  const Bounds3 b = v.scene.bounds();
  // Six directions plus an oblique one: every pixel sees a wall (the eye is inside the closed cube).
  const glm::vec3 targets[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 0.7f, -0.4f}};
  for (const auto& t : targets) {
    RgbaImage img = r.render(lookAt(glm::vec3(0.1f, -0.2f, 0.15f), glm::vec3(0.1f, -0.2f, 0.15f) + t, 100.0f, b),
                             96, 64, {});
    ASSERT_EQ(img.pixels.size(), 96u * 64u);
    float worst = 0.0f;
    for (const auto& p : img.pixels)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(p[c] - 1.0f));
    EXPECT_LT(worst, 0.02f) << "direction " << t.x << "," << t.y << "," << t.z;
  }
}

// A 4 m × 4 m floor (y = 0) with a smooth albedo texture, lit by a point light of intensity I at
// height h: irradiance/π = I h / (π r³). The page stores that at texel centres.
struct PlaneCase {
  ViewerScene view;
  glm::vec3 light{0.3f, 1.0f, -0.2f};
  float intensity = 3.0f;
  float mapAt(glm::vec3 x) const {
    float r = glm::length(light - x);
    return intensity * light.y / (kPi * r * r * r);
  }
};

Texture smoothAlbedo() {
  Texture t;
  t.name = "smooth albedo";
  t.width = t.height = 64;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      float u = (x + 0.5f) / t.width, v = (y + 0.5f) / t.height;
      t.texels.emplace_back(0.45f + 0.3f * std::sin(2 * kPi * u), 0.3f + 0.5f * v, 0.7f - 0.4f * u * v, 1.0f);
    }
  t.wrapS = t.wrapT = WrapMode::ClampToEdge;
  return t;
}

PlaneCase texturedPlane() {
  PlaneCase c;
  Scene s;
  s.textures.push_back(smoothAlbedo());
  Material m;
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  const int size = 256;
  addQuad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0, 0, size);
  // uv0 = uv1 = ((x+2)/4, (z+2)/4).
  auto& p = s.primitives[0];
  for (size_t i = 0; i < 4; ++i) p.uv0[i] = p.uv1[i] = glm::vec2(p.positions[i].x + 2, p.positions[i].z + 2) / 4.0f;
  Lightmap page = constantPage(0, size, glm::vec3(0.0f));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      glm::vec2 uv((x + 0.5f) / size, (y + 0.5f) / size);
      page.texels[static_cast<size_t>(y) * size + x] = glm::vec3(c.mapAt(glm::vec3(uv.x * 4 - 2, 0, uv.y * 4 - 2)));
    }
  c.view = makeViewerScene(std::move(s), {page});
  return c;
}

// The floor point a pixel centre sees (row 0 at the top), or false when the ray misses the floor.
bool floorPointAt(const ViewCamera& cam, int w, int h, int px, int py, glm::vec3& hit) {
  glm::mat4 inv = glm::inverse(cam.projection(static_cast<float>(w) / h) * cam.view());
  glm::vec2 ndc((px + 0.5f) / w * 2 - 1, 1 - (py + 0.5f) / h * 2);
  glm::vec4 a = inv * glm::vec4(ndc, -1, 1), b = inv * glm::vec4(ndc, 0, 1);
  glm::vec3 o = glm::vec3(a) / a.w, d = glm::vec3(b) / b.w - o;
  if (d.y >= 0) return false;
  hit = o + d * (-o.y / d.y);
  return true;
}

TEST(ViewRenderer, TexturedPlaneMatchesAlbedoTimesClosedFormMap) {
  GlContext gl;
  PlaneCase c = texturedPlane();
  ViewRenderer r(c.view);
  const int w = 160, h = 120;
  ViewCamera cam = lookAt({0.2f, 3.0f, 2.5f}, {0, 0, -0.3f}, 55.0f, c.view.scene.bounds());
  RgbaImage img = r.render(cam, w, h, {});
  size_t checked = 0;
  float worst = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 p;
      if (!floorPointAt(cam, w, h, x, y, p) || std::abs(p.x) > 1.9f || std::abs(p.z) > 1.9f) continue;
      glm::vec2 uv = (glm::vec2(p.x, p.z) + 2.0f) / 4.0f;
      glm::vec3 expected = glm::vec3(sampleBilinear(c.view.scene.textures[0], uv)) * c.mapAt(p);
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(img.at(x, y)[k] / expected[k] - 1.0f));
      ++checked;
    }
  EXPECT_GT(checked, static_cast<size_t>(w * h / 3));
  EXPECT_LT(worst, 0.02f);
  // The other views read the same inputs: albedo only and light map only.
  int cx = w / 2, cy = h / 2;
  glm::vec3 p;
  ASSERT_TRUE(floorPointAt(cam, w, h, cx, cy, p));
  glm::vec2 uv = (glm::vec2(p.x, p.z) + 2.0f) / 4.0f;
  RgbaImage albedo = r.render(cam, w, h, {ViewMode::Albedo});
  RgbaImage map = r.render(cam, w, h, {ViewMode::Lightmap});
  EXPECT_NEAR(albedo.at(cx, cy).g, sampleBilinear(c.view.scene.textures[0], uv).g, 0.01f);
  EXPECT_NEAR(map.at(cx, cy).r / c.mapAt(p), 1.0f, 0.02f);
}

// The window's output (draw with encodeSrgb into an 8-bit target): the shader's sRGB encode is a fit
// (no pow()), so check it against the exact IEC 61966-2-1 encode of 2^EV × the linear render, pixel
// by pixel: within one 8-bit step, over dark, mid and clipped values.
TEST(ViewRenderer, DisplayOutputIsTheSrgbEncodeOfTheLinearRenderWithinOneStep) {
  GlContext gl;
  PlaneCase c = texturedPlane();
  ViewRenderer r(c.view);
  const int w = 160, h = 120;
  ViewCamera cam = lookAt({0.2f, 3.0f, 2.5f}, {0, 0, -0.3f}, 55.0f, c.view.scene.bounds());
  RenderTarget target(w, h, GL_RGBA8);
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
  auto exactSrgb = [](float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
  };
  const RgbaImage linear = r.render(cam, w, h, {});  // binds its own framebuffer, restores ours
  int worst = 0, dark = 0, mid = 0, clipped = 0;
  for (float ev : {-6.0f, -3.0f, 0.0f, 2.0f}) {
    DrawSettings display;
    display.encodeSrgb = true;
    display.exposure = ev;
    glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
    r.draw(cam, w, h, display);
    std::vector<uint8_t> rgba(static_cast<size_t>(w) * h * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k) {
          const int got = rgba[(static_cast<size_t>(h - 1 - y) * w + x) * 4 + k];  // GL row 0 = bottom
          const float shown = exactSrgb(std::exp2(ev) * linear.at(x, y)[k]);
          const int expected = static_cast<int>(std::lround(255.0f * shown));
          worst = std::max(worst, std::abs(got - expected));
          dark += expected > 0 && expected < 64;
          mid += expected >= 64 && expected < 200;
          clipped += expected == 255;
        }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  EXPECT_LE(worst, 1);
  EXPECT_GT(dark, 1000);
  EXPECT_GT(mid, 1000);
  EXPECT_GT(clipped, 1000);
}

// Each material feature selects its own shader variant; check each against the CPU: a base colour
// texture read through TEXCOORD_1 (uv0 mirrored, so reading the wrong set shows), an emissive
// texture on TEXCOORD_0 over a base colour factor, and an alpha-masked texture (alpha = u, cutoff
// 0.5) whose holes show the background in the lit, light-map and charts views. Map = 1 everywhere.
TEST(ViewRenderer, MaterialFeaturesMatchTheirClosedForm) {
  GlContext gl;
  Scene s;
  Texture t;
  t.name = "gradient";
  t.width = t.height = 64;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const float u = (x + 0.5f) / t.width;
      t.texels.emplace_back(0.2f + 0.6f * u, 0.5f, 0.8f - 0.6f * u, u);
    }
  t.wrapS = t.wrapT = WrapMode::ClampToEdge;
  s.textures.push_back(t);
  Material onUv1;
  onUv1.baseColorTexture = 0;
  onUv1.baseColorTexCoord = 1;
  Material emissive;
  emissive.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  emissive.emissiveFactor = glm::vec3(0.3f);
  emissive.emissiveTexture = 0;
  Material masked;
  masked.baseColorTexture = 0;
  masked.alphaMode = AlphaMode::Mask;
  masked.alphaCutoff = 0.5f;
  s.materials = {onUv1, emissive, masked};
  std::vector<Lightmap> pages;
  const float x0[3] = {-3.2f, -1.0f, 1.2f};  // quads x0 .. x0 + 2, z -1 .. 1; u = (z + 1)/2, v = (x − x0)/2
  for (int q = 0; q < 3; ++q) {
    addQuad(s, {x0[q], 0, -1}, {x0[q], 0, 1}, {x0[q] + 2, 0, 1}, {x0[q] + 2, 0, -1}, q, q, 8);
    pages.push_back(constantPage(q, 8, glm::vec3(1.0f)));
  }
  for (auto& uv : s.primitives[0].uv0) uv.x = 1.0f - uv.x;
  ViewerScene v = makeViewerScene(std::move(s), std::move(pages));
  ViewRenderer r(v);
  const int w = 200, h = 64;
  ViewCamera cam = lookAt({0, 6, 0.01f}, {0, 0, 0}, 24.0f, v.scene.bounds());
  const RgbaImage lit = r.render(cam, w, h, {});
  const RgbaImage map = r.render(cam, w, h, {ViewMode::Lightmap});
  const RgbaImage charts = r.render(cam, w, h, {ViewMode::Charts});
  const Texture& tex = v.scene.textures[0];
  int checked[3] = {0, 0, 0}, holes = 0;
  float worst = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 p;
      if (!floorPointAt(cam, w, h, x, y, p)) continue;
      for (int q = 0; q < 3; ++q) {
        const glm::vec2 uv((p.z + 1) / 2, (p.x - x0[q]) / 2);
        if (uv.x < 0.05f || uv.x > 0.95f || uv.y < 0.05f || uv.y > 0.95f) continue;
        glm::vec3 expected;
        if (q == 0) expected = glm::vec3(sampleBilinear(tex, uv));
        if (q == 1) expected = glm::vec3(0.5f) + 0.3f * glm::vec3(sampleBilinear(tex, uv));
        if (q == 2) {
          if (std::abs(uv.x - 0.5f) < 0.05f) continue;  // the cut itself
          if (uv.x < 0.5f) {
            ++holes;
            EXPECT_EQ(lit.at(x, y), glm::vec4(0, 0, 0, 1)) << x << "," << y;
            EXPECT_EQ(map.at(x, y), glm::vec4(0, 0, 0, 1)) << x << "," << y;
            EXPECT_EQ(charts.at(x, y), glm::vec4(0, 0, 0, 1)) << x << "," << y;
            continue;
          }
          expected = glm::vec3(sampleBilinear(tex, uv));
        }
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(lit.at(x, y)[k] / expected[k] - 1.0f));
        EXPECT_NEAR(map.at(x, y).r, 1.0f, 1e-3f);
        ++checked[q];
      }
    }
  EXPECT_LT(worst, 0.02f);
  for (int q = 0; q < 3; ++q) EXPECT_GT(checked[q], 150) << "quad " << q;
  EXPECT_GT(holes, 150);
}

// KHR_texture_transform in the shader, the loader's closed form (gltf_loader_test.cpp) on the GPU: a 2-texel
// image (black, white; centres at u = 1/4, 3/4), clamped. UV (1/8, 1/2) with scale (2, 1) and offset (1/4, 0)
// reads u = 1/2, halfway: 0.5; UV (0.3, 0.75) turned by π/2 reads u = 0.75, white (the opposite turn, black);
// the emissive texture takes its own transform. Map = 1, so the pixel is the base colour (+ emission).
TEST(ViewRenderer, TextureTransformMatchesItsClosedForm) {
  GlContext gl;
  struct Case {
    glm::vec2 uv;
    UvTransform base, emissive;
    float expected;
  };
  UvTransform half;
  half.present = true;
  half.scale = {2, 1};
  half.offset = {0.25f, 0};
  UvTransform turn;
  turn.present = true;
  turn.rotation = kPi / 2;
  UvTransform none;
  const Case cases[] = {{{0.125f, 0.5f}, none, none, 0.0f},
                        {{0.125f, 0.5f}, half, none, 0.5f},
                        {{0.3f, 0.75f}, turn, none, 1.0f},
                        {{0.125f, 0.5f}, none, half, 0.5f}};
  for (const Case& c : cases) {
    Scene s;
    Texture t;
    t.width = 2;
    t.height = 1;
    t.texels = {glm::vec4(0, 0, 0, 1), glm::vec4(1.0f)};
    t.wrapS = t.wrapT = WrapMode::ClampToEdge;
    s.textures.push_back(t);
    Material m;
    if (c.emissive.present) {
      m.baseColorFactor = glm::vec4(0, 0, 0, 1);
      m.emissiveFactor = glm::vec3(1.0f);
      m.emissiveTexture = 0;
      m.emissiveUvTransform = c.emissive;
    } else {
      m.baseColorTexture = 0;
      m.baseColorUvTransform = c.base;
    }
    s.materials.push_back(m);
    addQuad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0, 0, 4);
    s.primitives[0].uv0.assign(4, c.uv);
    ViewerScene v = makeViewerScene(std::move(s), {constantPage(0, 4, glm::vec3(1.0f))});
    ViewRenderer r(v);
    const RgbaImage img = r.render(lookAt({0, 2, 0.01f}, {0, 0, 0}, 40.0f, v.scene.bounds()), 32, 32, {});
    EXPECT_NEAR(img.at(16, 16).r, c.expected, 0.01f) << "uv " << c.uv.x << ", " << c.uv.y;
  }
}

TEST(ViewRenderer, MaterialLightmapTextureIsScaledByIntensity) {
  // No float pages: MOZ_lightmap texture (0.25) × intensity (4) = 1, on albedo 0.6.
  GlContext gl;
  Scene s;
  Texture lm;
  lm.width = lm.height = 4;
  lm.texels.assign(16, glm::vec4(0.25f, 0.25f, 0.25f, 1.0f));
  s.textures.push_back(lm);
  Material m;
  m.baseColorFactor = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  m.lightmapTexture = 0;
  m.lightmapIntensity = 4.0f;
  s.materials.push_back(m);
  addQuad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0, 0, 4);
  ViewerScene v = makeViewerScene(std::move(s), {});
  EXPECT_EQ(lightmapSourceOf(v, v.scene.primitives[0]), LightmapSource::MaterialTexture);
  ViewRenderer r(v);
  RgbaImage img = r.render(lookAt({0, 2, 0.01f}, {0, 0, 0}, 40.0f, v.scene.bounds()), 32, 32, {});
  EXPECT_NEAR(img.at(16, 16).r, 0.6f, 0.006f);
}

TEST(ViewRenderer, SceneWithoutLightmapShowsAlbedoAndWarns) {
  GlContext gl;
  Scene s;
  Material m;
  m.baseColorFactor = glm::vec4(0.2f, 0.4f, 0.8f, 1.0f);
  s.materials.push_back(m);
  addQuad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0, -1, 0);
  ViewerScene v = makeViewerScene(std::move(s), {});
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_NE(v.warnings[0].find("albedo only"), std::string::npos);
  ViewRenderer r(v);
  // 90° from 2 m: the 2 m quad fills the middle, the corners see the background.
  RgbaImage img = r.render(lookAt({0, 2, 0.01f}, {0, 0, 0}, 90.0f, v.scene.bounds()), 32, 32, {});
  EXPECT_NEAR(img.at(16, 16).b, 0.8f, 0.005f);
  EXPECT_NEAR(img.at(16, 16).r, 0.2f, 0.005f);
  EXPECT_EQ(img.at(0, 0), glm::vec4(0, 0, 0, 1));  // background outside the quad
}

// The sky is drawn behind the scene, as linear radiance (screenshots) and, on screen, exposed and
// sRGB-encoded like the scene's pixels.
TEST(ViewRenderer, SkyIsTheBackground) {
  GlContext gl;
  Scene s;
  Material m;
  m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials.push_back(m);
  addQuad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0, -1, 0);
  s.environment = Environment::uniform({0.25f, 0.5f, 1.0f});
  ViewerScene v = makeViewerScene(std::move(s), {});
  ViewRenderer r(v);
  DrawSettings settings;
  settings.background = skyBackground(v.scene);
  RgbaImage img = r.render(lookAt({0, 2, 0.01f}, {0, 0, 0}, 90.0f, v.scene.bounds()), 32, 32, settings);
  EXPECT_NEAR(img.at(0, 0).r, 0.25f, 1e-3f);
  EXPECT_NEAR(img.at(0, 0).g, 0.5f, 1e-3f);
  EXPECT_NEAR(img.at(0, 0).b, 1.0f, 1e-3f);
  EXPECT_EQ(skyBackground(Scene{}), glm::vec3(0.0f));  // no sky: black
}

// An environment map is drawn itself behind the scene. A 16 × 8 map with a distinct radiance per texel,
// turned 40° about +Y: every background pixel whose view direction lies inside a texel (not within 2% of a texel
// edge, where float and double directions may pick different neighbours) shows exactly the texel the baker's
// Environment::radiance reads for that direction; pixels on the floor quad show the quad. On screen the same
// pixels are exposed and sRGB-encoded like the scene's.
TEST(ViewRenderer, EnvironmentMapIsDrawnBehindTheScene) {
  GlContext gl;
  const int mapW = 16, mapH = 8;
  std::vector<glm::vec3> texels;
  for (int y = 0; y < mapH; ++y)
    for (int x = 0; x < mapW; ++x)
      texels.emplace_back(0.05f + x / 16.0f, 0.05f + y / 8.0f, 0.3f + 0.02f * static_cast<float>((x * 7 + y * 3) % 11));
  const float rotation = glm::radians(40.0f);
  Scene s;
  Material m;
  m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials.push_back(m);
  addQuad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0, -1, 0);
  s.environment = Environment::fromEquirect(mapW, mapH, texels, 1.0f, rotation);
  const Environment env = s.environment;
  ViewerScene v = makeViewerScene(std::move(s), {});
  ViewRenderer r(v);
  const int w = 96, h = 64;
  // From above the quad's corner, looking out and up: the quad, the horizon and most of a hemisphere of sky.
  const ViewCamera cam = lookAt({0.8f, 0.6f, 0.8f}, {2.0f, 1.0f, -0.6f}, 120.0f, v.scene.bounds());
  DrawSettings settings;
  settings.background = skyBackground(v.scene);
  const RgbaImage img = r.render(cam, w, h, settings);
  const glm::mat4 inv = glm::inverse(cam.projection(static_cast<float>(w) / h) * cam.view());
  auto directionOf = [&](int x, int y) {
    const glm::vec2 ndc((x + 0.5f) / w * 2 - 1, 1 - (y + 0.5f) / h * 2);
    const glm::vec4 a = inv * glm::vec4(ndc, -1, 1), b = inv * glm::vec4(ndc, 0, 1);
    return std::pair{glm::vec3(a) / a.w, glm::normalize(glm::vec3(b) / b.w - glm::vec3(a) / a.w)};
  };
  auto insideATexel = [&](const glm::vec3& d) {  // the continuous map coordinates, away from texel edges
    const double c = std::cos(rotation), sn = std::sin(rotation);
    const glm::dvec3 mdir(c * d.x - sn * d.z, d.y, sn * d.x + c * d.z);
    const double u = (std::atan2(mdir.x, -mdir.z) + kPi) / (2 * kPi) * mapW;
    const double vv = std::acos(std::clamp(mdir.y, -1.0, 1.0)) / kPi * mapH;
    auto away = [](double t) { return std::abs(t - std::round(t)) > 0.02; };
    return away(u) && away(vv);
  };
  size_t sky = 0, floor = 0;
  std::vector<int> seen(mapW * mapH, 0);
  float worstSky = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [origin, d] = directionOf(x, y);
      const glm::vec3 hit = origin + d * (-origin.y / d.y);
      const bool onQuad = d.y < 0 && std::abs(hit.x) < 1 && std::abs(hit.z) < 1;
      const bool nearEdge = d.y < 0 && std::abs(std::max(std::abs(hit.x), std::abs(hit.z)) - 1.0f) < 0.05f;
      if (nearEdge) continue;
      if (onQuad) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(x, y)[c], 0.5f, 1e-6f) << x << "," << y;
        ++floor;
        continue;
      }
      if (!insideATexel(d)) continue;
      const glm::vec3 expected = env.radiance(d);
      for (int c = 0; c < 3; ++c) worstSky = std::max(worstSky, std::abs(img.at(x, y)[c] - expected[c]));
      for (int i = 0; i < mapW * mapH; ++i)
        if (texels[i] == expected) seen[i] = 1;
      ++sky;
    }
  int texelsSeen = 0;
  for (int k : seen) texelsSeen += k;
  std::printf("[ figure ] environment background: %zu sky pixels, %d texels, worst |pixel − texel| %.2g; %zu floor pixels\n",
              sky, texelsSeen, worstSky, floor);
  EXPECT_EQ(worstSky, 0.0f);  // RGB32F texel, fetched: the same float
  EXPECT_GT(sky, 3000u);
  EXPECT_GT(floor, 300u);
  EXPECT_GE(texelsSeen, 30);

  // The window's path: exposure +1 EV and the sRGB encode, like the scene's pixels.
  RenderTarget target(w, h, GL_RGBA32F);
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
  settings.encodeSrgb = true;
  settings.exposure = 1.0f;
  r.draw(cam, w, h, settings);
  std::vector<glm::vec4> shown(static_cast<size_t>(w) * h);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, shown.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  float worstShown = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [origin, d] = directionOf(x, y);
      if (d.y < 0.05f || !insideATexel(d)) continue;  // sky only
      const glm::vec3 L = env.radiance(d);
      const glm::vec4& p = shown[static_cast<size_t>(h - 1 - y) * w + x];  // GL rows bottom up
      for (int c = 0; c < 3; ++c) {
        const double e = std::min(1.0, 2.0 * L[c]);
        const double srgb = e <= 0.0031308 ? 12.92 * e : 1.055 * std::pow(e, 1.0 / 2.4) - 0.055;
        worstShown = std::max(worstShown, static_cast<float>(std::abs(p[c] - srgb)));
      }
    }
  std::printf("[ figure ] environment background on the display path: worst |pixel − sRGB(2L)| %.2g\n", worstShown);
  EXPECT_LT(worstShown, 5e-4f);  // the shader's fitted encode: 3.6e-4 (view_encode.glsl)

  // drawEnvironment = false: the flat background (the map's mean) as before.
  settings = DrawSettings{};
  settings.background = skyBackground(v.scene);
  settings.drawEnvironment = false;
  const RgbaImage flat = r.render(cam, w, h, settings);
  EXPECT_NEAR(flat.at(w / 2, 2).r, settings.background.r, 1e-6f);
}

TEST(ViewRenderer, DebugViewsDifferFromLitAndStayFinite) {
  GlContext gl;
  PlaneCase c = texturedPlane();
  ViewRenderer r(c.view);
  ViewCamera cam = lookAt({0.2f, 3.0f, 2.5f}, {0, 0, -0.3f}, 55.0f, c.view.scene.bounds());
  RgbaImage lit = r.render(cam, 64, 48, {});
  for (ViewMode m : {ViewMode::Charts, ViewMode::TexelDensity, ViewMode::Wireframe}) {
    RgbaImage img = r.render(cam, 64, 48, {m});
    double diff = 0.0;
    for (size_t i = 0; i < img.pixels.size(); ++i) {
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(img.pixels[i][k]));
      diff += glm::length(glm::vec3(img.pixels[i] - lit.pixels[i]));
    }
    EXPECT_GT(diff / img.pixels.size(), 0.01) << toString(m);
  }
  // The density checker alternates at the page's texel size: two neighbouring texels differ.
  RgbaImage density = r.render(lookAt({0, 0.5f, 0.0f}, {0, 0, -0.001f}, 10.0f, c.view.scene.bounds()), 64, 64,
                               {ViewMode::TexelDensity});
  float lo = 1e9f, hi = -1e9f;
  for (const auto& p : density.pixels) lo = std::min(lo, p.g), hi = std::max(hi, p.g);
  EXPECT_GT(hi, lo * 2.0f);
}

TEST(ViewRenderer, ViewModeNamesRoundTrip) {
  for (ViewMode m : {ViewMode::Lit, ViewMode::Lightmap, ViewMode::Albedo, ViewMode::Charts, ViewMode::TexelDensity,
                     ViewMode::Wireframe})
    EXPECT_EQ(parseViewMode(toString(m)), m);
  EXPECT_THROW(parseViewMode("shiny"), Error);
}

TEST(ViewerScene, ChartIdsAreConnectedComponents) {
  Primitive p;
  p.positions.assign(7, glm::vec3(0));
  p.indices = {0, 1, 2, 2, 1, 3, 4, 5, 6};  // two triangles sharing an edge, and one apart
  auto ids = chartIds(p);
  EXPECT_EQ(ids, (std::vector<uint32_t>{0, 0, 0, 0, 1, 1, 1}));
}


// A cube of half size h around c, four vertices per face (split like atlas seams), wound
// counter-clockwise seen from outside (outward) or from inside.
Primitive cube(glm::vec3 c, float h, bool outward) {
  Primitive p;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      glm::vec3 n(0.0f);
      n[axis] = (side ? 1.0f : -1.0f) * (outward ? 1.0f : -1.0f);
      const uint32_t base = static_cast<uint32_t>(p.positions.size());
      for (int k = 0; k < 4; ++k) {
        glm::vec3 q = c;
        q[axis] += side ? h : -h;
        q[a] += (k == 1 || k == 2) ? h : -h;
        q[b] += k >= 2 ? h : -h;
        p.positions.push_back(q);
        p.normals.push_back(n);
        p.uv0.emplace_back(k == 1 || k == 2 ? 1.0f : 0.0f, k >= 2 ? 1.0f : 0.0f);
      }
      const glm::vec3 e1 = p.positions[base + 1] - p.positions[base];
      const glm::vec3 e2 = p.positions[base + 2] - p.positions[base];
      if (glm::dot(glm::cross(e1, e2), n) > 0)
        p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else
        p.indices.insert(p.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  p.uv1 = p.uv0;
  return p;
}

TEST(ViewerScene, ClosedOutwardSolidsAreDetected) {
  EXPECT_TRUE(isClosedOutward(cube({1, 2, 3}, 0.5f, true)));
  EXPECT_FALSE(isClosedOutward(cube({1, 2, 3}, 0.5f, false))) << "inward (a room): walls seen from inside";
  Primitive open = cube({0, 0, 0}, 1.0f, true);
  open.indices.resize(open.indices.size() - 6);  // one face missing
  EXPECT_FALSE(isClosedOutward(open));
  Primitive flipped = cube({0, 0, 0}, 1.0f, true);
  std::swap(flipped.indices[1], flipped.indices[2]);  // one triangle wound the other way
  EXPECT_FALSE(isClosedOutward(flipped));
  // A UV sphere: seams welded by position, the poles' degenerate triangles ignored.
  Primitive sphere;
  const int rings = 8, segments = 12;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const float th = kPi * i / rings, ph = 2 * kPi * j / segments;
      // Exact poles and seam: the same position from every (i, j) that lands there.
      const float st = (i == 0 || i == rings) ? 0.0f : std::sin(th);
      const float ct = i == 0 ? 1.0f : i == rings ? -1.0f : std::cos(th);
      const float cp = j % segments == 0 ? 1.0f : std::cos(ph), sp = j % segments == 0 ? 0.0f : std::sin(ph);
      sphere.positions.emplace_back(st * cp, ct, st * sp);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = i * (segments + 1) + j, b = a + 1, c = a + segments + 1, d = c + 1;
      sphere.indices.insert(sphere.indices.end(), {a, b, c, b, d, c});
    }
  EXPECT_TRUE(isClosedOutward(sphere));
  Primitive quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  EXPECT_FALSE(isClosedOutward(quad));
}

// Back faces are culled on closed outward solids only: a cube seen from outside shows albedo × map,
// from inside it is not drawn (only its back faces face the eye); an inward cube (a room) still
// shows its walls from outside, as any wall seen from behind.
TEST(ViewRenderer, BackFacesAreCulledOnClosedOutwardSolidsOnly) {
  GlContext gl;
  for (bool outward : {true, false}) {
    Scene s;
    Material m;
    m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    s.materials.push_back(m);
    Primitive p = cube({0, 0, 0}, 1.0f, outward);
    p.lightmap = {0, 8, 8};
    s.primitives.push_back(p);
    ViewerScene v = makeViewerScene(std::move(s), {constantPage(0, 8, glm::vec3(0.8f))});
    ViewRenderer r(v);
    const Bounds3 b = v.scene.bounds();
    const RgbaImage outside = r.render(lookAt({0.3f, 0.4f, 5}, {0, 0, 0}, 30.0f, b), 32, 32, {});
    const RgbaImage inside = r.render(lookAt({0.1f, 0.2f, 0.3f}, {0, 0, -1}, 60.0f, b), 32, 32, {});
    EXPECT_NEAR(outside.at(16, 16).r, 0.4f, 0.004f) << (outward ? "outward" : "inward");
    if (outward)
      EXPECT_EQ(inside.at(16, 16), glm::vec4(0, 0, 0, 1));  // culled: the background
    else
      EXPECT_NEAR(inside.at(16, 16).r, 0.4f, 0.004f);
  }
}

}  // namespace
}  // namespace irbake::view
