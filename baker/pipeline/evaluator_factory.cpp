#include "pipeline/evaluator_factory.h"

#include "common/error.h"
#include "evaluators/embree/embree_backend.h"

namespace irbake {

std::unique_ptr<Evaluator> makeEvaluator(BackendKind kind, const EvaluatorSettings& settings,
                                         const Evaluator* contacts) {
  switch (kind) {
    case BackendKind::Gl: return std::make_unique<GlEvaluator>(settings.gl, contacts);
    case BackendKind::Embree: return std::make_unique<EmbreeEvaluator>();
    case BackendKind::Reference: return std::make_unique<ReferenceEvaluator>(settings.reference);
    case BackendKind::Auto: break;
  }
  throw Error(ErrorCode::Usage, "", "backend auto has no evaluator of its own: choose gl, embree or reference first");
}

}  // namespace irbake
