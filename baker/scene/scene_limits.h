// The coordinates a bake handles (docs/refusals.md), in metres, world space. Above 1e9 m a triangle's squared
// cross product can pass float's 3.4e38: its normal vanishes and Embree aborts (SIGABRT) on the rays built from
// it; Embree also aborts on any ray whose origin lies beyond about 1.8e18 m. The scene loader refuses vertices and
// punctual lights beyond it, the probes' options and files points beyond it.
#pragma once

namespace irbake {

constexpr double kMaxSceneCoordinate = 1e9;
// Relative slack on the scene's limits, so that a value of exactly the limit, rounded to float, is inside.
constexpr double kSceneLimitSlack = 1e-6;

}  // namespace irbake
