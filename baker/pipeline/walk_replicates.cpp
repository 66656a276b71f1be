// The walk of an error-estimating bake as independent replicates, and the VPL blocks of each.
#include <algorithm>
#include <cmath>

#include "pipeline/bake_state.h"
#include "sampling/sampling.h"
#include "stages/interleave/interleaved_sampling.h"

namespace irbake {

// The walk of replicate i: the plan's walk, or with an estimate half its paths and a seed of its own (an
// independent digit permutation of the Halton points), so that replicates are independent estimates.
WalkOptions replicateWalk(const BakeState& s, size_t i) {
  WalkOptions o = s.plan.walk;
  if (!estimating(s)) return o;
  o.paths = std::max(1, o.paths / 2);
  o.seed = static_cast<uint32_t>(hashSeed(s.options.walk.seed, 0x7265706c6963ull, i));  // "replic"
  return o;
}

namespace {

// Replicate i's VPLs, walked and selected as replicate 0's were (the same factor and bound).
VplSet walkReplicate(BakeState& s, size_t i) {
  WalkOptions o = replicateWalk(s, i);
  o.progress = withProgress(s, o.progress);
  if (s.plan.importanceFactor > 1.0)
    o.paths = static_cast<int>(std::min(double(1 << 26), std::round(o.paths * s.plan.importanceFactor)));
  VplSet set = generateVpls(s.scene, *s.rayTracer, o);
  if (s.plan.importanceFactor > 1.0) {
    VplSelection selection;
    selection.keepFraction = s.options.vplImportance.keepShare / s.plan.importanceFactor;
    selection.clampBound = s.candidateBound;
    selection.seed = o.seed;
    selectVplsByImportance(s.scene, *s.rayTracer, s.texels, set, s.options.vplImportance, selection);
  }
  return set;
}

// The walk so far as one set (the report's counts; powers as the mean of the replicates).
void combineReplicates(BakeState& s) {
  VplSet all = s.replicates[0];
  all.vpls.clear();
  const float share = 1.0f / static_cast<float>(s.replicates.size());
  for (auto& power : all.powerPerBounce) power *= share;
  for (size_t r = 0; r < s.replicates.size(); ++r) {
    for (size_t b = 0; r > 0 && b < s.replicates[r].powerPerBounce.size(); ++b) {
      if (b >= all.powerPerBounce.size()) all.powerPerBounce.resize(b + 1, glm::dvec3(0.0));
      all.powerPerBounce[b] += s.replicates[r].powerPerBounce[b] * double(share);
    }
    for (Vpl v : s.replicates[r].vpls) {
      v.power *= share;
      all.vpls.push_back(v);
    }
    for (size_t b = 0; r > 0 && b < s.replicates[r].countPerBounce.size(); ++b) {
      if (b >= all.countPerBounce.size()) all.countPerBounce.resize(b + 1, 0);
      all.countPerBounce[b] += s.replicates[r].countPerBounce[b];
    }
  }
  s.vpls = std::move(all);
}

}  // namespace

// Replicate 0 is the walk just made (its clamp settled); replicate 1 pairs it.
void startReplicates(BakeState& s) {
  s.replicates = {s.vpls, walkReplicate(s, 1)};
  combineReplicates(s);
}

void addRound(BakeState& s) {
  timed(s, "vpls", [&] {
    for (int k = 0; k < 2; ++k) s.replicates.push_back(walkReplicate(s, s.replicates.size()));
    combineReplicates(s);
  });
  for (size_t r = s.replicates.size() - 2; r < s.replicates.size(); ++r) appendBlocks(s, r);
}

void appendBlocks(BakeState& s, size_t r) {
  const VplSet& set = s.replicates.empty() ? s.vpls : s.replicates[r];
  if (s.classVpls.size() <= r) s.classVpls.resize(r + 1);
  s.classVpls[r] = classVplSubsets(set, s.plan.interleave);
  const size_t blockSize = static_cast<size_t>(std::max(1, s.options.vplBlock));
  for (size_t c = 0; c < s.classVpls[r].size(); ++c)
    for (size_t b0 = 0; b0 < s.classVpls[r][c].vpls.size(); b0 += blockSize)
      s.blocks.push_back({static_cast<int>(c), b0, std::min(s.classVpls[r][c].vpls.size(), b0 + blockSize), r});
}

}  // namespace irbake
