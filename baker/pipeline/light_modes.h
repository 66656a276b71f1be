// Each punctual light's bake mode (mixed lighting): from --light-mode, the glTF light's extras.irbake.mode,
// or baked; checked before anything is traced so that a bad name costs nothing.
//
// A --light-mode selector (NAME of NAME=MODE) is one of
//   *            every punctual light
//   sun          the light of --sun
//   #I           KHR light I (KHR_lights_punctual.lights[I])
//   TEXT         the glTF lights named TEXT
// and, never ambiguous, name:TEXT (the glTF lights named TEXT, whatever TEXT is: `name:*`, `name:sun`,
// `name:#0`), index:I (KHR light I) and option:sun (the light of --sun). A plain `sun` or `#I` that is also
// another light's glTF name is refused, naming both lights and the explicit form of each.
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

// The name messages use for a light: "sun" for --sun's, else its glTF name (or "#i" when it has none).
std::string lightModeName(const Light& light);

// The scene lights a selector other than "*" addresses (empty: none); `what` names the option in the refusal
// of an ambiguous plain `sun` or `#I` (Error(Usage)). Light groups (pipeline/light_groups.h) read the same selectors.
std::vector<size_t> lightsSelectedBy(const Scene& scene, const std::string& selector, const std::string& what);
// The scene's punctual lights as selectors ("sun, lamp, #2"), for a refusal's list; "" without lights.
std::string knownLightSelectors(const Scene& scene);
// The light of --sun (not a glTF light).
bool isCommandLineSun(const Light& light);

// Per scene light. Throws Error(Usage) naming the light for a selector no punctual light answers to, one that
// names an emitter or the sky (those stay baked), an ambiguous one, or "*" in a scene without punctual lights.
std::vector<RequestedLightMode> resolveLightModes(const Scene& scene, const std::vector<LightModeRequest>& requests);

}  // namespace irbake
