// Sampling utilities against their definitions: Keller's radical inverses, stratification, the alias table's
// exact probabilities, the cosine lattice.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

#include "common/maths.h"
#include "sampling/sampling.h"

using namespace irbake;

TEST(Halton, RadicalInversesAreKellersPhi) {
  EXPECT_DOUBLE_EQ(radicalInverse(2, 1), 0.5);
  EXPECT_DOUBLE_EQ(radicalInverse(2, 6), 0.375);  // 110b → 0.011b
  EXPECT_DOUBLE_EQ(radicalInverse(3, 5), 2.0 / 3.0 + 1.0 / 9.0);  // 12 in base 3 → 0.21
}

// Randomized QMC: over seeds, every point of every dimension is a uniform number, independent of the
// other dimensions of the same point, so a walk's expected result over seeds is the exact integral
// whatever the path's dimensions are used for. (The earlier construction left dimensions 0 and 1 as the
// plain radical inverses and used one digit permutation per dimension: on Sponza's gallery the walk came
// out dark for every seed; docs/units.md.)
TEST(Halton, EveryPointIsUniformOverSeeds) {
  constexpr int kSeeds = 4000;
  for (uint64_t index : {0ull, 1ull, 5ull, 1000ull}) {
    std::array<std::array<int, 10>, 6> histogram{};
    double cross = 0.0;  // E[(x0 − ½)(x2 − ½)] over seeds: 0 when dimensions are independent
    for (int seed = 0; seed < kSeeds; ++seed) {
      Halton h(6, static_cast<uint32_t>(seed));
      for (int d = 0; d < 6; ++d) ++histogram[d][std::min(9, static_cast<int>(h.sample(d, index) * 10.0))];
      cross += (h.sample(0, index) - 0.5) * (h.sample(2, index) - 0.5);
    }
    for (int d = 0; d < 6; ++d) {
      double chi2 = 0.0;
      for (int c : histogram[d]) chi2 += (c - kSeeds / 10.0) * (c - kSeeds / 10.0) / (kSeeds / 10.0);
      EXPECT_LT(chi2, 27.9) << "dimension " << d << " index " << index;  // χ²(9 dof) at p = 0.001
    }
    // Var of the product is 1/144; 4.5 standard errors.
    EXPECT_LT(std::abs(cross / kSeeds), 4.5 / (12.0 * std::sqrt(static_cast<double>(kSeeds)))) << "index " << index;
  }
}

TEST(Halton, EveryDimensionIsStratifiedOverFullDigitBlocks) {
  for (uint32_t seed : {0u, 7u}) {
    Halton h(12, seed);
    for (int d = 0; d < 12; ++d) {
      static const uint32_t primes[12] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37};
      uint32_t b = primes[d], n = b * b;
      std::set<uint32_t> cells;
      for (uint32_t i = 0; i < n; ++i) {
        double x = h.sample(d, i);
        ASSERT_GE(x, 0.0);
        ASSERT_LT(x, 1.0);
        cells.insert(static_cast<uint32_t>(std::floor(x * n + 1e-9)));  // radical inverses hit k/n exactly
      }
      EXPECT_EQ(cells.size(), n) << "dimension " << d << " seed " << seed;
    }
  }
  // Scrambling changes high dimensions with the seed.
  Halton a(6, 1), b(6, 2);
  int differ = 0;
  for (int i = 1; i < 20; ++i) differ += a.sample(5, i) != b.sample(5, i);
  EXPECT_GT(differ, 10);
}

// The lattice the per-sample stages trace: ray for ray cosineHemisphere's directions at the lattice's (u, v),
// and a cosine-weighted estimator over it is exact for cosθ (∫ cosθ · cosθ/π dω / ∫ cosθ/π dω = 2/3).
TEST(CosineLattice, MatchesCosineHemisphereAtTheLatticePoints) {
  const glm::vec3 normals[] = {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(0.3f, -0.8f, 0.2f))};
  for (const glm::vec3& n : normals)
    for (int count : {1, 16, 64, 1000}) {
      const double r1 = 0.73, r2 = 0.41;
      CosineLattice lattice(n, count, r1, r2);
      double meanCos = 0.0;
      for (int i = 0; i < count; ++i) {
        const double u = std::fmod((i + 0.5) / count + r1, 1.0), v = std::fmod(i * 0.6180339887498949 + r2, 1.0);
        const glm::vec3 want = cosineHemisphere(n, u, v), got = lattice.next();
        EXPECT_NEAR(glm::length(got - want), 0.0, 2e-6) << "ray " << i << " of " << count;
        EXPECT_NEAR(glm::length(got), 1.0, 1e-6);
        meanCos += glm::dot(got, n) / count;
      }
      if (count >= 1000) {
        EXPECT_NEAR(meanCos, 2.0 / 3.0, 1e-4);
      }
    }
}

TEST(AliasTable, ProbabilitiesAndResidualsAreExact) {
  std::vector<double> w = {1.0, 3.0, 0.0, 4.0};
  AliasTable t(w);
  EXPECT_DOUBLE_EQ(t.total(), 8.0);
  EXPECT_DOUBLE_EQ(t.pdf(1), 3.0 / 8.0);
  const int M = 80000;
  std::vector<int> count(4, 0);
  std::vector<double> residualSum(4, 0.0);
  for (int k = 0; k < M; ++k) {
    double r;
    size_t i = t.sample((k + 0.5) / M, &r);
    ++count[i];
    residualSum[i] += r;
    ASSERT_GE(r, 0.0);
    ASSERT_LT(r, 1.0);
  }
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(count[i] / double(M), w[i] / 8.0, 2.0 / M);
    if (count[i] > 0) { EXPECT_NEAR(residualSum[i] / count[i], 0.5, 1e-3); }
  }
}
