// Lambert's polygon formula (lightmap/polygon_irradiance.h) against closed forms and a quadrature, and the choice
// of exact emitters (exact_emitters.h).
#include <gtest/gtest.h>

#include <cmath>

#include "lightmap/polygon_irradiance.h"
#include "stages/probes/exact_emitters.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;
constexpr double kPi = 3.14159265358979323846;

// A square of half-side a at height h over the origin, facing down, as two triangles.
struct Square {
  glm::vec3 v[4];
  Square(float a, float h) : v{{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}} {}
  double factor(const glm::vec3& p, const glm::vec3& n) const {
    return triangleIrradianceFactor(v[0], v[1], v[2], p, n) + triangleIrradianceFactor(v[0], v[2], v[3], p, n);
  }
  double solidAngle(const glm::vec3& p) const {
    return triangleSolidAngle(v[0], v[1], v[2], p) + triangleSolidAngle(v[0], v[2], v[3], p);
  }
  // E/L at p facing n by a midpoint quadrature over the square: Σ max(0, n·ω) cosθ_y / r² dA.
  double quadrature(const glm::dvec3& p, const glm::dvec3& n, int cells = 800) const {
    const double a = v[1].x, h = v[0].y, dA = (2 * a / cells) * (2 * a / cells);
    double sum = 0.0;
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j) {
        const glm::dvec3 y(-a + (i + 0.5) * 2 * a / cells, h, -a + (j + 0.5) * 2 * a / cells), d = y - p;
        const double r2 = glm::dot(d, d), r = std::sqrt(r2), cosY = d.y / r;  // the square faces down
        if (cosY > 0.0) sum += std::max(0.0, glm::dot(n, d) / r) * cosY / r2 * dA;
      }
    return sum;
  }
};

TEST(ExactEmitters, PolygonFormulaMatchesTheParallelSquareAndItsSolidAngle) {
  // Under the centre of a square of half-side a at distance h, facing it: E/L = π F with the parallel-rectangle
  // view factor F = (2/π) · 2 (x/s) atan(x/s), x = a/h, s = √(1 + x²); Ω = 4 asin(a²/(a² + h²)).
  for (const auto [a, h] : {std::pair{0.2, 1.0}, std::pair{0.5, 0.3}, std::pair{1.0, 2.0}}) {
    const Square sq(static_cast<float>(a), static_cast<float>(h));
    const double x = a / h, s = std::sqrt(1.0 + x * x), F = 2.0 / kPi * 2.0 * (x / s) * std::atan(x / s);
    EXPECT_NEAR(sq.factor(glm::vec3(0.0f), glm::vec3(0, 1, 0)), kPi * F, 1e-5 * kPi * F) << a << " " << h;
    const double omega = 4.0 * std::asin(a * a / (a * a + h * h));
    EXPECT_NEAR(sq.solidAngle(glm::vec3(0.0f)), omega, 1e-5 * omega);
    // Behind the square (its back face) and facing away: nothing.
    EXPECT_EQ(sq.factor(glm::vec3(0.0f, static_cast<float>(2 * h), 0.0f), glm::vec3(0, -1, 0)), 0.0);
    EXPECT_EQ(sq.solidAngle(glm::vec3(0.0f, static_cast<float>(2 * h), 0.0f)), 0.0);
    EXPECT_EQ(sq.factor(glm::vec3(0.0f), glm::vec3(0, -1, 0)), 0.0);
  }
}

TEST(ExactEmitters, PolygonFormulaClipsAtTheHorizon) {
  // Tilted normals, several with the square straddling the tangent plane: the clipped polygon against an 800²
  // midpoint quadrature of the clamped cosine (its error ~1e-5 here).
  const Square sq(0.2f, 1.0f);
  for (const glm::vec3 p : {glm::vec3(0.05f, 0.9f, 0.0f), glm::vec3(0.3f, 0.5f, -0.1f), glm::vec3(0.0f)})
    for (const glm::vec3 n : {glm::vec3(1, 0, 0), glm::normalize(glm::vec3(1, 0.1f, 0)), glm::normalize(glm::vec3(-1, 0.3f, 0.2f)),
                              glm::normalize(glm::vec3(0.3f, 0.2f, -0.9f)), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)}) {
      const double want = sq.quadrature(glm::dvec3(p), glm::dvec3(n)), got = sq.factor(p, n);
      EXPECT_NEAR(got, want, 2e-4 * std::max(want, 0.05)) << p.x << "," << p.y << "," << p.z << " n " << n.x << "," << n.y << "," << n.z;
    }
}

TEST(ExactEmitters, ChoosesUniformPlanarEmittersBrightestFirstWithinTheTriangleBudget) {
  // Three emissive squares: bright (2 triangles), dim (2), and a 32-triangle one between them in power; a budget of
  // 4 triangles keeps the bright and the dim (the middle one does not fit), 0 keeps none.
  Scene scene;
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f), glm::vec3(10.0f)), glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1));
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f), glm::vec3(1.0f)), glm::vec3(3, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1));
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f), glm::vec3(5.0f)), glm::vec3(6, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), 4);
  addQuad(scene, addMaterial(scene, glm::vec3(0.5f)), glm::vec3(0, 0, 0), glm::vec3(9, 0, 0), glm::vec3(0, 0, 1));
  const ExactEmitters four = chooseExactEmitters(scene, 1.0f, 4);
  ASSERT_EQ(four.primitives.size(), 2u);
  EXPECT_EQ(four.primitives[0], 0u);
  EXPECT_EQ(four.primitives[1], 1u);
  EXPECT_NEAR(four.emitters[0].radiance.x, 10.0 / kPi, 1e-6);
  EXPECT_EQ(four.emitters[0].positions.size(), 6u);
  EXPECT_FALSE(four.contains(2));
  EXPECT_EQ(chooseExactEmitters(scene, 1.0f, 64).primitives.size(), 3u);
  EXPECT_TRUE(chooseExactEmitters(scene, 1.0f, 0).primitives.empty());
}

}  // namespace
}  // namespace irbake
