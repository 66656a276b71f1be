// Closed forms per light kind, the checks every kind must pass (its power is the integral of its intensity, its
// rays leave it distributed like its intensity), and a test-only kind that shows what a new kind implements.
#include "lights/light_kind.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "common/maths.h"
#include "lights/positional_light.h"
#include "sampling/sampling.h"
#include "scene/ies_profile.h"
#include "testing/ies_profiles.h"

namespace irbake {
namespace {

Light makeLight(LightType type, glm::vec3 position, glm::vec3 direction, float intensity) {
  Light l;
  l.type = type;
  l.position = position;
  l.direction = glm::normalize(direction);
  l.intensity = intensity;
  return l;
}

Light spot(float inner, float outer) {
  Light l = makeLight(LightType::Spot, glm::vec3(0.0f), glm::vec3(0, 0, -1), 3.0f);
  l.innerConeAngle = inner;
  l.outerConeAngle = outer;
  return l;
}

// ∫ f(ω) dω over the sphere, midpoint rule on uniformSphere's (u, v) square (n × n cells).
double sphereIntegral(const std::function<double(const glm::vec3&)>& f, int n = 400) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) sum += f(uniformSphere((i + 0.5) / n, (j + 0.5) / n));
  return 4.0 * kPi * sum / (double(n) * n);
}

// Mean of f over the kind's emitted directions on an n × n grid of (u2, u3).
double emittedMean(const LightKind& kind, const Light& light, const std::function<double(const glm::vec3&)>& f,
                   int n = 400) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      glm::vec3 origin, dir;
      kind.emit(light, glm::vec3(0.0f), 1.0f, 0.5, 0.5, (i + 0.5) / n, (j + 0.5) / n, origin, dir);
      sum += f(dir);
    }
  return sum / (double(n) * n);
}

// What every kind with a position must satisfy: power = ∮ I(ω) dω, and its rays distributed like I, so the mean of
// cos(ω, axis) over its rays equals ∮ cos · I dω / Φ.
void expectEmissionMatchesIntensity(const LightKind& kind, const Light& light) {
  const auto intensity = [&](const glm::vec3& w) { return double(kind.intensityToward(light, w).x); };
  const double power = kind.power(light).x;
  EXPECT_NEAR(sphereIntegral(intensity), power, 2e-3 * power) << kind.name();
  const auto cosAxis = [&](const glm::vec3& w) { return double(glm::dot(w, light.direction)); };
  const double expected = sphereIntegral([&](const glm::vec3& w) { return cosAxis(w) * intensity(w); }) / power;
  EXPECT_NEAR(emittedMean(kind, light, cosAxis), expected, 2e-3) << kind.name();
}

TEST(LightKinds, RegistryFindsEachKindByItsType) {
  EXPECT_STREQ(lightKind(LightType::Point).name(), "point");
  EXPECT_STREQ(lightKind(LightType::Spot).name(), "spot");
  EXPECT_STREQ(lightKind(LightType::Directional).name(), "directional");
  EXPECT_STREQ(lightKind(LightType::Ies).name(), "ies");
  EXPECT_EQ(lightKind(LightType::Ies).shaderCode(), 3);
  EXPECT_TRUE(lightKind(LightType::Directional).atInfinity());
  EXPECT_FALSE(lightKind(LightType::Point).atInfinity());
  EXPECT_NE(lightKind(LightType::Point).shaderCode(), lightKind(LightType::Spot).shaderCode());
  EXPECT_NE(lightKind(LightType::Spot).shaderCode(), lightKind(LightType::Directional).shaderCode());
}

TEST(PointLight, IrradianceIsIntensityOverDistanceSquaredTimesCosine) {
  const Light l = makeLight(LightType::Point, glm::vec3(0, 0, 2), glm::vec3(0, 0, -1), 8.0f);
  const LightKind& kind = lightKind(l);
  // Receiver at (1.5, 0, 0) facing +z: d² = 6.25, cosθ = 2 / 2.5.
  const PunctualContribution c = kind.direct(l, glm::vec3(1.5f, 0, 0), glm::vec3(0, 0, 1));
  EXPECT_NEAR(c.mapValue.x, 8.0 / 6.25 * 0.8 / kPi, 1e-6);
  EXPECT_NEAR(c.distance, 2.5f, 1e-6f);
  EXPECT_NEAR(c.toLight.z, 0.8f, 1e-6f);
  EXPECT_EQ(kind.direct(l, glm::vec3(1.5f, 0, 0), glm::vec3(0, 0, -1)).mapValue, glm::vec3(0.0f));  // faces away
  EXPECT_NEAR(kind.power(l).x, 4.0 * kPi * 8.0, 1e-4);
  EXPECT_NEAR(kind.atNormalIncidence(l, glm::vec3(1.5f, 0, 0)).mapValue.x, 8.0 / 6.25 / kPi, 1e-6);
  expectEmissionMatchesIntensity(kind, l);
}

TEST(PointLight, RangeAndReachBoundItsInfluence) {
  Light l = makeLight(LightType::Point, glm::vec3(0.0f), glm::vec3(0, 0, -1), 1.0f);
  const LightKind& kind = lightKind(l);
  const float reach = std::sqrt(1.0f / (kPiF * 1e-3f));  // I / (π r²) = threshold
  EXPECT_TRUE(kind.influences(l, glm::vec3(reach * 0.99f, 0, 0), 1e-3f));
  EXPECT_FALSE(kind.influences(l, glm::vec3(reach * 1.01f, 0, 0), 1e-3f));
  l.range = 2.0f;
  EXPECT_FALSE(kind.influences(l, glm::vec3(2.1f, 0, 0), 1e-3f));
  EXPECT_EQ(kind.direct(l, glm::vec3(2.1f, 0, 0), glm::vec3(-1, 0, 0)).mapValue, glm::vec3(0.0f));  // glTF's window
  EXPECT_GT(kind.direct(l, glm::vec3(1.9f, 0, 0), glm::vec3(-1, 0, 0)).mapValue.x, 0.0f);
}

// glTF's range as three.js and Babylon window the inverse square law: w(d) = clamp(1 − (d/R)⁴, 0, 1)².
TEST(PointLight, RangeWindowIsSmoothAndZeroFromTheRangeOn) {
  Light l = makeLight(LightType::Point, glm::vec3(0.0f), glm::vec3(0, 0, -1), 8.0f);
  EXPECT_EQ(l.rangeWindow(0.0f), 1.0f);  // no range: the inverse square law alone, at every distance
  EXPECT_EQ(l.rangeWindow(1e6f), 1.0f);
  const float R = 2.0f;
  l.range = R;
  EXPECT_EQ(l.rangeWindow(0.0f), 1.0f);
  EXPECT_NEAR(l.rangeWindow(0.5f * R), (15.0 / 16.0) * (15.0 / 16.0), 1e-7);  // (1 − 1/16)²
  EXPECT_NEAR(l.rangeWindow(0.9f * R), std::pow(1.0 - std::pow(0.9, 4.0), 2.0), 1e-6);
  EXPECT_EQ(l.rangeWindow(R), 0.0f);
  EXPECT_EQ(l.rangeWindow(1.01f * R), 0.0f);
  EXPECT_EQ(l.rangeWindow(100.0f * R), 0.0f);
  // No step anywhere: |w′| = 8 q³ (1 − q⁴) / R is largest at q⁴ = 3/7, where it is (32/7)(3/7)^¾ / R; each
  // step of h changes w by at most that times h (and a little float rounding).
  const double maxSlope = 32.0 / 7.0 * std::pow(3.0 / 7.0, 0.75) / R;
  const int n = 12000;
  const double h = 1.5 * R / n;
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const double step = std::abs(double(l.rangeWindow(float((i + 1) * h))) - l.rangeWindow(float(i * h)));
    worst = std::max(worst, step);
    EXPECT_LE(step, maxSlope * h * 1.001 + 1e-6) << "d = " << i * h;
  }
  EXPECT_GT(worst, 0.9 * maxSlope * h);  // the bound is tight: the window does fall that fast near q = 0.81
  // The direct term carries it: E/π = I w(d) / (π d²) facing the light, for point, spot and IES kinds alike.
  const LightKind& kind = lightKind(l);
  EXPECT_NEAR(kind.direct(l, glm::vec3(0.5f * R, 0, 0), glm::vec3(-1, 0, 0)).mapValue.x,
              8.0 * (225.0 / 256.0) / (R * R / 4.0) / kPi, 1e-6);
  EXPECT_NEAR(kind.atNormalIncidence(l, glm::vec3(0, 0.9f * R, 0)).mapValue.x,
              8.0 * l.rangeWindow(0.9f * R) / (0.81 * R * R) / kPi, 1e-6);
  Light s = spot(0.2f, 0.6f);
  s.range = R;
  EXPECT_NEAR(lightKind(s).direct(s, glm::vec3(0, 0, -0.5f * R), glm::vec3(0, 0, 1)).mapValue.x,
              3.0 * (225.0 / 256.0) / (R * R / 4.0) / kPi, 1e-6);
  EXPECT_EQ(lightKind(s).direct(s, glm::vec3(0, 0, -R), glm::vec3(0, 0, 1)).mapValue.x, 0.0f);
}

TEST(SpotLight, ConeFalloffIsTheSquareOfALinearRampInCosine) {
  const Light l = spot(0.2f, 0.6f);
  const LightKind& kind = lightKind(l);
  const double cosI = std::cos(0.2), cosO = std::cos(0.6);
  const auto at = [&](double angle) {
    return double(kind.intensityToward(l, glm::vec3(std::sin(angle), 0.0, -std::cos(angle))).x);
  };
  EXPECT_NEAR(at(0.1), 3.0, 1e-6);  // inside the inner cone
  EXPECT_EQ(at(0.7), 0.0);          // outside the outer cone
  const double mid = std::acos(0.5 * (cosI + cosO));  // t = ½
  EXPECT_NEAR(at(mid), 3.0 * 0.25, 1e-4);
  const double solid = 2.0 * kPi * ((1.0 - cosI) + (cosI - cosO) / 3.0);
  EXPECT_NEAR(kind.power(l).x, 3.0 * solid, 1e-4);
  expectEmissionMatchesIntensity(kind, l);
  expectEmissionMatchesIntensity(kind, spot(0.0f, 1.2f));  // the band only
}

TEST(SpotLight, InfluenceStopsAtTheOuterConeAndShadowMapFollowsItsWidth) {
  const Light l = spot(0.3f, 0.5f);
  const LightKind& kind = lightKind(l);
  EXPECT_TRUE(kind.influences(l, glm::vec3(0.1f, 0, -1.0f), 1e-3f));
  EXPECT_FALSE(kind.influences(l, glm::vec3(1.0f, 0, -1.0f), 1e-3f));  // 45°, beyond 0.5 rad
  EXPECT_EQ(kind.shadowProjection(l, 1.0f), ShadowProjection::Perspective);
  EXPECT_EQ(kind.shadowProjection(l, 0.4f), ShadowProjection::Cube);
  nlohmann::json gltf;
  kind.describeGltf(l, gltf);
  EXPECT_EQ(gltf["type"].get<std::string>(), "spot");
  EXPECT_FLOAT_EQ(gltf["spot"]["outerConeAngle"].get<float>(), 0.5f);
  const ShaderLight s = kind.shaderLight(l);
  EXPECT_NEAR(s.cosOuter, std::cos(0.5), 1e-6);
  EXPECT_NEAR(s.spotScale, 1.0 / (std::cos(0.3) - std::cos(0.5)), 1e-3);
}

TEST(DirectionalLight, IrradianceIsConstantTimesCosine) {
  const Light l = makeLight(LightType::Directional, glm::vec3(0.0f), glm::vec3(0, -1, -1), 2.0f);
  const LightKind& kind = lightKind(l);
  for (const glm::vec3 x : {glm::vec3(0.0f), glm::vec3(100.0f, -3.0f, 7.0f)}) {
    const PunctualContribution c = kind.direct(l, x, glm::vec3(0, 0, 1));
    EXPECT_NEAR(c.mapValue.x, 2.0 / std::sqrt(2.0) / kPi, 1e-6);
    EXPECT_TRUE(std::isinf(c.distance));
  }
  EXPECT_EQ(kind.power(l), glm::vec3(0.0f));
  EXPECT_NEAR(kind.walkPower(l, 3.0f).x, 2.0 * kPi * 9.0, 1e-4);  // through the scene's disc
  EXPECT_TRUE(kind.influences(l, glm::vec3(1e6f), 1e-3f));
  EXPECT_EQ(kind.shadowProjection(l, 1.0f), ShadowProjection::Orthographic);
}

TEST(DirectionalLight, RaysStartOnTheDiscUpstreamOfTheSceneSphere) {
  const Light l = makeLight(LightType::Directional, glm::vec3(0.0f), glm::vec3(1, -2, 0.5f), 1.0f);
  const LightKind& kind = lightKind(l);
  const glm::vec3 centre(4.0f, 5.0f, -6.0f);
  const float radius = 3.0f;
  for (double u0 : {0.0, 0.3, 1.0})
    for (double u1 : {0.1, 0.7}) {
      glm::vec3 origin, dir;
      kind.emit(l, centre, radius, u0, u1, 0.5, 0.5, origin, dir);
      EXPECT_NEAR(glm::length(dir - l.direction), 0.0f, 1e-6f);
      const glm::vec3 offset = origin - centre;
      EXPECT_NEAR(glm::dot(offset, dir), -1.01f * radius, 1e-4f);
      EXPECT_NEAR(glm::length(offset - glm::dot(offset, dir) * dir), radius * std::sqrt(u0), 1e-4f);
    }
}

// An IES light tilted off the axes: the profile's nadir along `nadir`, its horizontal angle 0 along `axisX`.
Light iesLight(std::shared_ptr<const IesProfile> profile) {
  Light l = makeLight(LightType::Ies, glm::vec3(0.5f, -1.0f, 2.0f), glm::vec3(0.3f, -0.2f, -1.0f), 2.0f);
  l.color = glm::vec3(1.0f, 0.5f, 0.25f);
  l.profile = std::move(profile);
  const glm::vec3 across(1.0f, 0.4f, 0.1f);
  l.profileAxisX = glm::normalize(across - l.direction * glm::dot(across, l.direction));
  return l;
}

// The profile's angles of a direction leaving light l, in degrees.
void anglesOf(const Light& l, const glm::vec3& w, double& theta, double& phi) {
  const glm::vec3 y = glm::cross(-l.direction, l.profileAxisX);
  theta = std::acos(std::clamp(double(glm::dot(w, l.direction)), -1.0, 1.0)) * 180.0 / kPi;
  phi = std::atan2(double(glm::dot(w, y)), double(glm::dot(w, l.profileAxisX))) * 180.0 / kPi;
}

TEST(IesLight, IntensityIsCandelaTimesMultiplierAndColourInTheNodesFrame) {
  const auto profile = std::make_shared<const IesProfile>(parseIesProfile(testing::cosineIesProfile(40.0), "t.ies"));
  const Light l = iesLight(profile);
  const LightKind& kind = lightKind(l);
  const glm::vec3 y = glm::cross(-l.direction, l.profileAxisX);
  // Straight down the nadir: I0 · f(0) = 40 · 1.5; along +X at 60° from the nadir: 40 cos 60° · 1.5; along +Y
  // at 60°: 40 · 0.5 · 1.2; along −X: · 0.5; upwards: nothing.
  auto at = [&](float theta, glm::vec3 side) {
    return glm::normalize(l.direction * std::cos(theta) + side * std::sin(theta));
  };
  const float sixty = float(kPi / 3.0);
  EXPECT_NEAR(kind.intensityToward(l, l.direction).x, 2.0 * 60.0, 1e-5 * 120.0);
  EXPECT_NEAR(kind.intensityToward(l, at(sixty, l.profileAxisX)).y, 2.0 * 0.5 * 20.0 * 1.5, 1e-3);
  EXPECT_NEAR(kind.intensityToward(l, at(sixty, y)).x, 2.0 * 20.0 * 1.2, 1e-3);
  EXPECT_NEAR(kind.intensityToward(l, at(sixty, -l.profileAxisX)).z, 2.0 * 0.25 * 20.0 * 0.5, 1e-3);
  EXPECT_EQ(kind.intensityToward(l, -l.direction).x, 0.0f);
  // The direct term at a receiver below and beside the light: I(ω) cosθ / (π d²).
  const glm::vec3 x(1.2f, -0.4f, 0.0f), n(0.0f, 0.0f, 1.0f);
  const glm::vec3 d = x - l.position;
  const glm::vec3 w = glm::normalize(d);
  double theta, phi;
  anglesOf(l, w, theta, phi);
  const double expected = 2.0 * testing::cosineIesCandela(40.0, theta, phi) * double(glm::dot(-w, n)) /
                          (kPi * double(glm::dot(d, d)));
  EXPECT_NEAR(kind.direct(l, x, n).mapValue.x, expected, 1e-5 * expected);
  EXPECT_NEAR(kind.atNormalIncidence(l, x).mapValue.x, expected / double(glm::dot(-w, n)), 1e-5 * expected);
}

// Power = ∮ I dω, and the walk's rays weighted by what emit returns carry I: the weighted mean of any g over
// them is ∮ g I dω / Φ (the cosine to the nadir, and to the horizontal axis, which an unweighted or mirrored
// sampling would get wrong), with a mean weight of 1.
TEST(IesLight, PowerIsTheIntegralAndWeightedRaysFollowTheProfile) {
  const auto profile = std::make_shared<const IesProfile>(parseIesProfile(testing::cosineIesProfile(40.0), "t.ies"));
  const Light l = iesLight(profile);
  const LightKind& kind = lightKind(l);
  const auto intensity = [&](const glm::vec3& w) { return double(kind.intensityToward(l, w).x); };
  const double power = kind.power(l).x;
  EXPECT_NEAR(power, 2.0 * 40.0 * kPi, 2.0 * 40.0 * kPi * 4e-5);  // IesProfile.IntegralIsTheClosedForm
  EXPECT_NEAR(sphereIntegral(intensity, 800), power, 2e-3 * power);
  const Halton halton(3, 7);
  const int n = 200000;
  double weights = 0.0, nadir = 0.0, axis = 0.0;
  for (int i = 0; i < n; ++i) {
    glm::vec3 origin, dir;
    const double w = kind.emit(l, glm::vec3(0.0f), 1.0f, halton.sample(0, i), 0.5, halton.sample(1, i),
                               halton.sample(2, i), origin, dir);
    EXPECT_EQ(origin, l.position);
    weights += w;
    nadir += w * glm::dot(dir, l.direction);
    axis += w * glm::dot(dir, l.profileAxisX);
  }
  const auto expected = [&](const glm::vec3& v) {
    return sphereIntegral([&](const glm::vec3& w) { return double(glm::dot(w, v)) * intensity(w); }, 800) / power;
  };
  EXPECT_NEAR(weights / n, 1.0, 2e-3);
  EXPECT_NEAR(nadir / n, expected(l.direction), 2e-3);
  EXPECT_NEAR(axis / n, expected(l.profileAxisX), 2e-3);
  EXPECT_GT(axis / n, 0.05);  // f(0°) > f(180°): more light towards +X
  EXPECT_EQ(kind.shadowProjection(l, 1.0f), ShadowProjection::Cube);
  // Its reach follows the profile's peak: 2 · 60 cd at threshold 1 reaches √(120 / π) m.
  EXPECT_TRUE(kind.influences(l, l.position + glm::vec3(0, 0, 6.1f), 1.0f));
  EXPECT_FALSE(kind.influences(l, l.position + glm::vec3(0, 0, 6.3f), 1.0f));
}

// A kind the registry does not hold, to show the seam: a point light with a cosine lobe around its direction,
// I(ω) = I₀ max(0, d·ω). Everything a stage asks of a light is here; a real one adds its LightType value, its row in
// light_kinds.cpp and its name in the glTF loader.
class CosineLobeLight final : public LightKind {
 public:
  const char* name() const override { return "cosine_lobe"; }
  bool atInfinity() const override { return false; }
  bool aimed() const override { return true; }
  glm::vec3 intensityToward(const Light& l, const glm::vec3& w) const override {
    return l.color * l.intensity * std::max(0.0f, glm::dot(l.direction, w));
  }
  glm::vec3 power(const Light& l) const override { return kPiF * (l.color * l.intensity); }
  glm::dvec3 walkPower(const Light& l, float) const override { return glm::dvec3(power(l)); }
  double emit(const Light& l, const glm::vec3&, float, double, double, double u2, double u3, glm::vec3& origin,
              glm::vec3& dir) const override {
    origin = l.position;
    dir = cosineHemisphere(l.direction, u2, u3);
    return 1.0;
  }
  glm::vec3 toward(const Light& l, const glm::vec3& x) const override { return l.position - x; }
  PunctualContribution direct(const Light& l, const glm::vec3& x, const glm::vec3& nx) const override {
    return positionalDirect(l, x, nx, [this](const Light& light, const glm::vec3& w) { return intensityToward(light, w); });
  }
  bool influences(const Light& l, const glm::vec3& x, float threshold) const override {
    const glm::vec3 d = x - l.position;
    return glm::dot(d, l.direction) > 0.0f && withinReach(l, glm::dot(d, d), threshold);
  }
  void describeGltf(const Light&, nlohmann::json& gltfLight) const override { gltfLight["type"] = name(); }
  ShadowProjection shadowProjection(const Light&, float) const override { return ShadowProjection::Cube; }
  int shaderCode() const override { return 99; }
};

TEST(LightKindSeam, ATestOnlyKindAnswersEveryStagesQuestionsThroughTheInterface) {
  const CosineLobeLight lobe;
  const LightKind& kind = lobe;
  Light l = makeLight(LightType::Point, glm::vec3(0, 0, 2), glm::vec3(0, 0, -1), 5.0f);
  // Direct term: I₀ cosθ_emit cosθ_recv / r², here both cosines 0.8 at r = 2.5.
  EXPECT_NEAR(kind.direct(l, glm::vec3(1.5f, 0, 0), glm::vec3(0, 0, 1)).mapValue.x, 5.0 * 0.8 * 0.8 / 6.25 / kPi, 1e-6);
  // The probes' delta: the receiver faces the light, so only the emitting cosine remains.
  EXPECT_NEAR(kind.atNormalIncidence(l, glm::vec3(1.5f, 0, 0)).mapValue.x, 5.0 * 0.8 / 6.25 / kPi, 1e-6);
  EXPECT_FALSE(kind.influences(l, glm::vec3(0, 0, 3), 1e-3f));  // behind it
  EXPECT_TRUE(kind.influences(l, glm::vec3(0, 0, 1), 1e-3f));
  expectEmissionMatchesIntensity(kind, l);  // power πI₀; its rays' mean cosine 2/3
  const ShaderLight s = kind.shaderLight(l);
  EXPECT_EQ(s.code, 99);
  EXPECT_EQ(s.intensity, glm::vec3(5.0f));
}

}  // namespace
}  // namespace irbake
