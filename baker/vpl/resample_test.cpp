#include <gtest/gtest.h>

#include <cmath>

#include "sampling/sampling.h"
#include "raytrace/ray_tracer.h"
#include "testing/scenes.h"
#include "vpl/resample.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

// Two bounces of VPLs scattered in a unit cube with uneven, coloured powers.
VplSet scatteredSet(size_t perBounce) {
  VplSet set;
  Rng rng(7);
  for (int j = 0; j < 2; ++j)
    for (size_t i = 0; i < perBounce; ++i) {
      Vpl v;
      v.position = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform());
      v.power = glm::vec3(0.1 + rng.uniform(), 0.1 + 2.0 * rng.uniform(), 0.05 + 0.2 * rng.uniform()) * float(j + 1);
      v.bounce = j;
      set.vpls.push_back(v);
    }
  set.countPerBounce = {perBounce, perBounce};
  set.powerPerBounce.assign(2, glm::dvec3(0.0));
  for (const Vpl& v : set.vpls) set.powerPerBounce[v.bounce] += glm::dvec3(v.power);
  return set;
}

double weight(const glm::dvec3& p) { return p.x + p.y + p.z; }

}  // namespace

// Each bounce keeps at most its count and exactly its Σ(r+g+b); over seeds every VPL's kept power averages to
// its own (each channel: the resampling is unbiased VPL by VPL).
TEST(VplResample, BounceTotalsExactAndEveryVplUnbiased) {
  const VplSet original = scatteredSet(64);
  const std::vector<size_t> keep{16, 8};
  std::vector<glm::dvec3> mean(original.vpls.size(), glm::dvec3(0.0));
  // Kept VPLs keep their position: which original each one is, by position.
  auto indexOf = [&](const Vpl& v) {
    for (size_t i = 0; i < original.vpls.size(); ++i)
      if (original.vpls[i].position == v.position && original.vpls[i].bounce == v.bounce) return i;
    return original.vpls.size();
  };
  constexpr int kSeeds = 4000;
  for (int seed = 0; seed < kSeeds; ++seed) {
    VplSet set = original;
    resampleVpls(set, keep, seed);
    ASSERT_EQ(set.walked, 128u);
    for (int j = 0; j < 2; ++j) {
      ASSERT_LE(set.countPerBounce[j], keep[j]);
      ASSERT_NEAR(weight(set.powerPerBounce[j]), weight(original.powerPerBounce[j]), 1e-5 * weight(original.powerPerBounce[j]));
    }
    for (const Vpl& v : set.vpls) {
      const size_t i = indexOf(v);
      ASSERT_LT(i, original.vpls.size());
      mean[i] += glm::dvec3(v.power) / double(kSeeds);
    }
  }
  // A VPL is kept with probability K w / W ≈ 1/4 (bounce 0) or 1/8 (bounce 1): the mean of 4000 seeds is within
  // a few percent of its power (3 standard errors: ≈ 3 √(7/4000) ≈ 13% at worst for bounce 1; systematic picks
  // are far less spread than independent ones).
  double worst = 0.0, sumAll = 0.0, sumKept = 0.0;
  for (size_t i = 0; i < original.vpls.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(mean[i][c] / original.vpls[i].power[c] - 1.0));
      sumAll += original.vpls[i].power[c];
      sumKept += mean[i][c];
    }
  EXPECT_LT(worst, 0.13);
  EXPECT_NEAR(sumKept / sumAll, 1.0, 1e-4);
}

// Systematic picks along the Morton curve spread the kept VPLs over space: with 16 of 4096 equal VPLs on a
// unit square's 4×4 cells, every cell keeps exactly one (independent picks would leave ≈ 36% of cells empty).
TEST(VplResample, KeptVplsAreSpreadOverSpace) {
  VplSet set;
  Rng rng(3);
  for (int i = 0; i < 4096; ++i) {
    Vpl v;
    v.position = glm::vec3(rng.uniform(), rng.uniform(), 0.0f);
    v.power = glm::vec3(1.0f);
    set.vpls.push_back(v);
  }
  set.countPerBounce = {set.vpls.size()};
  set.powerPerBounce = {glm::dvec3(4096.0)};
  resampleVpls(set, {16}, 11);
  ASSERT_EQ(set.vpls.size(), 16u);
  int cells[16] = {};
  for (const Vpl& v : set.vpls) {
    EXPECT_NEAR(v.power.x, 256.0f, 1e-3f);
    ++cells[std::min(3, int(v.position.x * 4)) + 4 * std::min(3, int(v.position.y * 4))];
  }
  int empty = 0;
  for (int c : cells) empty += c == 0;
  EXPECT_LE(empty, 1);  // the Morton curve's quadrants are the cells; only rounding at the cell edges can move a pick
}

// A walk of 8× the paths split 4 ways, resampled to a plain walk's counts: in a closed grey room every bounce keeps
// exactly its energy, Φ ρ^j, on M_j = ⌊N ρ^j⌋ VPLs (the rounding of the big walk's counts aside).
TEST(VplResample, WalkFactorKeepsAPlainWalksCountsAndEveryBouncesEnergy) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(0.6f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 500;
  o.geometricTail = false;
  o.split = 4;
  o.walkFactor = 8;
  const VplSet set = generateVpls(s, rt, o);
  const double Phi = set.emittedPower.x;
  ASSERT_GE(set.bounces, 5);
  EXPECT_GT(set.walked, 8 * 4 * 500 * 0.36);  // the big walk's bounce 2 alone
  for (int j = 0; j <= 5; ++j) {
    const double m = std::floor(500 * std::pow(0.6, j) + 1e-9);
    EXPECT_NEAR(double(set.countPerBounce[j]), m, 1.0) << "bounce " << j;
    EXPECT_NEAR(set.powerPerBounce[j].x, Phi * std::pow(0.6, j), 1e-5 * Phi) << "bounce " << j;
  }
  // Two VPLs per surviving path past bounce 1.
  o.evaluatedSplit = 2;
  const VplSet two = generateVpls(s, rt, o);
  EXPECT_NEAR(double(two.countPerBounce[2]), 2 * std::floor(500 * 0.36 + 1e-9), 2.0);
  EXPECT_NEAR(two.powerPerBounce[2].x, Phi * 0.36, 1e-5 * Phi);
  // Half the emitter's VPLs, each twice as heavy: bounce 0 still carries Φ.
  o.evaluatedSplit = 1;
  o.evaluatedEmitterShare = 0.5;
  const VplSet half = generateVpls(s, rt, o);
  EXPECT_EQ(half.countPerBounce[0], 250u);
  EXPECT_NEAR(half.powerPerBounce[0].x, Phi, 1e-5 * Phi);
  EXPECT_NEAR(double(half.countPerBounce[1]), 300.0, 1.0);
}
