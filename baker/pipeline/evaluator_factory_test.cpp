// The factory makes each evaluator behind the interface, with the settings of its kind.
#include "pipeline/evaluator_factory.h"

#include <gtest/gtest.h>

#include "common/error.h"

namespace irbake {
namespace {

TEST(EvaluatorFactory, MakesEachKindWithItsSettings) {
  EvaluatorSettings settings;
  settings.reference.spp = 12;
  const auto embree = makeEvaluator(BackendKind::Embree, settings);
  const auto gl = makeEvaluator(BackendKind::Gl, settings);  // no devices: no context until it evaluates
  const auto reference = makeEvaluator(BackendKind::Reference, settings);
  EXPECT_STREQ(embree->name(), "embree");
  EXPECT_STREQ(gl->name(), "gl");
  EXPECT_STREQ(reference->name(), "reference");
  EXPECT_EQ(reference->stats().at("spp"), 12);
  EXPECT_EQ(gl->stats().at("counts").at("passes"), 0);  // nothing evaluated yet
}

TEST(EvaluatorFactory, AutoMustBeResolvedFirst) {
  try {
    makeEvaluator(BackendKind::Auto);
    FAIL() << "auto made an evaluator";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
  }
}

}  // namespace
}  // namespace irbake
