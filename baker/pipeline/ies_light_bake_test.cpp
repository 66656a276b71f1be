// EXT_lights_ies end to end: a glTF with an IES light (its profile a data URI, its node turned) above a large
// floor, loaded and baked through the whole pipeline on the GL backend and on Embree. Each texel of the map
// holds candela(θ, φ) × multiplier × cosθ / d², as E/π (docs/export.md), within 1% (the texel's own square
// averages a curved falloff: under a light 1 m up, at 16 texels a metre, about a tenth of that).
#include <cmath>
#include <cstdio>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "common/base64.h"
#include "pipeline/bake.h"
#include "scene/gltf_loader.h"
#include "testing/gltf_builder.h"
#include "testing/ies_profiles.h"

namespace irbake {
namespace {

using json = nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

// A 10 × 10 m floor at y = 0 (glTF's up) and the light 1 m above (0.2, 0, −0.1): its nadir turned to −Y,
// then 30° about +Y, so the profile's horizontal angle 0 lies along (cos 30°, 0, −sin 30°).
Scene iesOverFloor() {
  GltfDocument doc = testing::meshDocument({{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}}, {0, 2, 1, 0, 3, 2},
                                           {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}});
  const std::string profile = testing::cosineIesProfile(3.0);
  doc.root["extensions"]["EXT_lights_ies"]["lights"] =
      json::array({{{"uri", "data:application/x-ies-lm-63;base64," + base64Encode(profile)}}});
  const glm::quat q = glm::angleAxis(glm::radians(30.0f), glm::vec3(0, 1, 0)) *
                      glm::angleAxis(glm::radians(-90.0f), glm::vec3(1, 0, 0));
  doc.append("nodes", {{"translation", {0.2, 1.0, -0.1}},
                       {"rotation", {q.x, q.y, q.z, q.w}},
                       {"extensions", {{"EXT_lights_ies", {{"light", 0}, {"multiplier", 1.5}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  doc.useExtension("EXT_lights_ies");
  const auto file = testing::testFolder("ies_light_bake") / "ies_over_floor.gltf";
  testing::writeDocument(doc, file);
  return loadScene(file);
}

// The closed form at a floor point (E/π).
double expectedAt(const glm::dvec3& p) {
  const glm::dvec3 light(0.2, 1.0, -0.1), nadir(0, -1, 0);
  const double c = std::cos(kPi / 6.0), s = std::sin(kPi / 6.0);
  const glm::dvec3 x(c, 0.0, -s), y = glm::cross(-nadir, x);
  const glm::dvec3 d = p - light;
  const double r2 = glm::dot(d, d);
  const glm::dvec3 w = d / std::sqrt(r2);
  const double theta = std::acos(glm::dot(w, nadir)) * 180.0 / kPi;
  const double phi = std::atan2(glm::dot(w, y), glm::dot(w, x)) * 180.0 / kPi;
  return 1.5 * testing::cosineIesCandela(3.0, theta, phi) * (-w.y) / (kPi * r2);
}

TEST(IesLightBake, FloorUnderTheLightIsCandelaTimesCosineOverDistanceSquared) {
  for (BackendKind backend : {BackendKind::Gl, BackendKind::Embree}) {
    BakeOptions o;
    o.backend = backend;
    o.atlas.texelsPerUnit = 16.0f;
    o.walk.paths = 256;
    const BakeResult r = bake(iesOverFloor(), o);
    ASSERT_EQ(r.scene.lights.size(), 1u);
    const Primitive& floor = r.scene.primitives.at(0);
    double worst = 0.0, widest = 0.0;
    size_t compared = 0;
    for (const Lightmap& m : r.maps) {
      if (m.page != floor.lightmap.page) continue;
      for (int ty = 0; ty < m.height; ++ty)
        for (int tx = 0; tx < m.width; ++tx) {
          const size_t i = size_t(ty) * m.width + tx;
          if (!m.valid[i]) continue;
          // The texel's centre on the floor: the triangle of uv1 that holds it, well inside.
          const glm::vec2 c((tx + 0.5f) / m.width, (ty + 0.5f) / m.height);
          for (size_t t = 0; t < floor.triangleCount(); ++t) {
            const uint32_t* k = &floor.indices[3 * t];
            const glm::vec2 a = floor.uv1[k[0]], e1 = floor.uv1[k[1]] - a, e2 = floor.uv1[k[2]] - a, q = c - a;
            const float det = e1.x * e2.y - e1.y * e2.x;
            const float b1 = (q.x * e2.y - q.y * e2.x) / det, b2 = (e1.x * q.y - e1.y * q.x) / det;
            if (b1 < 0.0f || b2 < 0.0f || b1 + b2 > 1.0f) continue;
            const glm::dvec3 p = glm::dvec3(floor.positions[k[0]]) * double(1.0f - b1 - b2) +
                                 glm::dvec3(floor.positions[k[1]]) * double(b1) + glm::dvec3(floor.positions[k[2]]) * double(b2);
            if (std::abs(p.x) > 4.0 || std::abs(p.z) > 4.0) break;
            const double expected = expectedAt(p);
            const double theta = std::acos(1.0 / glm::length(p - glm::dvec3(0.2, 1.0, -0.1))) * 180.0 / kPi;
            if (theta > 70.0 || !(expected > 0.0)) break;
            worst = std::max(worst, std::abs(double(m.texels[i].x) - expected) / expected);
            widest = std::max(widest, theta);
            ++compared;
            break;
          }
        }
    }
    std::printf("[ figure ] IES light over a floor, %s: %zu texels to θ = %.1f°, worst relative error %.2e\n",
                toString(backend), compared, widest, worst);
    EXPECT_GT(compared, 2000u) << toString(backend);
    EXPECT_GT(widest, 65.0) << toString(backend);
    EXPECT_LT(worst, 0.01) << toString(backend);
  }
}

}  // namespace
}  // namespace irbake
