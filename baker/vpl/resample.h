// Thinning a walk's VPLs to fewer of the same expected light: per bounce, systematic resampling by power in a
// space-filling order (docs/units.md, "Walking more paths than are evaluated").
#pragma once
#include <cstdint>
#include <vector>

#include "vpl/vpl.h"

namespace irbake {

// Keeps about keep[j] VPLs of bounce j (bounces past the list's end use its last entry; a bounce with no more
// VPLs than that is kept whole). Bounce j's VPLs are ordered along a Morton curve over their positions and
// picked by systematic resampling with probability ∝ w = Φ_r + Φ_g + Φ_b (one uniform offset per bounce from
// `seed`); a VPL picked n times is kept once with power Φ · n W / (K w) (W: the bounce's Σ w, K its keep), so
// the bounce's Σ w is exact and every channel's power is unbiased. The kept VPLs stay in the set's order
// (bounce, then path); countPerBounce and powerPerBounce are recomputed, `walked` records the count before.
void resampleVpls(VplSet& set, const std::vector<size_t>& keep, uint64_t seed);

}  // namespace irbake
