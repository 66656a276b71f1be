// The LM-63 parser on profiles written by the tests: a closed-form distribution read back, the symmetries of
// the horizontal angle ranges, the exact integral, and refusals naming the file and the line.
#include "scene/ies_profile.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/error.h"
#include "testing/ies_profiles.h"

namespace irbake {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(IesProfile, ReadsTheClosedFormBackAtEveryAngle) {
  const IesProfile p = parseIesProfile(testing::cosineIesProfile(100.0), "cosine.ies");
  EXPECT_EQ(p.vertical.size(), 91u);
  EXPECT_DOUBLE_EQ(p.maxCandela, 150.0);
  for (double theta : {0.0, 10.0, 33.3, 45.0, 60.5, 89.9})
    for (double phi : {0.0, 45.0, 90.0, 135.0, 200.0, 270.0, 330.0, -30.0})
      EXPECT_NEAR(p.candelaAt(theta, phi), testing::cosineIesCandela(100.0, theta, phi), 1e-9) << theta << ", " << phi;
  // Nothing above the horizon: the file lists θ up to 90° only.
  EXPECT_EQ(p.candelaAt(120.0, 0.0), 0.0);
  EXPECT_EQ(p.candelaAt(180.0, 90.0), 0.0);
}

// ∫ I0 cosθ f(φ) dω over the lower hemisphere = I0 · (1/2) · ∫ f dφ; f's mean over the circle is 1.0 here
// (trapezoids: (1.5+1.2)/2 + (1.2+0.5)/2 + (0.5+0.8)/2 + (0.8+1.5)/2 = 4, over 4 quarters), so I0 · π.
// The interpolation's chords of cosθ at 1° steps lie below it by under 4e-5 relative.
TEST(IesProfile, IntegralIsTheClosedForm) {
  const IesProfile p = parseIesProfile(testing::cosineIesProfile(100.0), "cosine.ies");
  EXPECT_NEAR(p.integral(), 100.0 * kPi, 100.0 * kPi * 4e-5);
  double cells = 0.0;
  for (size_t h = 0; h + 1 < p.horizontal.size(); ++h)
    for (size_t v = 0; v + 1 < p.vertical.size(); ++v) cells += p.cellIntegral(h, v);
  EXPECT_NEAR(cells, p.integral(), 1e-9 * cells);
}

// A profile listed over 0–90° (quadrant symmetry), 0–180° (bilateral), 0° alone (rotational), or 90–270°
// (LM-63-1995): each horizontal angle reads like its mirror images.
TEST(IesProfile, HorizontalSymmetriesMirrorTheListedPlanes) {
  const std::vector<double> vertical = {0, 45, 90, 135, 180};
  auto candela = [](double theta, double phi) { return 10.0 + theta / 10.0 + phi / 5.0; };
  const IesProfile quadrant = parseIesProfile(testing::iesProfileText(vertical, {0, 30, 90}, candela), "q.ies");
  const IesProfile half = parseIesProfile(testing::iesProfileText(vertical, {0, 60, 180}, candela), "h.ies");
  const IesProfile round = parseIesProfile(testing::iesProfileText(vertical, {0}, candela), "r.ies");
  const IesProfile old = parseIesProfile(testing::iesProfileText(vertical, {90, 180, 270}, candela), "o.ies");
  for (double theta : {0.0, 30.0, 100.0, 180.0}) {
    const double at20 = quadrant.candelaAt(theta, 20.0);
    EXPECT_NEAR(at20, 10.0 + theta / 10.0 + 4.0, 1e-9);
    for (double mirror : {160.0, 200.0, 340.0, -20.0}) EXPECT_NEAR(quadrant.candelaAt(theta, mirror), at20, 1e-9);
    EXPECT_NEAR(half.candelaAt(theta, 120.0), 10.0 + theta / 10.0 + 24.0, 1e-9);
    EXPECT_NEAR(half.candelaAt(theta, 240.0), half.candelaAt(theta, 120.0), 1e-9);
    for (double phi : {0.0, 77.0, 250.0}) EXPECT_NEAR(round.candelaAt(theta, phi), 10.0 + theta / 10.0, 1e-9);
    // 90–270°: φ and 180° − φ read alike; 0° reads the listed 180°.
    EXPECT_NEAR(old.candelaAt(theta, 0.0), 10.0 + theta / 10.0 + 36.0, 1e-9);
    EXPECT_NEAR(old.candelaAt(theta, 45.0), old.candelaAt(theta, 135.0), 1e-9);
    EXPECT_NEAR(old.candelaAt(theta, 300.0), old.candelaAt(theta, 240.0), 1e-9);
  }
  // A rotationally symmetric profile integrates to 2π ∫ I(θ) sinθ dθ; with I linear in θ: exact.
  const double a = 10.0, b = 0.1 * 180.0 / kPi;  // I = a + b θ (θ in radians)
  EXPECT_NEAR(round.integral(), 2.0 * kPi * (2.0 * a + b * kPi), 1e-9 * round.integral());
}

TEST(IesProfile, MultiplierTiltIncludeAndCommasAreRead) {
  std::string text = testing::iesProfileText({0, 90}, {0}, [](double, double) { return 4.0; }, 2.5);
  const size_t tilt = text.find("TILT=NONE\n");
  text.replace(tilt, 10, "TILT=INCLUDE\n1\n3\n0, 45, 90\n1 0.9 0.8\n");
  const IesProfile p = parseIesProfile(text, "tilt.ies");
  EXPECT_NEAR(p.candelaAt(30.0, 0.0), 10.0, 1e-12);
}

// Each malformed profile: Error(InvalidData) naming the source and "line N" with its problem.
void expectRefused(const std::string& text, int line, const std::string& problem) {
  try {
    parseIesProfile(text, "lamp.ies");
    ADD_FAILURE() << "accepted, expected: " << problem;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    const std::string what = e.what();
    EXPECT_NE(what.find("lamp.ies"), std::string::npos) << what;
    EXPECT_NE(what.find("line " + std::to_string(line) + ":"), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << what;
  }
}

TEST(IesProfile, MalformedProfilesAreRefusedNamingTheLine) {
  const std::string good = testing::iesProfileText({0, 45, 90}, {0, 90}, [](double, double) { return 5.0; });
  // good: 1 IESNA, 2-3 keywords, 4 TILT, 5 header, 6 ballast line, 7 vertical, 8 horizontal, 9 candela.
  auto replaceLine = [&](int line, const std::string& with) {
    std::string t = good;
    size_t start = 0;
    for (int i = 1; i < line; ++i) start = t.find('\n', start) + 1;
    t.replace(start, t.find('\n', start) - start, with);
    return t;
  };
  expectRefused(replaceLine(4, "[MORE] keywords"), 9, "no TILT= line");
  expectRefused(replaceLine(9, "5 5 5 5 5"), 9, "the file ends before candela value 6 of 6");
  expectRefused(replaceLine(7, "0 4x5 90"), 7, "'4x5' is not a number (vertical angle 2 of 3)");
  expectRefused(replaceLine(5, "1 -1 1 -3 2 1 2 0 0 0"), 5, "the number of vertical angles is -3");
  expectRefused(replaceLine(5, "1 -1 1 3 2 2 2 0 0 0"), 5, "photometric type B is not supported");
  expectRefused(replaceLine(5, "1 -1 1 3 2 3 2 0 0 0"), 5, "photometric type A is not supported");
  expectRefused(replaceLine(7, "0 90 45"), 7, "vertical angles must ascend");
  expectRefused(replaceLine(8, "0 120"), 8, "type C needs 0 alone, 0–90, 0–180, 0–360 or 90–270");
  expectRefused(replaceLine(9, "5 5 5 5 -5 5"), 9, "candela value 5 of 6 is -5");
}

}  // namespace
}  // namespace irbake
