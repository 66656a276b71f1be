// Directional light maps in the viewer: a floor of four quads, each with a constant
// normal map, constant L0 and L1 pages. Every pixel must equal albedo × max(0, L0 (n_g·n) + t·n)
// (transport/directional.h) for the quad's mapped normal n, which the test derives from the UV layout
// (tangent = where u grows, bitangent = where v shrinks: glTF's +Y up with UV (0,0) at the image's top left),
// not from the renderer's tangent code. Tolerances: half-float textures (L0, L1, normal map: 2^-11 relative).
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "common/maths.h"
#include "glcontext/gl_context.h"
#include "transport/directional.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

constexpr float kTolerance = 1e-3f;  // absolute, on values ≤ 0.5: half-float storage of every input
                                     // (measured worst 1.9e-4 with float L1 pages, 2.5e-4 with PNG L1)
const glm::vec3 kAlbedo(0.8f, 0.7f, 0.6f);
const glm::vec3 kL0(0.5f, 0.4f, 0.3f);
// t on the floor (n_g = +y) is tangential: no y component. Blue's large −x part drives the reconstruction
// below zero for a normal tilted towards +x, so the clamp is exercised.
const L1Vectors kL1{glm::vec3(0.2f, -0.1f, -0.5f), glm::vec3(0.0f), glm::vec3(-0.15f, 0.25f, 0.1f)};

Texture constantTexture(glm::vec3 value) {
  Texture t;
  t.name = "constant";
  t.width = t.height = 4;
  t.texels.assign(16, glm::vec4(value, 1.0f));
  return t;
}

Lightmap constantPage(int size, glm::vec3 value) {
  Lightmap m;
  m.page = 0;
  m.width = m.height = size;
  m.texels.assign(m.size(), value);
  m.valid.assign(m.size(), 1);
  return m;
}

// A tangent-space normal (x towards +u, y towards −v, z out) as stored in a normal map: × 0.5 + 0.5.
glm::vec3 encodeNormal(glm::vec3 m) { return glm::normalize(m) * 0.5f + 0.5f; }

struct QuadSpec {
  glm::vec3 tangentSpaceNormal;  // what the map stores (before scale)
  float scale = 1.0f;            // normalTexture.scale
  bool tangentAttribute = false;  // give TANGENT = (+z, w −1) instead of generating it from the UVs
};

// Quad i spans x ∈ [i − 2, i − 1], z ∈ [−1, 1], facing +y. uv0: u = x − x0 (grows with +x), v = (z + 1)/2
// (grows with +z), so a generated tangent is +x and the bitangent (towards −v) is −z.
struct FloorCase {
  ViewerScene view;
  std::vector<glm::vec3> worldNormal;  // the mapped normal each quad must shade with
};

FloorCase floorCase(const std::vector<QuadSpec>& quads, bool l1AsPngs) {
  FloorCase c;
  Scene s;
  for (size_t i = 0; i < quads.size(); ++i) {
    const QuadSpec& q = quads[i];
    Material m;
    m.baseColorFactor = glm::vec4(kAlbedo, 1.0f);
    m.normalTexture = static_cast<int>(s.textures.size());
    m.normalScale = q.scale;
    s.textures.push_back(constantTexture(encodeNormal(q.tangentSpaceNormal)));
    if (l1AsPngs) {
      // IRBAKE_lightmap_directional PNG texels: value = (2·texel − 1)·scale.
      const float scales[3] = {0.6f, 1.0f, 0.3f};
      for (int k = 0; k < 3; ++k) {
        m.directionalTextures[k] = static_cast<int>(s.textures.size());
        m.directionalScales[k] = scales[k];
        s.textures.push_back(constantTexture((kL1[k] / scales[k] + 1.0f) * 0.5f));
      }
    }
    s.materials.push_back(m);
    Primitive p;
    const float x0 = static_cast<float>(i) - 2.0f;
    p.positions = {{x0, 0, 1}, {x0 + 1, 0, 1}, {x0 + 1, 0, -1}, {x0, 0, -1}};
    p.normals.assign(4, glm::vec3(0, 1, 0));
    for (const glm::vec3& x : p.positions) {
      p.uv0.emplace_back(x.x - x0, (x.z + 1.0f) * 0.5f);
      p.uv1.emplace_back((x.x + 2.0f) / 4.0f, (x.z + 1.0f) * 0.5f);
    }
    p.indices = {0, 1, 2, 0, 2, 3};
    p.material = static_cast<int>(i);
    p.lightmap = {0, 16, 16};
    glm::vec3 tangent(1, 0, 0), bitangent(0, 0, -1);
    if (q.tangentAttribute) {
      p.tangents.assign(4, glm::vec4(0, 0, 1, -1));
      tangent = glm::vec3(0, 0, 1);
      bitangent = -glm::cross(glm::vec3(0, 1, 0), tangent);  // cross(n, t)·w, w = −1: −x
    }
    s.primitives.push_back(p);
    glm::vec3 tn = glm::normalize(q.tangentSpaceNormal);
    tn.x *= q.scale;
    tn.y *= q.scale;
    c.worldNormal.push_back(glm::normalize(tangent * tn.x + bitangent * tn.y + glm::vec3(0, 1, 0) * tn.z));
  }
  std::array<std::vector<Lightmap>, 3> l1;
  if (!l1AsPngs)
    for (int k = 0; k < 3; ++k) l1[k] = {constantPage(16, kL1[k])};
  c.view = makeViewerScene(std::move(s), {constantPage(16, kL0)}, std::move(l1));
  return c;
}

// The floor point a pixel centre sees (row 0 at the top); false when the ray misses y = 0.
bool floorPointAt(const ViewCamera& cam, int w, int h, int px, int py, glm::vec3& hit) {
  const glm::mat4 inv = glm::inverse(cam.projection(static_cast<float>(w) / h) * cam.view());
  const glm::vec2 ndc((px + 0.5f) / w * 2 - 1, 1 - (py + 0.5f) / h * 2);
  const glm::vec4 a = inv * glm::vec4(ndc, -1, 1), b = inv * glm::vec4(ndc, 0, 1);
  const glm::vec3 o = glm::vec3(a) / a.w, d = glm::vec3(b) / b.w - o;
  if (d.y >= 0) return false;
  hit = o + d * (-o.y / d.y);
  return true;
}

// Worst |pixel − expected(quad)| over the pixels that see a quad's inside (5 cm from its edges), and how
// many there were, per quad.
struct Comparison {
  float worst = 0.0f;
  std::vector<size_t> checked;
};
template <class Expected>
Comparison compare(const RgbaImage& img, const ViewCamera& cam, size_t quads, Expected expected) {
  Comparison r;
  r.checked.assign(quads, 0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      glm::vec3 p;
      if (!floorPointAt(cam, img.width, img.height, x, y, p) || std::abs(p.z) > 0.95f) continue;
      const float fx = p.x + 2.0f;
      const int quad = static_cast<int>(std::floor(fx));
      if (quad < 0 || quad >= static_cast<int>(quads) || fx - quad < 0.05f || fx - quad > 0.95f) continue;
      const glm::vec3 e = expected(quad);
      for (int k = 0; k < 3; ++k) r.worst = std::max(r.worst, std::abs(img.at(x, y)[k] - e[k]));
      ++r.checked[quad];
    }
  return r;
}

const std::vector<QuadSpec> kQuads = {
    {{0, 0, 1}},                                                            // flat
    {{std::sin(0.698f), 0, std::cos(0.698f)}},                              // 40° towards +u (blue clamps)
    {{0, std::sin(0.873f), std::cos(0.873f)}, 0.5f},                        // 50° towards −v, scale 0.5
    {{0.5f, -0.3f, 0.6f}, 1.0f, true},                                      // TANGENT given (+z, w = −1)
};

ViewCamera floorCamera(const Scene& s) { return lookAt({0.1f, 3.2f, 2.2f}, {0.1f, 0, -0.1f}, 60.0f, s.bounds()); }

TEST(DirectionalView, EveryPixelIsTheL1ReconstructionForItsMappedNormal) {
  GlContext gl;
  for (bool pngs : {false, true}) {
    const FloorCase c = floorCase(kQuads, pngs);
    ASSERT_EQ(directionalSourceOf(c.view, c.view.scene.primitives[0]),
              pngs ? DirectionalSource::MaterialTextures : DirectionalSource::Pages);
    ViewRenderer r(c.view);
    EXPECT_EQ(r.directionalPrimitiveCount(), kQuads.size());
    const ViewCamera cam = floorCamera(c.view.scene);
    const RgbaImage img = r.render(cam, 200, 150, {});
    const Comparison lit = compare(img, cam, kQuads.size(), [&](int q) {
      return kAlbedo * reconstructDirectional(kL0, kL1, glm::vec3(0, 1, 0), c.worldNormal[q]);
    });
    for (size_t q = 0; q < kQuads.size(); ++q) EXPECT_GT(lit.checked[q], 500u) << q;
    EXPECT_LT(lit.worst, kTolerance) << (pngs ? "PNG L1" : "float L1");
    // The light-map view shows the reconstruction alone.
    const Comparison map = compare(r.render(cam, 200, 150, {ViewMode::Lightmap}), cam, kQuads.size(), [&](int q) {
      return reconstructDirectional(kL0, kL1, glm::vec3(0, 1, 0), c.worldNormal[q]);
    });
    EXPECT_LT(map.worst, kTolerance);
    RecordProperty(pngs ? "worstPng" : "worstFloat", std::to_string(lit.worst));
    std::printf("[ figure ] directional floor (%s L1): worst |pixel − closed form| %.2e\n", pngs ? "PNG" : "float",
                lit.worst);
  }
  // The cases mean something: the tilts move every quad but the flat one, and blue clamps on quad 1.
  const FloorCase c = floorCase(kQuads, false);
  const glm::vec3 tilted = reconstructDirectional(kL0, kL1, glm::vec3(0, 1, 0), c.worldNormal[1]);
  EXPECT_EQ(tilted.b, 0.0f);
  EXPECT_GT(glm::length(tilted - kL0), 0.1f);
  for (size_t q = 1; q < kQuads.size(); ++q)
    EXPECT_GT(glm::length(reconstructDirectional(kL0, kL1, glm::vec3(0, 1, 0), c.worldNormal[q]) - kL0), 0.05f) << q;
}

TEST(DirectionalView, L0ModeAndFlatNormalMapShowThePlainMap) {
  GlContext gl;
  const FloorCase c = floorCase(kQuads, false);
  ViewRenderer r(c.view);
  const ViewCamera cam = floorCamera(c.view.scene);
  DrawSettings l0;
  l0.lightmapMode = LightmapMode::L0;
  const RgbaImage img = r.render(cam, 200, 150, l0);
  const Comparison plain = compare(img, cam, kQuads.size(), [&](int) { return kAlbedo * kL0; });
  EXPECT_LT(plain.worst, kTolerance);

  // A flat normal map with directional maps renders what the same floor without them renders.
  const FloorCase flat = floorCase({{{0, 0, 1}}, {{0, 0, 1}, 0.3f}, {{0, 0, 1}, 1.0f, true}}, false);
  Scene noNormalMaps = flat.view.scene;
  for (Material& m : noNormalMaps.materials) m.normalTexture = -1;
  const ViewerScene plainScene = makeViewerScene(std::move(noNormalMaps), flat.view.pages);  // and no L1 pages
  ViewRenderer withMaps(flat.view), without(plainScene);
  EXPECT_EQ(withMaps.directionalPrimitiveCount(), 3u);
  EXPECT_EQ(without.directionalPrimitiveCount(), 0u);
  const RgbaImage a = withMaps.render(cam, 200, 150, {}), b = without.render(cam, 200, 150, {});
  float worst = 0.0f;
  size_t floorPixels = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    if (b.pixels[i].g > 0.0f) ++floorPixels;
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(a.pixels[i][k] - b.pixels[i][k]));
  }
  EXPECT_GT(floorPixels, 5000u);
  EXPECT_LT(worst, kTolerance);
}

// Directional pages on a material without a normal map: nothing to bend, the plain shading and no L1 fetch.
TEST(DirectionalView, WithoutNormalMapTheShadingIsUnchanged) {
  GlContext gl;
  FloorCase c = floorCase(kQuads, false);
  for (Material& m : c.view.scene.materials) m.normalTexture = -1;
  ViewRenderer r(c.view);
  EXPECT_EQ(r.directionalPrimitiveCount(), 0u);
  const ViewCamera cam = floorCamera(c.view.scene);
  const Comparison lit = compare(r.render(cam, 200, 150, {}), cam, kQuads.size(), [&](int) { return kAlbedo * kL0; });
  EXPECT_LT(lit.worst, kTolerance);
}

// Generated tangents follow the UV layout: xyz = where u grows, cross(n, t)·w = where v shrinks, for a
// plain, a mirrored and a rotated layout on a tilted plane.
TEST(DirectionalView, GeneratedTangentsFollowTheUvLayout) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f));
  const glm::vec3 e1 = glm::normalize(glm::cross(n, glm::vec3(0, 0, 1))), e2 = glm::cross(n, e1);
  Primitive p;
  for (glm::vec2 a : {glm::vec2(0, 0), glm::vec2(2, 0), glm::vec2(2, 1), glm::vec2(0, 1), glm::vec2(1, 0.5f)})
    p.positions.push_back(e1 * a.x + e2 * a.y);
  p.normals.assign(p.positions.size(), n);
  p.indices = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
  struct Layout {
    glm::vec2 (*uv)(glm::vec2);
    glm::vec3 uGrows, vGrows;
  };
  const Layout layouts[] = {
      {[](glm::vec2 a) { return glm::vec2(0.5f * a.x, a.y); }, e1, e2},
      {[](glm::vec2 a) { return glm::vec2(1.0f - 0.5f * a.x, a.y); }, -e1, e2},  // mirrored u
      {[](glm::vec2 a) { return glm::vec2(a.y, 0.25f * a.x); }, e2, e1},         // rotated: u along e2
  };
  for (const Layout& l : layouts) {
    std::vector<glm::vec2> uv;
    for (size_t i = 0; i < p.positions.size(); ++i) uv.push_back(l.uv(glm::vec2(glm::dot(p.positions[i], e1),
                                                                                 glm::dot(p.positions[i], e2))));
    const std::vector<glm::vec4> t = generateTangents(p, uv);
    ASSERT_EQ(t.size(), p.positions.size());
    for (const glm::vec4& v : t) {
      EXPECT_NEAR(glm::length(glm::vec3(v) - l.uGrows), 0.0f, 1e-5f);
      EXPECT_NEAR(glm::length(glm::cross(n, glm::vec3(v)) * v.w + l.vGrows), 0.0f, 1e-5f);
    }
  }
}

// MikkTSpace's two rules that a plain sum of dP/du misses. (1) A vertex split only by another attribute (an
// export's light-map seam: same position, normal and UV) gets one frame on both copies. (2) At a vertex, each
// triangle's dP/du counts normalised and weighted by its corner angle: the centre of a fan of two triangles,
// one with a 90° corner and dP/du along e1, one with a 45° corner and dP/du along (e1 + e2)/√2 but a 4× larger
// gradient, gets t ∝ (π/2) e1 + (π/4) (e1 + e2)/√2, not the gradient-weighted sum.
TEST(DirectionalView, GeneratedTangentsWeldSeamsAndWeighCornerAngles) {
  const glm::vec3 n(0, 1, 0), e1(1, 0, 0), e2 = glm::cross(n, e1);  // the plane y = 0
  Primitive p;
  // Triangle A: the centre 0, (1, 0), (0, 1) in (e1, e2): a 90° corner at the centre; UV = (a, b): dP/du = e1.
  // Triangle B: the centre's copy 3, (0, 1), (−1, 1): a 45° corner; its UV is solved from the wanted gradients.
  auto at = [&](float a, float b) { return e1 * a + e2 * b; };
  p.positions = {at(0, 0), at(1, 0), at(0, 1), at(0, 0), at(0, 1), at(-1, 1)};
  p.normals.assign(p.positions.size(), n);
  p.indices = {0, 1, 2, 3, 4, 5};
  // UV of B: a linear map with dP/du = g_u, dP/dv = g_v, i.e. (u, v) = M⁻¹ (a, b) for the matrix of columns g_u, g_v.
  const glm::dvec2 gu = 4.0 * glm::normalize(glm::dvec2(1, 1)), gv = 4.0 * glm::normalize(glm::dvec2(-1, 1));
  const glm::dmat2 inv = glm::inverse(glm::dmat2(gu, gv));
  auto uvB = [&](double a, double b) { return glm::vec2(inv * glm::dvec2(a, b)); };
  const std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {0, 1}, uvB(0, 0), uvB(0, 1), uvB(-1, 1)};  // uvB(0, 0) = (0, 0)
  const std::vector<glm::vec4> t = generateTangents(p, uv);
  ASSERT_EQ(t.size(), p.positions.size());
  const glm::vec3 expected = glm::normalize(float(kPi / 2) * e1 + float(kPi / 4) * glm::normalize(e1 + e2));
  EXPECT_NEAR(glm::length(glm::vec3(t[0]) - expected), 0.0f, 1e-5f);
  EXPECT_EQ(t[0], t[3]);  // welded: one frame on both copies
  // Vertex 2 and its copy 4 have different UVs, so they stay apart: each follows its own triangle.
  EXPECT_NEAR(glm::length(glm::vec3(t[2]) - e1), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(glm::vec3(t[4]) - glm::normalize(e1 + e2)), 0.0f, 1e-5f);
}

// MikkTSpace keeps a UV mirror's halves apart. A strip of two quads on a plane whose u runs 1 → 0 → 1
// (mirrored at the middle line, whose vertices both halves share): split, each half's vertices get its own
// dP/du (−e1 on the left, +e1 on the right) and the same bitangent. Unsplit, or with the copies welded back
// (same position, normal and UV), the shared vertices would sum −e1 and +e1 (90° of corners each) to nothing.
TEST(DirectionalView, GeneratedTangentsKeepUvMirrorHalvesApart) {
  const glm::vec3 n(0, 1, 0), e1(1, 0, 0), e2 = glm::cross(n, e1);
  Primitive p;
  for (float b : {0.0f, 1.0f})
    for (float a : {-1.0f, 0.0f, 1.0f}) p.positions.push_back(e1 * a + e2 * b);  // 0 1 2 / 3 4 5
  p.normals.assign(p.positions.size(), n);
  p.indices = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  for (const glm::vec3& q : p.positions) p.uv0.push_back(glm::vec2(std::abs(glm::dot(q, e1)), glm::dot(q, e2)));
  const Primitive s = splitMirroredUvVertices(p, 0);
  ASSERT_EQ(s.positions.size(), 8u);  // vertices 1 and 4 copied
  ASSERT_EQ(s.normals.size(), 8u);
  ASSERT_EQ(s.uv0.size(), 8u);
  const std::vector<glm::vec4> t = generateTangents(s, s.uv0);
  for (size_t c = 0; c < s.indices.size(); ++c) {
    const size_t tri = c / 3;
    const glm::vec3 uGrows = tri < 2 ? -e1 : e1;  // triangles 0-1: the left half, u = −x
    const glm::vec4 v = t[s.indices[c]];
    EXPECT_NEAR(glm::length(glm::vec3(v) - uGrows), 0.0f, 1e-5f) << "corner " << c;
    // v grows along e2 on both halves: cross(n, t)·w = −dP/dv.
    EXPECT_NEAR(glm::length(glm::cross(n, glm::vec3(v)) * v.w + e2), 0.0f, 1e-5f) << "corner " << c;
  }
  // The split changed nothing else: same triangles in space, mirrored ones on the copies.
  for (size_t c = 0; c < p.indices.size(); ++c) EXPECT_EQ(s.positions[s.indices[c]], p.positions[p.indices[c]]);
}

}  // namespace
}  // namespace irbake::view
