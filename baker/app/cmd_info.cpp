// irbake info SCENE: what the loader made of a glTF (counts, lights with power, emitters, bounds,
// cameras). Works on geometry-only scenes too: lights are only required by `bake`.
#include <cmath>
#include <cstdio>
#include <string>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "common/progress.h"
#include "lights/light_kind.h"
#include "scene/gltf_loader.h"

namespace irbake::app {

namespace {

void printVec(const char* label, const glm::vec3& v) { std::printf("%s(%.6g, %.6g, %.6g)", label, v.x, v.y, v.z); }

}  // namespace

int runInfo(const Args& args) {
  std::vector<std::string> scenes;
  bool noImages = false;
  auto app = cli::makeApp("irbake info",
                              "Prints triangles (kept/dropped), materials, textures, lights with power, emitters,\n"
                              "bounding box and cameras of a glTF/GLB scene.");
  app->add_option("SCENE", scenes, "the glTF/GLB scene");
  app->add_flag("--no-images", noImages, "do not decode textures (faster)");
  if (!cli::parse(*app, args)) return 0;
  if (scenes.size() != 1) throw Error(ErrorCode::Usage, "", "info takes exactly one SCENE argument");
  const std::string file = scenes[0];
  LoadOptions options;
  options.decodeImages = !noImages;
  Stopwatch clock;
  Scene scene = loadScene(file, options);
  const double seconds = clock.seconds();

  std::printf("scene: %s\n", file.c_str());
  std::printf("load time: %.3f s\n", seconds);
  std::printf("primitives: %zu\n", scene.primitives.size());
  size_t vertices = 0;
  for (const auto& p : scene.primitives) vertices += p.positions.size();
  std::printf("vertices: %zu\n", vertices);
  std::printf("triangles: %zu kept, %zu dropped (degenerate)\n", scene.stats.trianglesKept, scene.stats.trianglesDropped);
  if (scene.stats.primitivesSkipped) std::printf("skipped primitives (points/lines): %zu\n", scene.stats.primitivesSkipped);
  if (scene.stats.normalsComputed) std::printf("primitives with computed normals: %zu\n", scene.stats.normalsComputed);
  std::printf("materials: %zu\n", scene.materials.size());
  for (const auto& m : scene.materials) {
    std::printf("  %s: baseColor (%.4g, %.4g, %.4g, %.4g)%s", m.name.c_str(), m.baseColorFactor.r, m.baseColorFactor.g,
                m.baseColorFactor.b, m.baseColorFactor.a, m.baseColorTexture >= 0 ? " × texture" : "");
    if (m.isEmissive()) printVec(", emission ", m.emission());
    // Material::lightmapIntensity is irbake's internal scale (irradiance/π); the user reads the specification's.
    if (m.lightmapTexture >= 0)
      std::printf(", MOZ_lightmap texture %d, irradiance = decoded × %.4g lux", m.lightmapTexture,
                  M_PI * m.lightmapIntensity);
    if (m.doubleSided) std::printf(", double-sided");
    std::printf("\n");
  }
  std::printf("textures: %zu\n", scene.textures.size());
  for (const auto& t : scene.textures) std::printf("  %s: %dx%d\n", t.name.c_str(), t.width, t.height);
  std::printf("lights: %zu\n", scene.lights.size());
  for (const auto& l : scene.lights) {
    const LightKind& kind = lightKind(l.type);
    std::printf("  %s %s: intensity %.6g × colour (%.4g, %.4g, %.4g)", kind.name(), l.name.c_str(), l.intensity,
                l.color.r, l.color.g, l.color.b);
    if (!kind.atInfinity()) printVec(", at ", l.position);
    if (kind.aimed()) printVec(", towards ", l.direction);
    if (kind.atInfinity()) std::printf(", irradiance %.6g W/m²\n", l.intensity);
    else printVec(", power W ", kind.power(l)), std::printf("\n");
  }
  size_t emitters = 0;
  for (const auto& p : scene.primitives)
    if (scene.materials[p.material].isEmissive()) ++emitters;
  std::printf("emissive primitives: %zu", emitters);
  if (emitters) printVec(", total power W ", scene.emitterPower());
  std::printf("\n");
  Bounds3 b = scene.bounds();
  printVec("bounds: min ", b.min);
  printVec(" max ", b.max);
  std::printf(" (diagonal %.6g m)\n", b.diagonal());
  std::printf("cameras: %zu\n", scene.cameras.size());
  for (const auto& c : scene.cameras) {
    glm::vec3 pos(c.cameraToWorld[3]);
    glm::vec3 fwd = -glm::vec3(c.cameraToWorld[2]);
    std::printf("  %s: ", c.name.c_str());
    printVec("at ", pos);
    printVec(" looking ", fwd);
    std::printf(", yfov %.4g°\n", c.yfov * 180.0 / M_PI);
  }
  if (!scene.lightmapExrPaths.empty()) std::printf("lightmap pages: %zu\n", scene.lightmapExrPaths.size());
  if (!scene.hasLightOrEmitter()) std::printf("note: no light and no emitter (bake will need --sun)\n");
  if (!scene.stats.warnings.empty()) std::printf("warnings: %zu\n", scene.stats.warnings.size());
  return 0;
}

}  // namespace irbake::app
