// One interface for the evaluators of BakeInputs (gl, embree, reference): peers that never call each other.
// Whoever builds them wires them together (the pipeline hands the GL evaluator the Embree one for its
// contact texels).
#pragma once
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

// The optional parts of one evaluation; the defaults ask for the plain map of every texel.
struct EvaluationRequest {
  // Per page, per texel: evaluate only texels marked ≠ 0, the rest come back invalid and 0 (null: every texel).
  const std::vector<std::vector<uint8_t>>* texelSubset = nullptr;
  // Out: the L1 pages of the same sources (transport/directional.h), valid as the maps (null: none made).
  L1Pages* directional = nullptr;
};

class Evaluator {
 public:
  virtual ~Evaluator() = default;
  // One Lightmap per page of inputs.texels (irradiance / π; valid = the texel's valid flag).
  virtual std::vector<Lightmap> evaluate(const BakeInputs& inputs, const EvaluationRequest& request = {}) const = 0;
  // "gl", "embree" or "reference": the name the command line and the progress reports use.
  virtual const char* name() const = 0;
  // What the evaluator measured over its evaluations, as JSON (each implementation lists its fields).
  virtual nlohmann::json stats() const = 0;
};

}  // namespace irbake
