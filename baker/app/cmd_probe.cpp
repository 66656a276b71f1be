// irbake probe OUT.gltf --at X,Y,Z [--normal NX,NY,NZ]: the baked irradiance probes (IRBAKE_light_probes) read
// at a point as JSON: E(n)/π per channel with --normal (the sun level's sun as an exact clamped cosine, the rest
// through L2: shadeProbeLambert), else the mean over every normal (the L0 term, which the exact sun leaves as it
// is: the clamped cosine's mean, 1/4, is its L0 part), the exact emitters (`emitters`) added at their blended
// visibility. Trilinear
// over the 8 probes around the point, valid ones only, and only those the point sees (the glTF's geometry is
// loaded for the visibility rays), so light never comes through a wall.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "export/light_probes_export.h"
#include "lightmap/probe_emitter_field.h"
#include "raytrace/ray_tracer.h"
#include "scene/gltf_loader.h"
#include "scene/scene_limits.h"

namespace irbake::app {

int runProbe(const Args& args) {
  std::vector<std::string> files;
  std::string at, normal;
  auto app = cli::makeApp("irbake probe", "Prints the irradiance/π the baked probes give at a point, as JSON.");
  app->add_option("GLTF", files, "a glTF/GLB that irbake bake wrote with probes");
  app->add_option("--at", at, "the point (metres, world space)")->transform(cli::numberList(3))->type_name("X,Y,Z");
  app->add_option("--normal", normal, "the surface normal to shade (default: the mean over every normal)")
      ->transform(cli::numberList(3))->type_name("NX,NY,NZ");
  if (!cli::parse(*app, args)) return 0;
  if (files.size() != 1) throw Error(ErrorCode::Usage, "", "probe takes exactly one glTF/GLB");
  if (at.empty()) throw Error(ErrorCode::Usage, "", "probe needs --at X,Y,Z");
  const std::string file = files[0];
  const std::vector<double> p = cli::parseNumberList(at);
  // In double, before float: the visibility rays start at the point, and Embree aborts on origins beyond 1.8e18 m.
  for (double c : p)
    if (!(std::abs(c) <= kMaxSceneCoordinate))
      throw Error(ErrorCode::Usage, "", "--at needs coordinates within the supported ±1e9 m (got '" + at + "')");
  const glm::vec3 point(p[0], p[1], p[2]);
  glm::vec3 n(0.0f);
  if (!normal.empty()) {
    const std::vector<double> v = cli::parseNumberList(normal);
    const glm::dvec3 d(v[0], v[1], v[2]);
    const double longest = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    if (!(longest > 0.0)) throw Error(ErrorCode::Usage, "", "--normal needs a non-zero direction (got '" + normal + "')");
    n = glm::vec3(glm::normalize(d / longest));
  }
  const LightProbeGrid grid = readLightProbes(file);
  LoadOptions load;
  load.decodeImages = false;
  const Scene scene = loadScene(file, load);
  const RayTracer rt(scene);
  const ProbeBlend blend = interpolateProbes(grid, point, [&](const glm::vec3& from, const glm::vec3& to) {
    const glm::vec3 d = to - from;
    const float r = glm::length(d);
    return !(r > 0.0f) || !rt.occluded(from, d / r, 0.0f, r);
  });
  if (blend.probes == 0)
    throw Error(ErrorCode::InvalidData, file, "no valid probe around " + at + " is visible from it");
  glm::vec3 value =
      normal.empty() ? shAverage(blend.coefficients) : shadeProbeLambert(blend.coefficients, blend.sunVisibility, grid.sun, n, false);
  // Plus the exact emitters (docs/export.md, `emitters`) at their blended visibility.
  const std::vector<float> v = blendEmitterVisibility(grid, blend);
  if (!normal.empty()) value += exactEmitterLight(grid.emitters, v, point, n);
  else value += exactEmitterMean(grid.emitters, v, point);
  nlohmann::json out = {{"file", file},
                        {"at", {point.x, point.y, point.z}},
                        {"value", {value.x, value.y, value.z}},
                        {"probes", blend.probes},
                        {"weight", blend.weight},
                        {"emitters", grid.emitters.size()}};
  if (grid.sun.present()) out["sunVisibility"] = blend.sunVisibility;
  if (!normal.empty()) out["normal"] = {n.x, n.y, n.z};
  else out["normal"] = nullptr;
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

}  // namespace irbake::app
