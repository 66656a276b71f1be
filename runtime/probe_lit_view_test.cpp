// A probe-lit object (extras.irbake.mode "probes") in irview: a white square floating in the Cornell box, baked
// without map texels, exported with extras.lightProbes, and drawn lit by the probes: each pixel shows albedo ×
// (max(0, shIrradiance(c(p), n)) + the exact emitters' E/π), c(p) the probes' field over the square's bounding
// sphere (probeObject, as the probe spheres and three.js's lightObject take it), p the pixel's point on the square
// (the camera ray met in double precision) and n its normal.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "probe_view.h"
#include "samples/sample_scenes.h"
#include "view_renderer.h"
#include "viewer_scene.h"

namespace irbake::view {
namespace {

const glm::vec3 kCentre(0.2f, 0.4f, 0.2f);  // open air in the box: above the short block, beside the tall one
// The camera looks down at it from below the ceiling (0.55 m).
constexpr float kHalf = 0.05f;
constexpr float kAlbedo = 0.8f;

std::filesystem::path outDir() {
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  return std::filesystem::path(dir ? dir : ".") / "runtime_bake_test" / "probe_lit";
}

// The Cornell box with a square of albedo kAlbedo facing +y at kCentre, probe-lit; baked with probes and exported.
std::filesystem::path bakedBoxWithProbeLitSquare() {
  Scene scene = samples::makeCornellBox();
  Material white;
  white.name = "probe-lit white";
  white.baseColorFactor = glm::vec4(kAlbedo, kAlbedo, kAlbedo, 1.0f);
  scene.materials.push_back(white);
  Primitive square;
  square.name = "probe-lit square";
  square.positions = {kCentre + glm::vec3(-kHalf, 0, -kHalf), kCentre + glm::vec3(kHalf, 0, -kHalf),
                      kCentre + glm::vec3(kHalf, 0, kHalf), kCentre + glm::vec3(-kHalf, 0, kHalf)};
  square.normals.assign(4, glm::vec3(0, 1, 0));
  square.indices = {0, 2, 1, 0, 3, 2};
  square.material = static_cast<int>(scene.materials.size()) - 1;
  square.mode = ObjectMode::Probes;
  scene.primitives.push_back(square);
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 16.0f;
  o.walk.paths = 512;
  BakeResult baked = bake(std::move(scene), o);
  EXPECT_GT(baked.probes.size(), 8u);
  ExportOptions ex;
  ex.output = outDir() / "cornell.gltf";
  ex.probes = &baked.probes;
  exportGltf(baked.scene, baked.maps, ex);
  return ex.output;
}

// The point of the square (y = kCentre.y) seen through pixel (x, y), from the camera's own matrices in double;
// false when it is off the square or within `margin` of its edge.
bool squarePointAt(const ViewCamera& camera, int w, int h, int x, int y, double margin, glm::dvec3& p) {
  const glm::dmat4 inv = glm::inverse(glm::dmat4(camera.projection(static_cast<float>(w) / h) * camera.view()));
  const glm::dvec2 ndc((x + 0.5) / w * 2.0 - 1.0, 1.0 - (y + 0.5) / h * 2.0);
  const glm::dvec4 a = inv * glm::dvec4(ndc, -1.0, 1.0), b = inv * glm::dvec4(ndc, 0.5, 1.0);
  const glm::dvec3 eye = glm::dvec3(camera.position());
  const glm::dvec3 d = glm::normalize(glm::dvec3(b) / b.w - glm::dvec3(a) / a.w);
  if (!(d.y < 0.0)) return false;
  p = eye + d * ((double(kCentre.y) - eye.y) / d.y);
  return std::abs(p.x - kCentre.x) < kHalf - margin && std::abs(p.z - kCentre.z) < kHalf - margin;
}

TEST(ProbeLitView, ProbeLitSquareShowsTheProbesIrradianceAtEachPixel) {
  const std::filesystem::path file = bakedBoxWithProbeLitSquare();
  nlohmann::json doc;
  std::ifstream(file) >> doc;
  int marked = 0;
  for (const auto& mesh : doc["meshes"])
    for (const auto& prim : mesh["primitives"])
      if (prim.contains("extras") && prim["extras"].value("lightProbes", false)) {
        ++marked;
        EXPECT_FALSE(prim["attributes"].contains("TEXCOORD_1"));
      }
  EXPECT_EQ(marked, 1);

  // The probes over the square as irview takes them: its box centre, its farthest corner.
  const ProbeSphere field = probeObject(readLightProbes(file), kCentre, kHalf * std::sqrt(2.0f), file);
  const auto expected = [&](const glm::dvec3& p) {
    const glm::vec3 o = glm::vec3(p) - kCentre;
    ShCoefficients c = field.coefficients;
    for (int k = 0; k < kShCoefficients; ++k)
      c[k] += o.x * field.gradient[0][k] + o.y * field.gradient[1][k] + o.z * field.gradient[2][k];
    glm::vec3 e = glm::max(shIrradiance(c, glm::vec3(0, 1, 0)), glm::vec3(0.0f));
    if (field.emitters) e += exactEmitterLight(*field.emitters, field.emitterVisibility.at(o), glm::vec3(p), glm::vec3(0, 1, 0));
    return kAlbedo * e;
  };
  const glm::vec3 atCentre = expected(glm::dvec3(kCentre));
  ASSERT_GT(atCentre.x, 0.01f) << "the probes at the square are dark";

  ViewerScene v = loadViewerScene(file);
  GlContext gl;
  ViewRenderer renderer(v);
  const int w = 65, h = 65;
  const ViewCamera camera = lookAt(kCentre + glm::vec3(0.03f, 0.1f, -0.06f), kCentre, 40.0f, v.scene.bounds());
  const RgbaImage img = renderer.render(camera, w, h, {});
  int pixels = 0;
  double worst = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::dvec3 p;
      if (!squarePointAt(camera, w, h, x, y, 0.002, p)) continue;
      const glm::vec3 e = expected(p);
      const glm::vec4& px = img.pixels[static_cast<size_t>(y) * w + x];
      for (int k = 0; k < 3; ++k) worst = std::max(worst, double(std::abs(px[k] - e[k]) / atCentre[k]));
      ++pixels;
    }
  const glm::vec4& middle = img.pixels[static_cast<size_t>(h / 2) * w + w / 2];
  std::printf("centre: expected %g %g %g, shown %g %g %g\n", atCentre.x, atCentre.y, atCentre.z, middle.x, middle.y, middle.z);
  EXPECT_GT(pixels, 300) << "the square should fill much of the view";
  // Float shading of the same sum in GLSL and C++: 1e-3 of the value at the centre.
  EXPECT_LT(worst, 1e-3);
  RecordProperty("worstRelativeError", std::to_string(worst));
}

}  // namespace
}  // namespace irbake::view
