// The baked irradiance probes (IRBAKE_light_probes, docs/export.md) in irview: matte white spheres lit by the
// probes (--probe-object X,Y,Z[,R]: the probes' SH blended at the centre with its gradient over the sphere,
// lightmap/probe_field.h, as a dynamic object would be),
// and the grid itself (--view probes: a small sphere at each probe, lit by its own SH, invalid ones red).
// A sphere of albedo 1 (Lambert) shows radiance = E(n)/π = shIrradiance(c(p), n) at the point p with normal n,
// c(p) = coefficients + (p − centre)·gradient, clamped at 0 (L2 ringing), plus the exact emitters' E/π
// (lightmap/probe_emitter_field.h, shaders/probe_emitters.glsl); with a sun level, its sun is taken out of c(p) and
// shaded as an exact clamped cosine at the visibility v(p) (shadeProbeLambert); each pixel's normal is exact: the
// sphere is ray-cast in the fragment shader, not tessellated.
#pragma once
#include <filesystem>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "lightmap/probe_emitter_field.h"
#include "lightmap/probe_field.h"
#include "lightmap/probe_grid.h"

namespace irbake {
class GlProgram;
}

namespace irbake::view {

class ViewRenderer;
struct ViewerOptions;

struct ProbeSphere {
  glm::vec3 centre{0.0f};
  float radius = 0.1f;
  ShCoefficients coefficients{};  // at the centre: E(n)/π = shIrradiance(coefficients, n)
  std::array<ShCoefficients, 3> gradient{};  // ∂coefficients/∂x, y, z (zero for the grid's own probes)
  bool valid = true;              // false: drawn in flat red (a probe left out of interpolation)
  float sunVisibility = 0.0f;     // the sun level's visibility at the centre and its gradient (probe_field.h)
  glm::vec3 sunGradient{0.0f};
  // The exact emitters (lightmap/probe_emitters.h; shared by every sphere of a grid) and their visibility at the
  // centre with its gradient: their light E/π is added at each point, unclamped L2 term clamped first.
  std::shared_ptr<const std::vector<ProbeEmitter>> emitters;
  EmitterVisibilityField emitterVisibility;
};

// The sun level's light as the spheres' shader takes it (zero irradiance and SH: no sun level).
struct ProbeSphereSun {
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // travel
  glm::vec3 irradiance{0.0f};              // E/π facing it at visibility 1
  ShCoefficients sh{};                     // its SH at visibility 1
};

// The probes over a dynamic object: trilinear over the 8 around its centre, valid ones only, weights renormalised
// (interpolateProbes), and their gradient over its radius (probeFieldOver). irview has no ray tracer, so every probe counts as visible from the point, unlike `irbake
// probe`, which drops the probes a wall hides; the two agree wherever the point sees its 8 probes. Throws
// Error(InvalidData, file) when no valid probe is near.
ProbeSphere probeObject(const LightProbeGrid& grid, const glm::vec3& centre, float radius,
                        const std::filesystem::path& file);

// One sphere per probe at its baked position (grid point + offset), radius 0.12 × spacing.
std::vector<ProbeSphere> probeGridSpheres(const LightProbeGrid& grid);

// The spheres the options ask for (--probe-object, --view probes), with the grid read from the scene file
// (readLightProbes: throws Error naming the file and the problem for a missing or malformed extension). Empty
// when neither is asked for; the file is then not read for probes.
// `sun`, when given, receives the grid's sun level.
std::vector<ProbeSphere> probeSpheresFor(const ViewerOptions& options, ProbeSphereSun* sun = nullptr);

// The shader's sun of a grid's sun level.
ProbeSphereSun probeSphereSun(const LightProbeGrid& grid);

// The exact emitters' triangles the spheres carry (every sphere's are the same grid's), at most
// kMaxExactEmitterTriangles: the EMITTER_TRIANGLES of a program that shades them (shaders/probe_emitters.glsl).
int emitterTriangles(const std::vector<ProbeSphere>& spheres);
// Sphere `s`'s exact emitters as that program's per-triangle uniforms (the bound program `p`).
void setEmitterUniforms(const GlProgram& p, const ProbeSphere& s, int triangles);

// Draws `spheres` after the scene in every frame of `renderer` (ViewRenderer::addOverlay), their sun level `sun`;
// GL context current.
void addProbeOverlay(ViewRenderer& renderer, std::vector<ProbeSphere> spheres, const ProbeSphereSun& sun = {});

}  // namespace irbake::view
