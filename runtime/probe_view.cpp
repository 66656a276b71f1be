#include "probe_view.h"

#include <cmath>
#include <string>

#include <epoxy/gl.h>

#include "common/error.h"
#include "export/light_probes_export.h"
#include "glcontext/gl_program.h"
#include "view_renderer.h"
#include "viewer_options.h"

namespace irbake::view {

ProbeSphere probeObject(const LightProbeGrid& grid, const glm::vec3& centre, float radius,
                        const std::filesystem::path& file) {
  // No visibility rays: irview does not link the ray tracer, so every probe is visible from the point.
  const ProbeField field = probeFieldOver(grid, centre, radius, [](const glm::vec3&, const glm::vec3&) { return true; });
  if (field.probes == 0)
    throw Error(ErrorCode::InvalidData, file.string(),
                "--probe-object at " + std::to_string(centre.x) + "," + std::to_string(centre.y) + "," +
                    std::to_string(centre.z) + ": no valid probe near it");
  ProbeSphere s;
  s.centre = centre;
  s.radius = radius;
  s.coefficients = field.centre;
  s.gradient = field.gradient;
  s.sunVisibility = field.sunVisibility;
  s.sunGradient = field.sunGradient;
  return s;
}

std::vector<ProbeSphere> probeGridSpheres(const LightProbeGrid& grid) {
  std::vector<ProbeSphere> spheres(grid.size());
  for (size_t i = 0; i < grid.size(); ++i) {
    spheres[i].centre = grid.position(i);
    spheres[i].radius = 0.12f * grid.spacing;
    spheres[i].coefficients = grid.coefficients[i];
    spheres[i].valid = grid.valid[i] != 0;
    if (grid.sun.present() && grid.sun.visibility.size() == grid.size()) spheres[i].sunVisibility = grid.sun.visibility[i];
  }
  return spheres;
}

ProbeSphereSun probeSphereSun(const LightProbeGrid& grid) {
  ProbeSphereSun s;
  if (!grid.sun.present()) return s;
  s.direction = grid.sun.direction;
  s.irradiance = grid.sun.irradiance;
  s.sh = grid.sun.sh;
  return s;
}

std::vector<ProbeSphere> probeSpheresFor(const ViewerOptions& o, ProbeSphereSun* sun) {
  if (o.probeObjects.empty() && !o.showProbes) return {};
  const LightProbeGrid grid = readLightProbes(o.scene);
  if (sun) *sun = probeSphereSun(grid);
  std::vector<ProbeSphere> spheres = o.showProbes ? probeGridSpheres(grid) : std::vector<ProbeSphere>{};
  for (const glm::vec4& object : o.probeObjects)
    spheres.push_back(probeObject(grid, glm::vec3(object), object.w, o.scene));
  return spheres;
}

namespace {

// The spheres' GL side: one program per output encoding, an empty vertex array, one draw per sphere.
class ProbeOverlay {
 public:
  ProbeOverlay(std::vector<ProbeSphere> spheres, const ProbeSphereSun& sun) : spheres_(std::move(spheres)), sun_(sun) {
    glGenVertexArrays(1, &vao_);
    program(0);  // compile now: shader errors surface before the first frame
  }
  ~ProbeOverlay() {
    if (vao_) glDeleteVertexArrays(1, &vao_);
  }
  ProbeOverlay(const ProbeOverlay&) = delete;
  ProbeOverlay& operator=(const ProbeOverlay&) = delete;

  void draw(const ViewCamera& camera, const glm::mat4& viewProjection, const DrawSettings& settings) {
    const GlProgram& p = program(settings.encodeSrgb ? 1 : 0);
    p.use();
    const glm::vec3 eye = camera.position();
    glUniformMatrix4fv(p.uniform("uViewProjection"), 1, GL_FALSE, &viewProjection[0][0]);
    glUniform3fv(p.uniform("uEye"), 1, &eye[0]);
    glUniform1f(p.uniform("uExposureScale"), std::exp2(settings.exposure));
    const GLint centre = p.uniform("uCentre"), radius = p.uniform("uRadius"), sh = p.uniform("uSh"),
                gradient = p.uniform("uShGradient"), valid = p.uniform("uValid"),
                sunVisibility = p.uniform("uSunVisibility"), sunGradient = p.uniform("uSunGradient");
    glUniform3fv(p.uniform("uSunDirection"), 1, &sun_.direction[0]);
    glUniform3fv(p.uniform("uSunIrradiance"), 1, &sun_.irradiance[0]);
    glUniform3fv(p.uniform("uSunSh"), kShCoefficients, &sun_.sh[0][0]);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);  // both sides of the box: the back faces still cover the sphere with the eye inside it
    glBindVertexArray(vao_);
    for (const ProbeSphere& s : spheres_) {
      glUniform3fv(centre, 1, &s.centre[0]);
      glUniform1f(radius, s.radius);
      glUniform3fv(sh, kShCoefficients, &s.coefficients[0][0]);
      glUniform3fv(gradient, 3 * kShCoefficients, &s.gradient[0][0][0]);
      glUniform1i(valid, s.valid ? 1 : 0);
      glUniform1f(sunVisibility, s.sunVisibility);
      glUniform3fv(sunGradient, 1, &s.sunGradient[0]);
      glDrawArrays(GL_TRIANGLES, 0, 36);
    }
    glBindVertexArray(0);
    glUseProgram(0);
  }

 private:
  const GlProgram& program(int output) {
    std::unique_ptr<GlProgram>& p = programs_[output];
    if (!p)
      p = std::make_unique<GlProgram>(
          std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"view_probe.vert"}},
                                   {GL_FRAGMENT_SHADER, {"view_encode.glsl", "view_probe.frag"}}},
          std::vector<std::string>{"#define OUTPUT " + std::to_string(output)}, "330 core");
    return *p;
  }

  std::vector<ProbeSphere> spheres_;
  ProbeSphereSun sun_;
  std::unique_ptr<GlProgram> programs_[2];
  GLuint vao_ = 0;
};

}  // namespace

void addProbeOverlay(ViewRenderer& renderer, std::vector<ProbeSphere> spheres, const ProbeSphereSun& sun) {
  if (spheres.empty()) return;
  auto overlay = std::make_shared<ProbeOverlay>(std::move(spheres), sun);
  renderer.addOverlay([overlay](const ViewCamera& camera, const glm::mat4& viewProjection, const DrawSettings& settings) {
    overlay->draw(camera, viewProjection, settings);
  });
}

}  // namespace irbake::view
