// The lights a client shades itself in an irbake export (mixed lighting, docs/export.md "Mixed lights"):
// KHR lights whose extras.irbake.mode is indirect or shadowmask, the command line's sun (root extras
// "irbakeSun", or its IRBAKE_shadowmask entry), each with its shadow-mask channel (-1: none).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace irbake {

// Reads the root IRBAKE_shadowmask light → channel map and "irbakeSun" of a glTF document whose KHR lights are
// already in `lights` (Light::extrasMode as the file says). A light in the channel map is shaded with its
// channel even without extras; an indirect one has none. Throws Error(InvalidData) naming `file` and the
// entry for a malformed map: not an array, a channel outside 0..3, a light index the file does not have, a
// directional entry without a finite direction and irradiance ≥ 0, two lights of one channel on one light.
std::vector<RuntimeLight> readRuntimeLights(const nlohmann::json& root, const std::vector<Light>& lights,
                                            size_t khrLightCount, const std::string& file);

}  // namespace irbake
