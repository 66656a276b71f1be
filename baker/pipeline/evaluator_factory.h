// The evaluators a bake runs, made in one place: this factory is the one part of the pipeline that knows the
// implementations. It wires them together (the GL evaluator gets its context and the Embree evaluator for its
// contact texels), so that no evaluator makes or includes another and the rest of the pipeline sees only the
// interface (evaluators/evaluator.h).
#pragma once
#include <memory>

#include "evaluators/evaluator.h"
#include "pipeline/backend_choice.h"

namespace irbake {

// What the evaluators are made with; each kind reads its own field.
struct EvaluatorSettings {
  GlBackendOptions gl;         // the GL evaluator's options
  ReferenceOptions reference;  // the reference evaluator's paths per sample and seed
};

// What the evaluators need of the machine, found once per bake: the GL context, made by the first probe (the
// automatic backend choice) or by makeEvaluator, and handed to the GL evaluator made with it. The callers count
// the time (the first call makes the context).
class EvaluatorDevices {
 public:
  EvaluatorDevices();
  ~EvaluatorDevices();
  EvaluatorDevices(const EvaluatorDevices&) = delete;
  EvaluatorDevices& operator=(const EvaluatorDevices&) = delete;

  // Whether GL runs here and on what kind of renderer; the error when no context can be made.
  GlProbe probeGl();
  // The context let go (another evaluator was chosen).
  void release();

 private:
  friend std::unique_ptr<Evaluator> makeEvaluator(BackendKind, const EvaluatorSettings&, EvaluatorDevices*);
  std::unique_ptr<GlContext> gl_;
};

// The evaluator of `kind` (gl, embree or reference; auto must be resolved first: Error(Usage)), with what it
// needs wired: the GL evaluator takes the context of `devices` (made now if none was: Error(Gl) when none can
// be; null devices: it makes one per call) and an Embree evaluator of its own for its contact texels.
std::unique_ptr<Evaluator> makeEvaluator(BackendKind kind, const EvaluatorSettings& settings = {},
                                         EvaluatorDevices* devices = nullptr);

}  // namespace irbake
