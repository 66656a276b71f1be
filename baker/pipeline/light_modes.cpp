#include "pipeline/light_modes.h"

#include "common/error.h"

namespace irbake {

namespace {

bool names(const std::string& request, const Light& light) {
  if (request == lightModeName(light)) return true;
  return light.gltfLight >= 0 && request == "#" + std::to_string(light.gltfLight);
}

// A request that names no punctual light: something that stays baked (the sky, an emitter), or nothing.
[[noreturn]] void refuseName(const Scene& scene, const LightModeRequest& request) {
  const std::string what = "--light-mode " + request.light + "=" + toString(request.mode);
  if (request.light == "sky" || request.light == "env")
    throw Error(ErrorCode::Usage, scene.sourcePath, what + ": '" + request.light +
                                                         "' is not a punctual light (the sky and emitters stay baked)");
  for (const Primitive& p : scene.primitives) {
    const Material& m = scene.materials[static_cast<size_t>(p.material)];
    if ((p.name == request.light || m.name == request.light) && m.isEmissive())
      throw Error(ErrorCode::Usage, scene.sourcePath, what + ": '" + request.light +
                                                           "' is an emissive surface, not a punctual light (emitters stay baked)");
  }
  std::string known;
  for (const Light& l : scene.lights) known += (known.empty() ? "" : ", ") + lightModeName(l);
  throw Error(ErrorCode::Usage, scene.sourcePath,
              what + ": no punctual light is named '" + request.light + "' (" +
                  (known.empty() ? std::string("the scene has none") : "its punctual lights: " + known) + ")");
}

}  // namespace

std::string lightModeName(const Light& light) {
  if (light.node < 0 && light.gltfLight < 0 && light.name.rfind("sun (command line)", 0) == 0) return "sun";
  if (!light.name.empty()) return light.name;
  return "#" + std::to_string(light.gltfLight);
}

std::vector<RequestedLightMode> resolveLightModes(const Scene& scene, const std::vector<LightModeRequest>& requests) {
  std::vector<RequestedLightMode> modes(scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    modes[i].reason = "default";
    if (l.hasExtrasMode) modes[i] = {l.extrasMode, "extras.irbake.mode in the glTF", true};
  }
  // "*" first, then the named ones: a name wins over "*" whatever the order; within each, the last wins.
  for (const bool star : {true, false})
    for (const LightModeRequest& r : requests) {
      if ((r.light == "*") != star) continue;
      if (star && scene.lights.empty())
        throw Error(ErrorCode::Usage, scene.sourcePath, "--light-mode *=" + std::string(toString(r.mode)) +
                                                             ": the scene has no punctual light");
      bool matched = false;
      for (size_t i = 0; i < scene.lights.size(); ++i)
        if (star || names(r.light, scene.lights[i])) {
          modes[i] = {r.mode, "--light-mode " + r.light + "=" + toString(r.mode), true};
          matched = true;
        }
      if (!matched) refuseName(scene, r);
    }
  return modes;
}

}  // namespace irbake
