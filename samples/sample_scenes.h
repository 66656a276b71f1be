// Sample scenes built in memory (and written as glTF by `irbake samples OUTDIR`). Each states its
// exact answer where one exists. Conventions (docs/units.md): metres, +Y up, map value = E/π
// (irradiance over π, W/m²/sr), point/spot intensity in W/sr, emission as radiance W/(m² sr).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace irbake::samples {

// The Cornell box from the Cornell Program of Computer Graphics measurements (mm → m): floor
// 552.8 × 559.2 mm, ceiling at 548.8 mm, short and tall blocks, the 130 × 105 mm ceiling light as
// an emissive quad 0.5 mm below the ceiling facing down (Le = (17, 12, 4) W/(m² sr) RGB; power
// π·Le·A = (0.729, 0.515, 0.172) W), camera at (278, 273, −800) mm looking +Z with yfov =
// 2·atan(12.5/35) ≈ 39.31°. Albedos: white (0.725, 0.71, 0.68), red (0.63, 0.065, 0.05), green
// (0.14, 0.45, 0.091). No closed form: scored against the reference integrator.
Scene makeCornellBox();

// Closed 2 m cube, normals inward, albedo rho and emission Le on all six walls.
// Exact everywhere (all bounces): map = Le / (1 − rho).
Scene makeFurnace(float rho = 0.5f, float Le = 1.0f);

// 10 × 10 m plane at y = 0 facing +Y (albedo 0.5), point light I = 10 W/sr at (0, 1, 0).
// Exact (no bounce: nothing faces the plane): map(x, z) = I·cosθ / (π r²) = I·h / (π r³), h = 1.
Scene makePointOverPlane();

// Emissive 1 × 1 m square (Le = 1, albedo 0) centred at (0, 1, 0) facing down; 4 × 4 m receiver
// at y = 0 facing up (albedo 0.5). Exact: map = Le · F(point → parallel rectangle),
// see parallelRectangleIrradianceOverPi().
Scene makeQuadOverPlane();

// Floor (y = 0, x,z ∈ [0,3]) and a wall (x = 0, facing +X), both 3 × 3 m with albedo `albedo`,
// lit by a spot light at (2, 2, 1.5) aimed at (0.5, 0, 1.5) (intensity W/sr, cones 30°/50°).
// Direct light exact (I·cosθ/(π r²) with the spot falloff); bounces: reference integrator.
Scene makeCorner(float albedo = 0.7f, float spotIntensity = 20.0f);

// Closed box x ∈ [−2, 2], y ∈ [0, 2], z ∈ [−1, 1] (normals inward, albedo 0.5) split at x = 0 by a
// zero-thickness partition: two coincident quads facing −X and +X. Point light I = 10 W/sr at
// (−1, 1, 0). Exact: the room x > 0 receives nothing (map < 1e-3 of the lit side in any bake).
Scene makeThinWall();

// 4 × 4 m plane at y = 0 facing +Y with TEXCOORD_0 over [0,1]² and a 64 × 64 checker
// baseColorTexture of 8 × 8 checks, linear albedo 0.8 and 0.2 (check (0,0) at the top-left is 0.8),
// point light I = 10 W/sr at (0, 1, 0). Exact map as makePointOverPlane (the map is irradiance,
// independent of albedo); albedo at a point = checker value.
Scene makeTexturedPlane();

// Contacts that a shadow map cannot resolve, from exact dimensions (metres, +Y up): a closed room
// x ∈ [0, 4], y ∈ [0, 2.5], z ∈ [0, 3] (normals inward; floor 0.5, walls and ceiling 0.7); a cupboard
// x ∈ [1.5, 2.5], y ∈ [0, 2], z ∈ [0.001, 0.601] standing on the floor 1 mm in front of the back wall
// z = 0; a 0.5 m cube resting on the floor at x ∈ [0.6, 1.1], z ∈ [1.6, 2.1]
// (bottom face on the floor plane); a 0.5 × 0.5 m emissive quad (Le = 8 W/(m² sr)) 0.1 mm under the
// ceiling, centred at (2, ·, 1.8), facing down. No closed form: the GL backend must match the Embree
// backend (ray-traced visibility) on the same VPLs, and both the reference integrator.
Scene makeContacts();

// Map value (E/π) at point p on the plane y = 0 (normal +Y) under a Lambertian rectangle of
// radiance Le parallel to it at height h > 0, spanning [x0,x1] × [z0,z1] and facing down:
// Le × the point-to-rectangle form factor (sum of four corner-aligned closed forms).
double parallelRectangleIrradianceOverPi(double px, double pz, double x0, double x1, double z0, double z1, double h, double Le);

struct NamedSample {
  std::string name;  // file stem, e.g. "cornell_box"
  Scene scene;
};
// Every sample with default parameters (furnace: rho 0.5, Le 1).
std::vector<NamedSample> allSamples();

// Writes <outDir>/<name>.gltf (+ .bin) for every sample; returns the written glTF paths.
std::vector<std::filesystem::path> writeSamples(const std::filesystem::path& outDir);

}  // namespace irbake::samples
