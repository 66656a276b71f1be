// The backend stage of a bake as StagedBake runs it (pipeline/bake.cpp: directStage, planBlocks, evaluateBlock,
// backendMaps), on the caller's texel pages and VPLs: for the interleave tests and the speed benchmark, which
// bake hand-built grids or their own atlas. integration_test checks it against the bake, bit for bit.
#pragma once
#include <vector>

#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator.h"
#include "lightmap/lightmap.h"

namespace irbake::testing {

// The punctual lights on every texel in one call (blank valid pages without them); then, for each of the n²
// interleave classes (classVplSubsets, interleaveClass), the class's VPLs on its texels in one call, each texel's
// value scattered back to its page; the classes mixed into the maps by addMixedClasses (n ≤ 1: one class, added
// unfiltered). The bake splits a class's VPLs into blocks and adds them exactly: with one block per class that
// sum is the block's own value. backendCalls, if given, is set to the number of evaluator calls.
std::vector<Lightmap> bakeBackendStage(const BakeInputs& in, int n, const Evaluator& evaluator,
                                       int* backendCalls = nullptr);

}  // namespace irbake::testing
