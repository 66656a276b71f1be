// The light tree's choice: a light that gives the point anything is never left out, the probabilities sum to at
// most one (the rest: a walk that ends in a node whose lights give nothing, an estimate of 0), and drawn choices
// follow the probabilities.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "lights/light_tree.h"
#include "common/maths.h"
#include "sampling/sampling.h"

namespace irbake {
namespace {

struct Lamps {
  std::vector<LightTreeEntry> entries;
  // What lamp i gives (x, n): I cosθ / (π d²) beyond its near distance, else 0.
  double value(uint32_t i, const glm::vec3& x, const glm::vec3& n) const {
    const LightTreeEntry& e = entries[i];
    const glm::vec3 d = e.position - x;
    const float r = glm::length(d);
    if (r <= e.near) return 0.0;
    return std::max(0.0, double(glm::dot(n, d / r))) * e.power / (kPi * r * r);
  }
};

Lamps scatteredLamps(size_t count, uint64_t seed) {
  Lamps l;
  Rng rng(seed);
  for (size_t i = 0; i < count; ++i) {
    const glm::vec3 p(float(rng.uniform() * 40.0 - 20.0), float(rng.uniform() * 3.0), float(rng.uniform() * 40.0 - 20.0));
    l.entries.push_back({static_cast<uint32_t>(i), p, float(1.0 + 9.0 * rng.uniform()), float(2.0 + 4.0 * rng.uniform())});
  }
  return l;
}

TEST(LightTree, ProbabilitiesCoverEveryContributingLightAndSumToAtMostOne) {
  const Lamps lamps = scatteredLamps(37, 5);
  const LightTree tree(lamps.entries);
  ASSERT_EQ(tree.size(), 37u);
  Rng rng(11);
  int contributing = 0;
  double sums = 0.0;
  for (int k = 0; k < 50; ++k) {
    const glm::vec3 x(float(rng.uniform() * 40.0 - 20.0), 0.0f, float(rng.uniform() * 40.0 - 20.0));
    const glm::vec3 n = k % 5 == 0 ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    auto exact = [&](uint32_t i) { return lamps.value(i, x, n); };
    double sum = 0.0;
    bool any = false;
    for (uint32_t i = 0; i < 37; ++i) {
      const double p = tree.pmf(x, n, i, exact);
      sum += p;
      if (exact(i) > 0.0) {
        any = true;
        EXPECT_GT(p, 0.0) << "point " << k << " lamp " << i;
      }
    }
    if (any) {
      ++contributing;
      EXPECT_LE(sum, 1.0 + 1e-9) << "point " << k;
      // A walk ends in nothing where a box's bound promises light that none of its lights gives (the point
      // within their near distance): little on the whole, at most four fifths at a point among close lamps.
      EXPECT_GT(sum, 0.15) << "point " << k;
      sums += sum;
    }
  }
  EXPECT_GT(contributing, 40);
  std::printf("[ figure ] probabilities' sum, mean over the points: %.3f\n", sums / contributing);
  EXPECT_GT(sums / contributing, 0.9);
}

TEST(LightTree, DrawsFollowTheProbabilitiesAndTheEstimateIsUnbiased) {
  const Lamps lamps = scatteredLamps(64, 9);
  const LightTree tree(lamps.entries);
  const glm::vec3 x(1.0f, 0.0f, -2.0f), n(0, 1, 0);
  auto exact = [&](uint32_t i) { return lamps.value(i, x, n); };
  double truth = 0.0;
  for (uint32_t i = 0; i < 64; ++i) truth += exact(i);
  ASSERT_GT(truth, 0.0);
  const int draws = 200000;
  std::map<uint32_t, int> counts;
  double sum = 0.0, squares = 0.0;
  for (int k = 0; k < draws; ++k) {
    const LightTree::Choice c = tree.sample(x, n, (k + 0.5) / draws, exact);
    ASSERT_NE(c.light, UINT32_MAX);
    ++counts[c.light];
    const double v = exact(c.light) / c.pmf;
    sum += v, squares += v * v;
  }
  for (const auto& [light, count] : counts)
    EXPECT_NEAR(double(count) / draws, tree.pmf(x, n, light, exact), 2e-4) << "lamp " << light;
  const double mean = sum / draws, deviation = std::sqrt(std::max(0.0, squares / draws - mean * mean));
  EXPECT_NEAR(mean, truth, 1e-3 * truth);
  // The importance follows the value: one draw's relative deviation stays well below a uniform choice's.
  double uniformSquares = 0.0;
  for (uint32_t i = 0; i < 64; ++i) uniformSquares += 64.0 * exact(i) * exact(i);
  const double uniformDeviation = std::sqrt(uniformSquares - truth * truth);
  std::printf("[ figure ] one draw's deviation / mean: tree %.3f, uniform %.3f\n", deviation / truth, uniformDeviation / truth);
  EXPECT_LT(deviation, 0.5 * uniformDeviation);
}

// Stratified draws walked at once give each u_k = (k + shift) / m the light sample() gives it, with its
// probability (to rounding: the walk splits intervals where sample() rescales u), each after the walk weighed
// that light.
TEST(LightTree, StratifiedDrawsAtOnceAreTheDrawsOneByOne) {
  const Lamps lamps = scatteredLamps(64, 9);
  const LightTree tree(lamps.entries);
  Rng rng(4);
  int same = 0, taken = 0;
  for (int p = 0; p < 20; ++p) {
    const glm::vec3 x(float(rng.uniform() * 40.0 - 20.0), 0.0f, float(rng.uniform() * 40.0 - 20.0)), n(0, 1, 0);
    std::set<uint32_t> weighed;
    auto exact = [&](uint32_t i) { return weighed.insert(i), lamps.value(i, x, n); };
    auto plain = [&](uint32_t i) { return lamps.value(i, x, n); };
    const double shift = rng.uniform();
    const int m = 16;
    int expect = 0;
    tree.sampleStratified(x, n, shift, m, exact, [&](int k, const LightTree::Choice& c) {
      EXPECT_TRUE(weighed.count(c.light)) << "point " << p << " draw " << k;
      EXPECT_GE(k, expect) << "in order of k";
      expect = k + 1, ++taken;
      const LightTree::Choice one = tree.sample(x, n, (k + shift) / m, plain);
      if (one.light == c.light) {
        ++same;
        EXPECT_NEAR(c.pmf, one.pmf, 1e-9 * one.pmf);
      }
    });
  }
  EXPECT_GT(taken, 200);
  EXPECT_GE(same, taken - 2);  // a u on a split's rounding edge may go the other way
}

// Two sets of stratified draws in one walk give each set what its own walk gives, bit for bit, each light after
// the walk weighed it.
TEST(LightTree, TwoSetsInOneWalkAreEachSetsOwnWalk) {
  const Lamps lamps = scatteredLamps(64, 9);
  const LightTree tree(lamps.entries);
  Rng rng(7);
  int taken = 0;
  for (int p = 0; p < 20; ++p) {
    const glm::vec3 x(float(rng.uniform() * 40.0 - 20.0), 0.0f, float(rng.uniform() * 40.0 - 20.0)), n(0, 1, 0);
    const double shift[2] = {rng.uniform(), rng.uniform()};
    const int m[2] = {12, 20};
    std::vector<LightTree::Choice> own[2];
    for (int s = 0; s < 2; ++s) {
      own[s].assign(size_t(m[s]), LightTree::Choice{});
      tree.sampleStratified(x, n, shift[s], m[s], [&](uint32_t i) { return lamps.value(i, x, n); },
                            [&](int k, const LightTree::Choice& c) { own[s][size_t(k)] = c; });
    }
    std::set<uint32_t> weighed;
    auto exact = [&](uint32_t i) { return weighed.insert(i), lamps.value(i, x, n); };
    int seen[2] = {0, 0};
    tree.sampleStratifiedPair(x, n, shift, m, exact, [&](int s, int k, const LightTree::Choice& c) {
      EXPECT_TRUE(weighed.count(c.light)) << "point " << p << " set " << s << " draw " << k;
      EXPECT_EQ(c.light, own[s][size_t(k)].light) << "point " << p << " set " << s << " draw " << k;
      EXPECT_EQ(c.pmf, own[s][size_t(k)].pmf) << "point " << p << " set " << s << " draw " << k;
      ++seen[s], ++taken;
    });
    for (int s = 0; s < 2; ++s)
      EXPECT_EQ(seen[s], int(std::count_if(own[s].begin(), own[s].end(), [](const LightTree::Choice& c) {
                  return c.light != UINT32_MAX;
                })));
  }
  EXPECT_GT(taken, 400);
}

}  // namespace
}  // namespace irbake
