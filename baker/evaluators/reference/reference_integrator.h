// The converged reference: path-traced irradiance / π per texel sample, with a standard error.
// Independent of the VPLs: cosine-hemisphere paths, next-event estimation on emissive triangles
// (multiple importance sampling with the hemisphere hits, power heuristic) and on punctual lights
// (exact, one shadow ray), Russian roulette, seeded per texel sample. The yardstick for every error figure.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator.h"
#include "lightmap/lightmap.h"
#include "vpl/light_sources.h"
#include "sampling/sampling.h"

namespace irbake {

// One Lightmap per TexelSamples page (inputs.vpls and inputs.eval are not used: the reference is the
// full solution). standardError (optional) receives per texel the standard error of the mean, same layout.
// request.texelSubset traces those texels only; it makes no L1 pages (request.directional: Error(Usage)).
std::vector<Lightmap> bakeReference(const BakeInputs& inputs, const ReferenceOptions& options,
                                    std::vector<Lightmap>* standardError = nullptr,
                                    const EvaluationRequest& request = {});

// bakeReference behind the evaluator interface. stats(): the last evaluation's {"spp", "relativeStandardError"}
// (the mean standard error over the mean value of its valid texels: how converged the yardstick is).
class ReferenceEvaluator final : public Evaluator {
 public:
  explicit ReferenceEvaluator(const ReferenceOptions& options) : options_(options) {}
  std::vector<Lightmap> evaluate(const BakeInputs& inputs, const EvaluationRequest& request = {}) const override;
  const char* name() const override { return "reference"; }
  nlohmann::json stats() const override;
  // report "reference" (stats()) and eval.referenceSpp.
  void describe(nlohmann::json& report) const override;

 private:
  ReferenceOptions options_;
  mutable double relativeStandardError_ = 0.0;  // of the last evaluation
};

// One path's estimate of irradiance / π at surface point (x, n); the mean over paths converges to it.
glm::vec3 referencePathSample(const Scene& scene, const RayTracer& rt, const LightSources& lights, const glm::vec3& x,
                              const glm::vec3& n, Rng& rng, const ReferenceOptions& options);

}  // namespace irbake
