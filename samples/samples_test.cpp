// Sample scenes: counts, units, orientation, stated exact answers, and the writer → loader round trip.
#include <cmath>

#include <gtest/gtest.h>

#include "lights/light_kind.h"
#include "samples/sample_scenes.h"
#include "scene/gltf_loader.h"
#include "testing/gltf_builder.h"

using namespace irbake;
using namespace irbake::samples;

namespace {

glm::vec3 faceNormal(const Primitive& p, size_t t) {
  const glm::vec3 &a = p.positions[p.indices[3 * t]], &b = p.positions[p.indices[3 * t + 1]], &c = p.positions[p.indices[3 * t + 2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

glm::vec3 centroid(const Primitive& p, size_t t) {
  return (p.positions[p.indices[3 * t]] + p.positions[p.indices[3 * t + 1]] + p.positions[p.indices[3 * t + 2]]) / 3.0f;
}

double area(const Primitive& p) {
  double a = 0.0;
  for (size_t t = 0; t < p.triangleCount(); ++t) {
    const glm::vec3 &x = p.positions[p.indices[3 * t]], &y = p.positions[p.indices[3 * t + 1]], &z = p.positions[p.indices[3 * t + 2]];
    a += 0.5 * glm::length(glm::cross(y - x, z - x));
  }
  return a;
}

const Primitive& part(const Scene& s, const std::string& name) {
  for (const auto& p : s.primitives)
    if (p.name == name) return p;
  throw std::runtime_error("no part " + name);
}

// Every triangle's geometric normal agrees with its vertex normals.
void expectConsistentNormals(const Scene& s) {
  for (const auto& p : s.primitives)
    for (size_t t = 0; t < p.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) EXPECT_GT(glm::dot(faceNormal(p, t), p.normals[p.indices[3 * t + k]]), 0.999f) << p.name;
}

// Writes and reloads a sample; geometry, materials, lights and cameras survive.
Scene roundTrip(const Scene& s, const std::string& name, const std::string& ext = ".gltf") {
  auto dir = irbake::testing::testFolder("samples_" + name);
  writeGltf(s, dir / (name + ext));
  Scene r = loadScene(dir / (name + ext));
  EXPECT_EQ(r.primitives.size(), s.primitives.size());
  EXPECT_EQ(r.triangleCount(), s.triangleCount());
  EXPECT_EQ(r.stats.trianglesDropped, 0u);
  for (size_t i = 0; i < std::min(r.primitives.size(), s.primitives.size()); ++i) {
    const auto &a = s.primitives[i], &b = r.primitives[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.positions.size(), b.positions.size());
    if (a.positions.size() != b.positions.size()) continue;
    for (size_t v = 0; v < a.positions.size(); ++v) EXPECT_LT(glm::length(a.positions[v] - b.positions[v]), 1e-6f);
    EXPECT_EQ(a.indices, b.indices);
    const Material &ma = s.materials[a.material], &mb = r.materials[b.material];
    EXPECT_EQ(ma.name, mb.name);
    EXPECT_LT(glm::length(glm::vec3(ma.baseColorFactor) - glm::vec3(mb.baseColorFactor)), 1e-6f);
    EXPECT_LT(glm::length(ma.emission() - mb.emission()), 1e-5f * (1.0f + glm::length(ma.emission())));
  }
  EXPECT_EQ(r.lights.size(), s.lights.size());
  for (size_t i = 0; i < std::min(r.lights.size(), s.lights.size()); ++i) {
    EXPECT_EQ(r.lights[i].type, s.lights[i].type);
    EXPECT_FLOAT_EQ(r.lights[i].intensity, s.lights[i].intensity);
    EXPECT_LT(glm::length(r.lights[i].position - s.lights[i].position), 1e-6f);
    if (s.lights[i].type != LightType::Point) {
      EXPECT_LT(glm::length(r.lights[i].direction - s.lights[i].direction), 1e-5f);
    }
    EXPECT_NEAR(r.lights[i].outerConeAngle, s.lights[i].outerConeAngle, 1e-6f);
  }
  EXPECT_EQ(r.cameras.size(), s.cameras.size());
  for (size_t i = 0; i < std::min(r.cameras.size(), s.cameras.size()); ++i) {
    EXPECT_NEAR(r.cameras[i].yfov, s.cameras[i].yfov, 1e-6f);
    for (int c = 0; c < 4; ++c) EXPECT_LT(glm::length(r.cameras[i].cameraToWorld[c] - s.cameras[i].cameraToWorld[c]), 1e-5f);
  }
  EXPECT_NEAR(r.emitterPower().x, s.emitterPower().x, 1e-4 * (1.0 + s.emitterPower().x));
  return r;
}

}  // namespace

TEST(Samples, CornellBoxGeometryUnitsAndLight) {
  Scene s = makeCornellBox();
  EXPECT_EQ(s.triangleCount(), 32u);  // 5 walls, 2 blocks × 5 faces, the light: 16 quads
  EXPECT_EQ(s.primitives.size(), 8u);
  Bounds3 b = s.bounds();
  EXPECT_NEAR(b.max.x, 0.556f, 1e-6f);
  EXPECT_NEAR(b.max.y, 0.5488f, 1e-6f);
  EXPECT_NEAR(b.max.z, 0.5592f, 1e-6f);
  EXPECT_NEAR(b.min.x, 0.0f, 1e-7f);
  // Light: 130 × 105 mm = 0.01365 m², Le = (17,12,4): power π·Le·A.
  const Primitive& light = part(s, "light");
  EXPECT_NEAR(area(light), 0.01365, 1e-7);
  glm::vec3 P = s.emitterPower();
  EXPECT_NEAR(P.x, M_PI * 17.0 * 0.01365, 1e-4);
  EXPECT_NEAR(P.y, M_PI * 12.0 * 0.01365, 1e-4);
  EXPECT_NEAR(P.z, M_PI * 4.0 * 0.01365, 1e-4);
  EXPECT_NEAR(faceNormal(light, 0).y, -1.0f, 1e-6f);
  EXPECT_LT(light.positions[0].y, 0.5488f);
  // Walls face the room; block faces point out of their block.
  const glm::vec3 inside(0.278f, 0.274f, 0.280f);
  for (const char* wall : {"floor", "ceiling", "back_wall", "left_wall_red", "right_wall_green"}) {
    const Primitive& w = part(s, wall);
    for (size_t t = 0; t < w.triangleCount(); ++t) EXPECT_GT(glm::dot(faceNormal(w, t), inside - centroid(w, t)), 0.0f) << wall;
  }
  const Primitive& tall = part(s, "tall_block");
  glm::vec3 tallCentre(0.3685f, 0.165f, 0.3515f);
  for (size_t t = 0; t < tall.triangleCount(); ++t) EXPECT_GT(glm::dot(faceNormal(tall, t), centroid(tall, t) - tallCentre), 0.0f);
  EXPECT_NEAR(s.materials[part(s, "left_wall_red").material].baseColorFactor.r, 0.63f, 1e-6f);
  EXPECT_NEAR(s.materials[part(s, "right_wall_green").material].baseColorFactor.g, 0.45f, 1e-6f);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_NEAR(s.cameras[0].yfov * 180.0 / M_PI, 39.3077, 1e-3);
  glm::vec3 eye(s.cameras[0].cameraToWorld[3]), forward = -glm::vec3(s.cameras[0].cameraToWorld[2]);
  EXPECT_LT(glm::length(eye - glm::vec3(0.278f, 0.273f, -0.8f)), 1e-6f);
  EXPECT_LT(glm::length(forward - glm::vec3(0, 0, 1)), 1e-6f);
  // Looking +Z with +Y up, camera right is −X: the red wall (x ≈ 0.55) is on the left.
  EXPECT_LT(glm::vec3(s.cameras[0].cameraToWorld[0]).x, -0.999f);
  expectConsistentNormals(s);
}

TEST(Samples, CornellBoxRoundTripsAsGltfAndGlb) {
  Scene s = makeCornellBox();
  roundTrip(s, "cornell_box");
  roundTrip(s, "cornell_box_glb", ".glb");
}

TEST(Samples, FurnaceIsClosedWithInwardNormalsAndStatedPower) {
  Scene s = makeFurnace(0.8f, 2.0f);
  EXPECT_EQ(s.triangleCount(), 12u);
  const Primitive& p = s.primitives[0];
  EXPECT_NEAR(area(p), 24.0, 1e-5);
  for (size_t t = 0; t < p.triangleCount(); ++t) EXPECT_LT(glm::dot(faceNormal(p, t), centroid(p, t)), 0.0f);
  // Emitted power π·Le·A; the exact map value Le/(1−ρ) = 10 is the furnace's stated answer.
  EXPECT_NEAR(s.emitterPower().x, M_PI * 2.0 * 24.0, 1e-3);
  EXPECT_FLOAT_EQ(s.materials[0].baseColorFactor.r, 0.8f);
  expectConsistentNormals(s);
  Scene r = roundTrip(s, "furnace");
  EXPECT_NEAR(r.materials[0].emission().x, 2.0f, 1e-6f);  // > 1: stored through emissive strength
}

TEST(Samples, PointOverPlaneAndTexturedPlane) {
  Scene s = makePointOverPlane();
  EXPECT_NEAR(area(s.primitives[0]), 100.0, 1e-4);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_FLOAT_EQ(s.lights[0].intensity, 10.0f);
  EXPECT_NEAR(faceNormal(s.primitives[0], 0).y, 1.0f, 1e-6f);
  roundTrip(s, "point_over_plane");

  Scene t = makeTexturedPlane();
  // uv (1/16, 1/16) is the centre of check (0,0) = 0.8; the next check over is 0.2.
  EXPECT_NEAR(sampleBilinear(t.textures[0], {1.0f / 16, 1.0f / 16}).r, 0.8f, 1e-6f);
  EXPECT_NEAR(sampleBilinear(t.textures[0], {3.0f / 16, 1.0f / 16}).r, 0.2f, 1e-6f);
  Scene r = roundTrip(t, "textured_plane");
  ASSERT_EQ(r.textures.size(), 1u);
  // 8-bit sRGB PNG: the round trip error is below half a code step (< 0.003 in linear at 0.8).
  EXPECT_NEAR(sampleBilinear(r.textures[0], {1.0f / 16, 1.0f / 16}).r, 0.8f, 3e-3f);
  EXPECT_NEAR(sampleBilinear(r.textures[0], {3.0f / 16, 1.0f / 16}).r, 0.2f, 2e-3f);
  // baseColorAt goes through TEXCOORD_0: vertex (−2,0,−2) has uv (0,0).
  EXPECT_TRUE(r.primitives[0].uv0.size() == 4);
}

TEST(Samples, QuadOverPlaneClosedFormMatchesQuadrature) {
  Scene s = makeQuadOverPlane();
  EXPECT_NEAR(s.emitterPower().x, M_PI * 1.0, 1e-5);
  EXPECT_EQ(s.materials[s.primitives[0].material].baseColorFactor.r, 0.0f);
  // Midpoint quadrature of Le cosθ cosθ' / (π r²) over the emitter, at three receiver points.
  for (glm::dvec2 p : {glm::dvec2(0, 0), glm::dvec2(0.7, -0.2), glm::dvec2(1.9, 1.9)}) {
    const int n = 400;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double x = -0.5 + (i + 0.5) / n, z = -0.5 + (j + 0.5) / n;
        double dx = x - p.x, dz = z - p.y, r2 = dx * dx + dz * dz + 1.0;
        sum += 1.0 / (r2 * r2) / M_PI / (double(n) * n);  // cosθ = cosθ' = 1/r, h = 1
      }
    EXPECT_NEAR(parallelRectangleIrradianceOverPi(p.x, p.y, -0.5, 0.5, -0.5, 0.5, 1.0, 1.0), sum, 1e-6);
  }
  // A small source tends to the point limit Le·A / (π h²); 1/(1+ρ²)² lowers it by 2⟨ρ²⟩ = 4a²/3 relative (a = half side).
  double far = parallelRectangleIrradianceOverPi(0, 0, -0.005, 0.005, -0.005, 0.005, 1.0, 1.0);
  EXPECT_NEAR(far / (1e-4 / M_PI), 1.0 - 2.0 * (2.0 * 0.005 * 0.005 / 3.0), 1e-7);
  roundTrip(s, "quad_over_plane");
}

TEST(Samples, CornerAndSpotLight) {
  Scene s = makeCorner();
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& spot = s.lights[0];
  EXPECT_EQ(spot.type, LightType::Spot);
  // Aimed at (0.5, 0, 1.5): the wall point (0, 1, 1.5) is inside the inner cone (26.6° < 30°).
  glm::vec3 toWall = glm::normalize(glm::vec3(0, 1, 1.5f) - spot.position);
  EXPECT_NEAR(lightKind(spot).intensityToward(spot, toWall).x, 20.0f, 1e-4f);
  EXPECT_NEAR(faceNormal(part(s, "wall"), 0).x, 1.0f, 1e-6f);
  EXPECT_NEAR(faceNormal(part(s, "floor"), 0).y, 1.0f, 1e-6f);
  EXPECT_NEAR(area(part(s, "wall")), 9.0, 1e-5);
  roundTrip(s, "corner");
}

TEST(Samples, ThinWallPartitionIsTwoCoincidentOppositeQuads) {
  Scene s = makeThinWall();
  const Primitive &lit = part(s, "room_lit"), &dark = part(s, "room_dark");
  int litFaces = 0, darkFaces = 0;
  for (size_t t = 0; t < lit.triangleCount(); ++t)
    if (std::abs(centroid(lit, t).x) < 1e-6f) {
      ++litFaces;
      EXPECT_NEAR(faceNormal(lit, t).x, -1.0f, 1e-6f);
    }
  for (size_t t = 0; t < dark.triangleCount(); ++t)
    if (std::abs(centroid(dark, t).x) < 1e-6f) {
      ++darkFaces;
      EXPECT_NEAR(faceNormal(dark, t).x, 1.0f, 1e-6f);
    }
  EXPECT_EQ(litFaces, 2);
  EXPECT_EQ(darkFaces, 2);
  EXPECT_LT(s.lights[0].position.x, 0.0f);
  expectConsistentNormals(s);
  roundTrip(s, "thin_wall");
}

TEST(Samples, WriteSamplesWritesEveryScene) {
  auto dir = irbake::testing::testFolder("samples_all");
  auto paths = writeSamples(dir);
  EXPECT_EQ(paths.size(), allSamples().size());
  for (const auto& p : paths) {
    EXPECT_TRUE(std::filesystem::exists(p));
    Scene s = loadScene(p);
    EXPECT_TRUE(s.hasLightOrEmitter()) << p;
  }
}
