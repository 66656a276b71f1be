// Each punctual light's bake mode (mixed lighting): from --light-mode, the glTF light's extras.irbake.mode,
// or baked; checked before anything is traced so that a bad name costs nothing.
#pragma once
#include <string>
#include <vector>

#include "pipeline/bake_options.h"
#include "scene/scene.h"

namespace irbake {

struct RequestedLightMode {
  LightMode mode = LightMode::Baked;
  std::string reason;  // "--light-mode NAME=MODE", "extras.irbake.mode", "default"
  bool given = false;  // an option or the file chose it
};

// The name --light-mode uses for a light: "sun" for --sun's, else its glTF name (or "#i" when it has none).
std::string lightModeName(const Light& light);

// Per scene light. Throws Error(Usage) naming the light for a name no punctual light has, one that names an
// emitter or the sky (those stay baked), or "*" in a scene without punctual lights.
std::vector<RequestedLightMode> resolveLightModes(const Scene& scene, const std::vector<LightModeRequest>& requests);

}  // namespace irbake
