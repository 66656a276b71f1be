// The estimator on synthetic replicates with a known variance (closed forms).
#include "stages/error_estimate/error_estimate.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "common/error.h"

namespace irbake {
namespace {

// R replicates of one W×H page: texel = mu + sigma·N(0, 1), independent everywhere; every 7th texel invalid.
std::vector<std::vector<Lightmap>> gaussianReplicates(int R, int W, int H, glm::vec3 mu, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  std::vector<std::vector<Lightmap>> reps(R);
  for (auto& r : reps) {
    Lightmap m;
    m.width = W;
    m.height = H;
    m.texels.resize(m.size());
    m.valid.assign(m.size(), 1);
    for (size_t t = 0; t < m.size(); ++t) {
      m.texels[t] = mu + sigma * glm::vec3(n(rng), n(rng), n(rng));
      if (t % 7 == 3) m.valid[t] = 0;
    }
    r.push_back(m);
  }
  return reps;
}

// Closed form: the mean of R replicates of a bin of n valid texels has standard error sigma/sqrt(nR), so the
// figure's square is the mean over bins of sigma²/(nR) (n = 13 or 14 of 16 here), over |mu|rms².
TEST(ErrorEstimate, MatchesTheClosedFormStandardErrorOfTheMean) {
  const glm::vec3 mu(1.0f, 0.5f, 0.25f);
  const float sigma = 0.3f;
  for (int R : {2, 4, 8}) {
    const auto reps = gaussianReplicates(R, 256, 256, mu, sigma, 17u + R);
    const BinnedError e = replicateError(reps, nullptr);
    ASSERT_EQ(e.bins, 64u * 64u);
    double meanInverseN = 0.0;  // over bins, 1/n of its valid texels (those with t % 7 == 3 are invalid)
    for (int by = 0; by < 256; by += 4)
      for (int bx = 0; bx < 256; bx += 4) {
        int n = 0;
        for (int y = by; y < by + 4; ++y)
          for (int x = bx; x < bx + 4; ++x) n += (static_cast<size_t>(y) * 256 + x) % 7 != 3;
        meanInverseN += 1.0 / n / (64.0 * 64.0);
      }
    const double expectedNoise = sigma * std::sqrt(meanInverseN / R);
    const double muRms = std::sqrt((1.0 + 0.25 + 0.0625) / 3.0);
    // 12288 bin-channels with R − 1 degrees of freedom each: the RMS is within 1.5% (3σ) at R = 2.
    EXPECT_NEAR(e.noiseRms / expectedNoise, 1.0, 0.03) << "R = " << R;
    EXPECT_NEAR(e.relative, expectedNoise / muRms, 0.03 * expectedNoise / muRms) << "R = " << R;
    // Against the truth: the replicates' mean's actual error on the same bins.
    const std::vector<Lightmap> mean = replicateMean(reps);
    std::vector<std::vector<Lightmap>> truthAndMean = {mean, mean};
    for (Lightmap& m : truthAndMean[0])
      for (auto& t : m.texels) t = mu;
    // Two "replicates" mean and truth: s²/2 = (mean − mu)²/4, so twice that noiseRms is the true RMS error.
    const double actual = 2.0 * replicateError(truthAndMean, nullptr).noiseRms;
    EXPECT_NEAR(e.noiseRms / actual, 1.0, 0.05) << "R = " << R;
  }
}

TEST(ErrorEstimate, PerTexelStandardErrorAveragesToSigmaOverRootR) {
  const float sigma = 0.2f;
  const int R = 4;
  const auto reps = gaussianReplicates(R, 128, 128, glm::vec3(2.0f), sigma, 5u);
  const std::vector<Lightmap> se = standardErrorPages(reps);
  double sum2 = 0.0;
  size_t n = 0;
  for (size_t t = 0; t < se[0].size(); ++t) {
    if (!reps[0][0].valid[t]) {
      EXPECT_EQ(se[0].texels[t], glm::vec3(0.0f));
      continue;
    }
    const glm::dvec3 s(se[0].texels[t]);
    sum2 += s.x * s.x + s.y * s.y + s.z * s.z;
    n += 3;
  }
  // E[s²/R] = σ²/R exactly: the mean square over 42k channel samples (3 dof each) within 3%.
  EXPECT_NEAR(std::sqrt(sum2 / double(n)) / (sigma / std::sqrt(double(R))), 1.0, 0.03);
}

// Charts as 56×56 squares of valid texels in 64×64 cells of a 256² page, their one-texel border ring 10×
// noisier than inside. Closed forms: a bin of texels with variances σ_t² has the mean's squared standard
// error Σσ_t²/(n² R). Interior bins leave the ring out (n = 16, 12 or 9 texels, all at σ_in); valid bins keep it.
TEST(ErrorEstimate, InteriorBinsLeaveTheChartBorderRingOut) {
  const int W = 256, R = 4;
  const float sigmaIn = 0.1f, sigmaRing = 1.0f;
  std::mt19937 rng(29u);
  std::normal_distribution<float> n01(0.0f, 1.0f);
  const auto inChart = [](int x, int y) { return x % 64 >= 4 && x % 64 < 60 && y % 64 >= 4 && y % 64 < 60; };
  const auto onRing = [](int x, int y) { return x % 64 == 4 || x % 64 == 59 || y % 64 == 4 || y % 64 == 59; };
  std::vector<std::vector<Lightmap>> reps(R);
  for (auto& r : reps) {
    Lightmap m;
    m.width = m.height = W;
    m.texels.resize(m.size());
    m.valid.assign(m.size(), 0);
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t t = static_cast<size_t>(y) * W + x;
        if (!inChart(x, y)) continue;
        m.valid[t] = 1;
        m.texels[t] = glm::vec3(1.0f) + (onRing(x, y) ? sigmaRing : sigmaIn) * glm::vec3(n01(rng), n01(rng), n01(rng));
      }
    r.push_back(m);
  }
  double validSe2 = 0.0, interiorSe2 = 0.0;
  size_t validBins = 0, interiorBins = 0;
  for (int by = 0; by < W; by += 4)
    for (int bx = 0; bx < W; bx += 4) {
      int nValid = 0, nInterior = 0;
      double var = 0.0;
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) {
          if (!inChart(x, y)) continue;
          ++nValid;
          nInterior += !onRing(x, y);
          var += onRing(x, y) ? sigmaRing * sigmaRing : sigmaIn * sigmaIn;
        }
      if (2 * nValid >= 16) validSe2 += var / (double(nValid) * nValid * R), ++validBins;
      if (2 * nInterior >= 16) interiorSe2 += sigmaIn * sigmaIn / (double(nInterior) * R), ++interiorBins;
    }
  const BinnedError valid = replicateError(reps, nullptr);
  const BinnedError interior = replicateError(reps, nullptr, 4, 1.0, BinTexels::Interior);
  ASSERT_EQ(valid.bins, validBins);
  ASSERT_EQ(interior.bins, interiorBins);
  // 9408 bin-channels with 3 degrees of freedom each: the RMS within 1.3% (3σ); 2% asked.
  EXPECT_NEAR(valid.noiseRms / std::sqrt(validSe2 / double(validBins)), 1.0, 0.02);
  EXPECT_NEAR(interior.noiseRms / std::sqrt(interiorSe2 / double(interiorBins)), 1.0, 0.02);
  // A page valid everywhere has no interior ring: the page's own edge does not erode (compare.py's rule).
  auto whole = gaussianReplicates(2, 32, 32, glm::vec3(1.0f), 0.2f, 3u);
  for (auto& r : whole) std::fill(r[0].valid.begin(), r[0].valid.end(), 1);
  EXPECT_EQ(replicateError(whole, nullptr).noiseRms, replicateError(whole, nullptr, 4, 1.0, BinTexels::Interior).noiseRms);
}

TEST(ErrorEstimate, DeterministicPagesGiveZeroAndBadInputIsRefused) {
  auto reps = gaussianReplicates(2, 16, 16, glm::vec3(1.0f), 0.0f, 1u);
  EXPECT_EQ(replicateError(reps, nullptr).noiseRms, 0.0);
  EXPECT_NEAR(replicateError(reps, nullptr).signalRms, 1.0, 1e-6);
  EXPECT_THROW(replicateError({reps[0]}, nullptr), Error);
  reps[1][0].width = 8;
  reps[1][0].texels.resize(reps[1][0].size());
  EXPECT_THROW(replicateError(reps, nullptr), Error);
}

}  // namespace
}  // namespace irbake
