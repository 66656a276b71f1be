#include "pipeline/backend_choice.h"

namespace irbake {

AutoBackendChoice chooseAutoBackend(size_t triangles, const std::string& seeThrough,
                                    const std::function<GlProbe()>& probeGl) {
  AutoBackendChoice c;
  const std::string count = std::to_string(triangles) + " triangles";
  const std::string hint = std::to_string(kGlTriangleHint);
  if (!seeThrough.empty()) {
    c.reason = seeThrough + ": the GL backend would trace most texels it shades anyway (red pane test: 64%)";
    return c;
  }
  if (triangles > kGlTriangleHint) {
    c.reason = count + " (> " + hint + "): Embree was as fast as GL or faster, on llvmpipe and on a GPU, and took " +
               "less memory (docs/validation.md)";
    return c;
  }
  const GlProbe gl = probeGl();
  if (!gl.error.empty()) {
    c.reason = "no GL context: " + gl.error;
    return c;
  }
  c.backend = BackendKind::Gl;
  c.reason = std::string(gl.softwareRenderer ? "software" : "hardware") + " GL renderer, " + count + " (≤ " + hint +
             ": GL as fast as Embree or faster)";
  return c;
}

}  // namespace irbake
