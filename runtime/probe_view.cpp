#include "probe_view.h"

#include <algorithm>
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
  if (!grid.emitters.empty()) {
    s.emitters = std::make_shared<const std::vector<ProbeEmitter>>(grid.emitters);
    s.emitterVisibility = field.emitters;
  }
  return s;
}

std::vector<ProbeSphere> probeGridSpheres(const LightProbeGrid& grid) {
  std::vector<ProbeSphere> spheres(grid.size());
  const auto emitters = grid.emitters.empty() ? nullptr : std::make_shared<const std::vector<ProbeEmitter>>(grid.emitters);
  for (size_t i = 0; i < grid.size(); ++i) {
    if (emitters) {  // each probe's own visibility, no gradient
      spheres[i].emitters = emitters;
      for (auto& g : spheres[i].emitterVisibility.gradient) g.assign(emitters->size(), 0.0f);
      for (const ProbeEmitter& e : *emitters) spheres[i].emitterVisibility.centre.push_back(e.visibility[i]);
    }
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

// The exact emitters' triangles (every sphere's are the same grid's), at most kMaxExactEmitterTriangles.
int emitterTriangles(const std::vector<ProbeSphere>& spheres) {
  size_t n = 0;
  for (const ProbeSphere& s : spheres)
    if (s.emitters) {
      for (const ProbeEmitter& e : *s.emitters) n += e.positions.size() / 3;
      break;
    }
  return static_cast<int>(std::min<size_t>(n, kMaxExactEmitterTriangles));
}

// Sphere `s`'s exact emitters as the shader's per-triangle uniforms (shaders/probe_emitters.glsl).
void setEmitterUniforms(const GlProgram& p, const ProbeSphere& s, int triangles) {
  if (triangles == 0 || !s.emitters) return;
  std::vector<glm::vec3> positions, radiance;
  std::vector<glm::vec4> visibility;
  for (size_t e = 0; e < s.emitters->size(); ++e) {
    const ProbeEmitter& em = (*s.emitters)[e];
    const auto& v = s.emitterVisibility;
    const glm::vec4 vis(e < v.centre.size() ? v.centre[e] : 0.0f, e < v.gradient[0].size() ? v.gradient[0][e] : 0.0f,
                        e < v.gradient[1].size() ? v.gradient[1][e] : 0.0f, e < v.gradient[2].size() ? v.gradient[2][e] : 0.0f);
    for (size_t t = 0; t + 2 < em.positions.size() && static_cast<int>(radiance.size()) < triangles; t += 3) {
      positions.insert(positions.end(), em.positions.begin() + t, em.positions.begin() + t + 3);
      radiance.push_back(em.radiance);
      visibility.push_back(vis);
    }
  }
  const GLsizei n = static_cast<GLsizei>(radiance.size());
  glUniform3fv(p.uniform("uEmitterPositions"), 3 * n, &positions[0][0]);
  glUniform3fv(p.uniform("uEmitterRadiance"), n, &radiance[0][0]);
  glUniform4fv(p.uniform("uEmitterVisibility"), n, &visibility[0][0]);
}

namespace {

// The spheres' GL side: one program per output encoding, an empty vertex array, one draw per sphere.
class ProbeOverlay {
 public:
  ProbeOverlay(std::vector<ProbeSphere> spheres, const ProbeSphereSun& sun)
      : spheres_(std::move(spheres)), sun_(sun), emitterTriangles_(emitterTriangles(spheres_)) {
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
      setEmitterUniforms(p, s, emitterTriangles_);
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
                                   {GL_FRAGMENT_SHADER, {"view_encode.glsl", "probe_emitters.glsl", "probe_sh.glsl", "view_probe.frag"}}},
          std::vector<std::string>{"#define OUTPUT " + std::to_string(output),
                                   "#define EMITTER_TRIANGLES " + std::to_string(emitterTriangles_)},
          "330 core");
    return *p;
  }

  std::vector<ProbeSphere> spheres_;
  ProbeSphereSun sun_;
  int emitterTriangles_ = 0;  // the shader's EMITTER_TRIANGLES (0: no exact emitters)
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
