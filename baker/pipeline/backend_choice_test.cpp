// --backend auto's rule on both renderers (a hardware GPU is not in CI, so the rule is tested alone).
#include "pipeline/backend_choice.h"

#include <gtest/gtest.h>

namespace irbake {
namespace {

TEST(AutoBackend, SmallScenesGetGlOnEitherRenderer) {
  for (bool software : {false, true}) {
    int probes = 0;
    const AutoBackendChoice c = chooseAutoBackend(kGlTriangleHint, "", [&] {
      ++probes;
      return GlProbe{"", software};
    });
    EXPECT_EQ(c.backend, BackendKind::Gl);
    EXPECT_EQ(probes, 1);
    EXPECT_NE(c.reason.find(software ? "software" : "hardware"), std::string::npos) << c.reason;
  }
}

TEST(AutoBackend, LargeScenesGetEmbreeWithoutAContext) {
  // Sponza (66k triangles) on an H100: GL no faster than Embree and 0.4 GiB more memory; on llvmpipe 4-17x slower.
  int probes = 0;
  const AutoBackendChoice c = chooseAutoBackend(66445, "", [&] {
    ++probes;
    return GlProbe{"", false};
  });
  EXPECT_EQ(c.backend, BackendKind::Embree);
  EXPECT_EQ(probes, 0);
  EXPECT_NE(c.reason.find("66445 triangles"), std::string::npos) << c.reason;
}

TEST(AutoBackend, SeeThroughOrNoContextGetEmbree) {
  int probes = 0;
  const auto probe = [&] {
    ++probes;
    return GlProbe{"no EGL display", true};
  };
  const AutoBackendChoice glass = chooseAutoBackend(12, "material 'pane' is alpha BLEND (see-through)", probe);
  EXPECT_EQ(glass.backend, BackendKind::Embree);
  EXPECT_EQ(probes, 0);
  EXPECT_NE(glass.reason.find("BLEND"), std::string::npos);
  const AutoBackendChoice none = chooseAutoBackend(12, "", probe);
  EXPECT_EQ(none.backend, BackendKind::Embree);
  EXPECT_EQ(probes, 1);
  EXPECT_NE(none.reason.find("no EGL display"), std::string::npos);
}

}  // namespace
}  // namespace irbake
