#include "pipeline/evaluator_factory.h"

#include <string>

#include "common/error.h"
#include "common/log.h"
#include "evaluators/embree/embree_backend.h"
#include "evaluators/gl/gl_backend.h"
#include "evaluators/reference/reference_integrator.h"
#include "glcontext/gl_context.h"

namespace irbake {
namespace {

// The GL evaluator as a bake runs it: it owns its context (null: one made per call) and its contact evaluator.
class OwningGlEvaluator final : public Evaluator {
 public:
  OwningGlEvaluator(GlBackendOptions options, std::unique_ptr<GlContext> context)
      : context_(std::move(context)), contacts_(std::make_unique<EmbreeEvaluator>()),
        gl_(withContext(std::move(options), context_.get()), contacts_.get()) {
    if (context_) log::info("GL backend: " + context_->description());
  }
  std::vector<Lightmap> evaluate(const BakeInputs& inputs, const EvaluationRequest& request) const override {
    return gl_.evaluate(inputs, request);
  }
  const char* name() const override { return gl_.name(); }
  nlohmann::json stats() const override { return gl_.stats(); }
  std::vector<EvaluatorChoice> settle(const BakeInputs& inputs) override {
    // On a CPU rasteriser the shadow pass costs every triangle once per VPL cube face (docs/validation.md).
    if (context_ && context_->softwareRenderer() && inputs.scene.triangleCount() > kGlTriangleHint &&
        inputs.eval.includeVpls)
      log::warn("GL backend on a software renderer with " + std::to_string(inputs.scene.triangleCount()) +
                " triangles: its shadow pass draws them for every VPL cube (on the 2-core bench machine the Embree "
                "backend baked a 58k-triangle room 4-17x faster); consider --backend embree");
    return gl_.settle(inputs);
  }
  void describe(nlohmann::json& report) const override { gl_.describe(report); }
  nlohmann::json counts() const override { return gl_.counts(); }
  void addCounts(const nlohmann::json& counts) override { gl_.addCounts(counts); }

 private:
  static GlBackendOptions withContext(GlBackendOptions options, const GlContext* context) {
    options.context = context;
    return options;
  }
  std::unique_ptr<GlContext> context_;
  std::unique_ptr<Evaluator> contacts_;
  GlEvaluator gl_;
};

}  // namespace

EvaluatorDevices::EvaluatorDevices() = default;
EvaluatorDevices::~EvaluatorDevices() = default;

GlProbe EvaluatorDevices::probeGl() {
  GlProbe probe;
  try {
    if (!gl_) gl_ = std::make_unique<GlContext>();
    probe.softwareRenderer = gl_->softwareRenderer();
  } catch (const Error& e) {
    probe.error = e.what();
  }
  return probe;
}

void EvaluatorDevices::release() { gl_.reset(); }

std::unique_ptr<Evaluator> makeEvaluator(BackendKind kind, const EvaluatorSettings& settings,
                                         EvaluatorDevices* devices) {
  switch (kind) {
    case BackendKind::Gl:
      if (devices && !devices->gl_) devices->gl_ = std::make_unique<GlContext>();
      return std::make_unique<OwningGlEvaluator>(settings.gl, devices ? std::move(devices->gl_) : nullptr);
    case BackendKind::Embree: return std::make_unique<EmbreeEvaluator>();
    case BackendKind::Reference: return std::make_unique<ReferenceEvaluator>(settings.reference);
    case BackendKind::Auto: break;
  }
  throw Error(ErrorCode::Usage, "", "backend auto has no evaluator of its own: choose gl, embree or reference first");
}

}  // namespace irbake
