// Hand-built scenes and texel-sample grids for the light-transport tests and benchmarks, with the closed
// forms they are checked against. A quad is two triangles (or div² cells), a box six quads.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"

namespace irbake::testing {

// A material named "m<index>" with the given albedo and emission; returns its index.
int addMaterial(Scene& s, glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f));

// Quad p0, p0+e1, p0+e1+e2, p0+e2 split into `div`×`div` cells; front face normal = normalize(e1 × e2).
int addQuad(Scene& s, int material, glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int div = 1);

// Axis-aligned box from six quads; inward = true for a room (normals point inside).
void addBox(Scene& s, int material, glm::vec3 lo, glm::vec3 hi, bool inward, int div = 1);

Light pointLight(glm::vec3 position, float intensity);

// A directional light shining along `direction` (normalized here) with irradiance `intensity` (W/m²).
Light directionalLight(glm::vec3 direction, float intensity);

// A W×H grid of texel samples (supersample 1) over the rectangle p0 + [0,1]e1 + [0,1]e2, texel centres,
// all valid, normal = normalize(e1 × e2). Texel (x, y) sits at p0 + (x+0.5)/W e1 + (y+0.5)/H e2.
// The samples name no triangle (primitive UINT32_MAX), so backends use the positions as given.
TexelSamples gridSamples(glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int W, int H, uint32_t primitive = UINT32_MAX);

// The irradiance vector g/π of a Lambertian polygon of radiance 1 seen from x (Lambert: ½ Σ edge angle ·
// unit edge-plane normal, / π), oriented towards the polygon. n·(this) = polygonFormFactor(x, n, poly).
glm::dvec3 polygonIrradianceVector(glm::dvec3 x, const std::vector<glm::dvec3>& poly);

// Illuminance of that polygon at (x, n), divided by π: the point-to-polygon form factor (Lambert's edge
// formula). The polygon must lie entirely above x's tangent plane.
double polygonFormFactor(glm::dvec3 x, glm::dvec3 n, const std::vector<glm::dvec3>& poly);

// A floor point d from a long wall of height h sees (1 + d/√(d² + h²))/2 of a uniform sky, cosine-weighted
// (view factor from a strip element to a parallel infinite strip, Hottel's crossed strings).
double skyFractionBesideWall(double d, double h);

// Relative errors value/exact − 1 over a set of texels: their RMS and mean.
struct RelativeErrors {
  double squares = 0.0, sum = 0.0;
  size_t count = 0;
  void add(double value, double exact) {
    const double e = value / exact - 1.0;
    squares += e * e;
    sum += e;
    ++count;
  }
  double rms() const { return count ? std::sqrt(squares / count) : 0.0; }
  double mean() const { return count ? sum / count : 0.0; }
};

// A floor beside a wall traced with independent lattice rotations (errors[0]) and interleaved ones (errors[1])
// at 4 rays and a 5×5 filter: prints the figure; the interleaved RMS error must be below 0.7 of the independent
// one, and both means within 0.3% (interleaving stratifies each window without biasing any texel).
void expectInterleavingBeatsIndependent(const RelativeErrors errors[2]);

// A scene with its light-map atlas (pages of pageSize² texels), the ray tracer and the pages' samples.
struct AtlasedScene {
  Scene scene;
  std::unique_ptr<RayTracer> rayTracer;
  std::vector<TexelSamples> pages;
  AtlasedScene(Scene s, int pageSize);
};

// Of the part of texel t's square on its primitive's triangles where visible(p), the share where lit(p), from a
// 64×64 grid of points (closed-form predicates, no rays); -1 where no point is in that part.
double exactLitShare(const Scene& s, const TexelSamples& ts, size_t t, const std::function<bool(glm::vec3)>& lit,
                     const std::function<bool(glm::vec3)>& visible = [](glm::vec3) { return true; });

}  // namespace irbake::testing
