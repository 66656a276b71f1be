// The evaluators a bake runs, made in one place: the pipeline wires them together (it hands the GL
// evaluator the Embree one for its contact texels), so that no evaluator makes or includes another.
#pragma once
#include <memory>

#include "evaluators/evaluator.h"
#include "evaluators/gl/gl_backend.h"
#include "evaluators/reference/reference_integrator.h"
#include "pipeline/backend_choice.h"

namespace irbake {

// What the evaluators are made with; each kind reads its own field.
struct EvaluatorSettings {
  GlBackendOptions gl;         // the GL evaluator's options (its context and where its figures go included)
  ReferenceOptions reference;  // the reference evaluator's paths per sample and seed
};

// The evaluator of `kind` (gl, embree or reference; auto must be resolved first: Error(Usage)). contacts:
// where the GL evaluator sends its contact texels (null: they stay as rendered); it must outlive the result.
std::unique_ptr<Evaluator> makeEvaluator(BackendKind kind, const EvaluatorSettings& settings = {},
                                         const Evaluator* contacts = nullptr);

}  // namespace irbake
