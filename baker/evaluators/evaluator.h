// One interface for the evaluators of BakeInputs (gl, embree, reference): peers that never call each other.
// Whoever builds them wires them together (the pipeline hands the GL evaluator the Embree one for its
// contact texels).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator_options.h"
#include "lightmap/lightmap.h"

namespace irbake {

// The optional parts of one evaluation; the defaults ask for the plain map of every texel.
struct EvaluationRequest {
  // Per page, per texel: evaluate only texels marked ≠ 0, the rest come back invalid and 0 (null: every texel).
  const std::vector<std::vector<uint8_t>>* texelSubset = nullptr;
  // Out: the L1 pages of the same sources (transport/directional.h), valid as the maps (null: none made).
  L1Pages* directional = nullptr;
};

// A choice an evaluator settles for itself; the bake's plan records it under `key` with its reason.
struct EvaluatorChoice {
  std::string key;
  nlohmann::json value;
  std::string reason;
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

  // What its options leave automatic, settled once before its first evaluation from inputs like the ones it
  // will get (the bake hands the first interleave class's pages, every VPL, the clamp settled). Returns the
  // choices made, for the plan. Default: none.
  virtual std::vector<EvaluatorChoice> settle(const BakeInputs& inputs) {
    (void)inputs;
    return {};
  }
  // Its own objects in the bake's report (its wall-clock figures under report["timings"]). Default: none.
  virtual void describe(nlohmann::json& report) const { (void)report; }
  // Its counts over the evaluations so far (the same every run), for a shard to carry to the merge, and a
  // shard's counts added to its own. Default: none.
  virtual nlohmann::json counts() const { return nlohmann::json::object(); }
  virtual void addCounts(const nlohmann::json& counts) { (void)counts; }
};

}  // namespace irbake
