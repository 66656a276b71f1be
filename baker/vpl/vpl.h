// Virtual point lights from Keller's quasi-random walk.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common/progress.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"

namespace irbake {

// A cosine (Lambertian) emitter at a surface point: radiant intensity I(ω) = Φ max(0, n·ω) / π.
struct Vpl {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec3 power{0.0f};  // Φ, watts (RGB)
  int bounce = 0;         // 0: on an area emitter; j ≥ 1: after j diffuse reflections
};

struct WalkOptions {
  int paths = 1024;        // N: paths started from the lights (area emitters and punctual lights); the
                           // library's default, which irbake bake always replaces (--quality: app/quality.cpp)
  std::optional<int> maxBounces;  // unset: auto (autoBounceDepth, tail added); set (≥ 0): exactly this deepest
                                  // bounce, no tail added
  double tailEnergy = 1e-3;      // auto: stop once the light not yet placed, ρ̄^(J+1), is below this fraction
  double maxVplsPerPath = 8.0;   // auto: VPL budget Σ_j M_j ≤ this × N (a scene of ρ̄ = 0.9 reaches J = 14)
  bool geometricTail = true;     // auto: the bounces beyond J added to bounce J as a geometric series
  std::optional<int> split;      // paths fork into this many where they leave bounce 1 (unset: auto, from the
                                 // share of bounce-1 light that meets the scene again; 1 = Keller's walk)
  int maxAutoSplit = 4;          // auto: at most this many children per path (more cost time for no less error)
  int minAutoSplit = 1;          // auto: at least this many (the bake plan raises it where the VPL sum is the map's
                                 // bounced light: the deep bounces' few carriers are the seed-to-seed noise there)
  int walkFactor = 1;            // the walk follows this many times `paths`, then each bounce is resampled
                                 // (vpl/resample.h) to the count a walk of `paths` would leave there
  int evaluatedSplit = 1;        // with walkFactor > 1: VPLs kept per surviving path at bounces ≥ 2 (1: a plain
                                 // walk's M_j, however many ways the walk split)
  double evaluatedEmitterShare = 1.0;  // with walkFactor > 1: bounce 0 keeps this share of `paths` VPLs (on small
                                       // emitters they lie close together, so fewer light the scene as well)
  uint32_t seed = 0;       // seeds the Halton digit permutations
  ProgressCallback progress;
};

struct VplSet {
  std::vector<Vpl> vpls;
  std::vector<size_t> countPerBounce;       // index = bounce
  std::vector<glm::dvec3> powerPerBounce;   // watts, index = bounce
  glm::dvec3 emittedPower{0.0};             // area emitters + punctual lights (W)
  double meanReflectivity = 0.0;            // ρ̄ used for the path-count reduction
  int split = 1;                            // children per path past bounce 1
  std::vector<double> lightReach;           // per punctual light, then the sky: share of pilot rays that reach a
                                            // lit side (within a light's range, by its window); the start table
                                            // weighs their power by it
  double rehitFraction = 1.0;               // auto split: V_2 M_1 / (V_1 M_2), the share of paths leaving
                                            // bounce 1 that hit the scene again
  int bounces = 0;                          // deepest bounce generated
  size_t walked = 0;                        // VPLs the walk left before resampling (vpl/resample.h)
  glm::dvec3 tailFactor{1.0};               // bounces ⌈J/2⌉…J carry this × their own power: with it, the
                                            // light of bounces > J, P_J r/(1−r) per channel, r the ratio of
                                            // successive bounce powers pooled over those bounces
  // The report's "vpls" object without what the walk was asked for (paths, seed: the bake adds them).
  nlohmann::json toJson() const {
    auto rgb = [](const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
    nlohmann::json perBounce = nlohmann::json::array();
    glm::dvec3 total(0.0);
    for (size_t b = 0; b < countPerBounce.size(); ++b) {
      const glm::dvec3 power = b < powerPerBounce.size() ? powerPerBounce[b] : glm::dvec3(0.0);
      total += power;
      perBounce.push_back({{"bounce", b}, {"count", countPerBounce[b]}, {"power", rgb(power)}});
    }
    return {{"count", vpls.size()},          {"bounces", bounces},     {"meanReflectivity", meanReflectivity},
            {"emittedPower", rgb(emittedPower)}, {"totalPower", rgb(total)}, {"perBounce", perBounce},
            {"split", split},                {"rehitFraction", rehitFraction}, {"lightReach", lightReach},
            {"walked", walked}};
  }
};

// The deepest bounce of the auto walk for N paths at mean reflectivity ρ̄: the largest J with
// M_J = ⌊N ρ̄^J⌋ ≥ 1 while ρ̄^J ≥ tailEnergy (the light left after J − 1 is still worth placing) and
// Σ_{j≤J} M_j ≤ maxVplsPerPath · N. The light beyond J is added as a tail (docs/units.md).
int autoBounceDepth(uint64_t paths, double rho, const WalkOptions& options);

// 1/(1 − r) per channel with r = lastPower / previousPower clamped to [0, 0.999]: the bounces beyond J, each assumed
// to be the previous one times r (exact when the bounce distribution has reached the transport
// operator's dominant mode, e.g. a closed furnace, where r = ρ).
glm::dvec3 geometricTailFactor(const glm::dvec3& lastPower, const glm::dvec3& previousPower);

// The bounces beyond J of an auto walk (J = set.bounces), P_J r/(1 − r), added to the VPLs of bounces ⌈J/2⌉…J
// in proportion to their power (sets tailFactor). r is pooled over those bounces that hold at least 16 VPLs
// (and whose previous bounce does); when none of them does, over the deepest such bounces.
void addGeometricTail(VplSet& set);

VplSet generateVpls(const Scene& scene, const RayTracer& rt, const WalkOptions& options);

}  // namespace irbake
