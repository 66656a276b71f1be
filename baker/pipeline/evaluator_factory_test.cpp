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

TEST(EvaluatorFactory, EachEvaluatorDescribesItselfInTheReport) {
  EvaluatorSettings settings;
  settings.reference.spp = 12;
  nlohmann::json report = {{"eval", {{"clampBound", 0.0}}}};
  makeEvaluator(BackendKind::Reference, settings)->describe(report);
  EXPECT_EQ(report.at("reference").at("spp"), 12);
  EXPECT_EQ(report.at("eval").at("referenceSpp"), 12);
  EXPECT_EQ(report.at("eval").at("clampBound"), 0.0);  // added to, not replaced

  nlohmann::json embreeReport = nlohmann::json::object();
  const auto embree = makeEvaluator(BackendKind::Embree, settings);
  embree->describe(embreeReport);
  EXPECT_TRUE(embreeReport.empty());
  EXPECT_TRUE(embree->counts().empty());

  nlohmann::json glReport = nlohmann::json::object();
  const auto gl = makeEvaluator(BackendKind::Gl, settings);  // no devices: no context until it evaluates
  gl->describe(glReport);
  EXPECT_TRUE(glReport.contains("renderer"));
  EXPECT_EQ(glReport.at("gl").at("passes"), 0);
  EXPECT_TRUE(glReport.at("timings").contains("gl"));
  gl->addCounts({{"passes", 3}, {"texelsEvaluated", 7}});  // a shard's counts, as a merge adds them
  EXPECT_EQ(gl->counts().at("passes"), 3);
  EXPECT_EQ(gl->counts().at("texelsEvaluated"), 7);
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
