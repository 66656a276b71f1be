#include "pipeline/backend_choice.h"

#include "common/error.h"

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

BackendKind parseBackend(const std::string& name) {
  if (name == "auto") return BackendKind::Auto;
  if (name == "gl") return BackendKind::Gl;
  if (name == "embree") return BackendKind::Embree;
  if (name == "reference") return BackendKind::Reference;
  throw Error(ErrorCode::Usage, "", "unknown backend '" + name + "' (auto, gl, embree or reference)");
}

const char* toString(BackendKind kind) {
  switch (kind) {
    case BackendKind::Auto: return "auto";
    case BackendKind::Gl: return "gl";
    case BackendKind::Embree: return "embree";
    case BackendKind::Reference: return "reference";
  }
  return "?";
}

}  // namespace irbake
