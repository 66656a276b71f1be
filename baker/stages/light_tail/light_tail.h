// The light the cut takes back, sampled. A light without range is cut where its light falls to a share of the
// scene's reference (lights/light_reach.h): every evaluator gives it only up to its reach, faded out over the last
// quarter. Many such lights (a town's lamps) leave many small tails whose sum is not small. Here each texel gets
// an estimate of that sum: candidate lights drawn from a light tree (lights/light_tree.h) over the cut lights, in
// proportion to a bound on what each gives the texel, weighed by their exact unshadowed left-out light (their light
// without the cut less their faded light); N shadow rays go to lights resampled among them in proportion to that
// weight (resampled importance sampling), so the rays only find out the visibility; each texel's rays follow its
// unshadowed estimate (the page's mean N), and its candidates the estimate of the texels just before it along its
// row. The tail is faint and smooth
// (far lights), so the estimate is filtered on the surface like the sky; two independent halves of the candidates
// and rays, filtered alike, tell its remaining noise for the error figure. docs/units.md, "Light reach".
#pragma once
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

struct LightTailOptions {
  int samples = 8;       // shadow rays per texel (0: the cut light stays left out)
  int candidates = 16;   // lights drawn per texel, among which the rays are resampled (0: each ray its own draw)
  int filterRadius = 3;  // (2r+1)² window of the texel filter on the same surface over the estimate; 0: none
  bool allocate = true;  // with candidates: rays per texel in proportion to its unshadowed tail, the page's mean
                         // `samples` (false: `samples` everywhere)
  bool allocateCandidates = true;  // with allocate: candidates per texel in proportion to the tail of the texels
                                   // just before it, the page's mean `candidates` (false: `candidates` everywhere)
  uint64_t seed = 0;     // the draws' seed (the walk's)
};

struct LightTailStats {
  size_t lights = 0;          // cut lights in the tree
  size_t texels = 0;          // texels given an estimate
  size_t rays = 0;            // shadow rays traced
  double added = 0.0;         // sum over those texels of the added map value (channel mean)
  double variance = 0.0;      // sum over those texels of the estimate's variance (channel mean, after the filter)
  double seconds = 0.0;
  nlohmann::json toJson() const;
};

// The cut lights' left-out light per page of the punctual lights' direct pages, traced but not yet added: the
// shadow-edge stage weighs a texel's visibility jump against all of the lights' light, the cut part included.
struct LightTailPages {
  std::vector<std::vector<glm::vec3>> added;   // per page and texel: what addLightTailPages adds (0 where nothing)
  std::vector<std::vector<float>> unshadowed;  // per page and texel: the candidates' estimate of the same light
                                               // before its shadows (channel mean), filtered alike; 0 without candidates
  LightTailStats stats;
};

// The cut lights' left-out light for each page of `maps` (the punctual lights' direct pages, one per in.texels
// page; their validity is read). skip: per scene light, 1: leave it alone (a light whose direct light is not in
// these pages); may be empty.
LightTailPages traceLightTail(const BakeInputs& in, const std::vector<Lightmap>& maps, const LightTailOptions& options,
                              const std::vector<uint8_t>& skip = {});
void addLightTailPages(const LightTailPages& tail, std::vector<Lightmap>& maps);

// Both at once: adds to each page of `maps` the cut lights' left-out light.
LightTailStats addLightTail(const BakeInputs& in, std::vector<Lightmap>& maps, const LightTailOptions& options,
                            const std::vector<uint8_t>& skip = {});

}  // namespace irbake
