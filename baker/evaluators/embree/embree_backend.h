// The Embree evaluator: every valid texel sample gathers the punctual lights (exact, one shadow ray each)
// and all VPLs (clamped geometry term, ray-traced visibility). Formulas: transport/geometry_term.h. The
// energy the clamp removes is given back after any evaluator by stages/compensation; eval.biasCompensation
// is not read here.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator.h"
#include "lightmap/lightmap.h"
#include "sampling/sampling.h"

namespace irbake {

struct EmbreeOptions {
  int vplBlock = 256;            // VPLs per block: a block stays in cache while a tile of samples loops over it
  int tileSlots = 64;            // texel samples per parallel task
  bool packets = true;           // shadow rays in packets of 8 (rtcOccluded8): faster than one by one, the same maps
};

// Asked for L1 pages (EvaluationRequest::directional), it gathers them in the same pass from the same punctual
// lights and clamped VPLs (each visible source's direction is at hand there); the map is the same bits with
// or without them. A texel subset costs only its texels' rays. stats(): an empty object (nothing measured).
class EmbreeEvaluator final : public Evaluator {
 public:
  explicit EmbreeEvaluator(const EmbreeOptions& options = {}) : options_(options) {}
  // Throws Error(NumericError) on NaN/Inf.
  std::vector<Lightmap> evaluate(const BakeInputs& inputs, const EvaluationRequest& request = {}) const override;
  const char* name() const override { return "embree"; }
  nlohmann::json stats() const override { return nlohmann::json::object(); }

 private:
  EmbreeOptions options_;
};

// Every texel, no L1 pages: EmbreeEvaluator(options).evaluate(inputs), for the tests and tools that want a map.
std::vector<Lightmap> bakeEmbree(const BakeInputs& inputs, const EmbreeOptions& options = {});

// What one texel sample at (x, n) receives, as irradiance / π. For tests and tools.
struct PointShading {
  glm::vec3 direct{0.0f};        // punctual lights, exact
  glm::vec3 vpl{0.0f};           // clamped VPL sum
  glm::vec3 total() const { return direct + vpl; }
};
PointShading shadePointEmbree(const BakeInputs& inputs, const glm::vec3& x, const glm::vec3& n,
                              const EmbreeOptions& options = {});
// The same; the generator is not used (it seeded the recursive compensation this backend no longer has).
// Kept until sky_light_test.cpp calls the overload above.
PointShading shadePointEmbree(const BakeInputs& inputs, const glm::vec3& x, const glm::vec3& n, Rng& rng,
                              const EmbreeOptions& options = {});

}  // namespace irbake
