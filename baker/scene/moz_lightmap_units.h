// MOZ_lightmap's units as irbake writes and reads them (docs/export.md, "MOZ_lightmap units").
// The extension's own rule: E = intensity × sRGBToLinear(texel) is the irradiance on the surface. irbake's map
// values are irradiance/π, so the export writes intensity = π × the 8-bit encoding's range and marks the
// extension with extras {"irbake": {"mozLightmap": "irradiance"}}. An older irbake wrote intensity × texel =
// irradiance/π without the marker: a file is read that way only when its asset.generator starts with "irbake" and
// the marker is absent. Every other file (another tool's, or one naming no generator) is read as the spec says.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "common/maths.h"

namespace irbake {

inline constexpr const char* kMozLightmapMarkerKey = "irbake";          // MOZ_lightmap.extras.<key>
inline constexpr const char* kMozLightmapUnitKey = "mozLightmap";       // MOZ_lightmap.extras.irbake.<key>
inline constexpr const char* kMozLightmapIrradiance = "irradiance";     // its value: intensity × texel = E
inline constexpr const char* kIrbakeGenerator = "irbake";               // how irbake's asset.generator starts

// The marker's JSON, for MOZ_lightmap.extras.irbake.
inline nlohmann::json mozLightmapMarker() { return {{kMozLightmapUnitKey, kMozLightmapIrradiance}}; }

// Whether a MOZ_lightmap object carries the marker (intensity × texel = irradiance E).
inline bool mozLightmapIsIrradiance(const nlohmann::json& moz) {
  if (!moz.is_object()) return false;
  auto extras = moz.find("extras");
  if (extras == moz.end() || !extras->is_object()) return false;
  auto mark = extras->find(kMozLightmapMarkerKey);
  if (mark == extras->end() || !mark->is_object()) return false;
  auto unit = mark->find(kMozLightmapUnitKey);
  return unit != mark->end() && unit->is_string() && unit->get<std::string>() == kMozLightmapIrradiance;
}

// Whether a MOZ_lightmap is in the older irbake convention (intensity × texel = irradiance/π): the file's
// asset.generator (empty when it names none) starts with "irbake" and the extension has no marker.
inline bool mozLightmapIsOlderIrbake(const nlohmann::json& moz, const std::string& generator) {
  return generator.rfind(kIrbakeGenerator, 0) == 0 && !mozLightmapIsIrradiance(moz);
}

// The factor that turns a MOZ_lightmap's intensity × texel into irbake's map value (irradiance/π): 1 for an
// older irbake's extension, 1/π for every other (the specification's irradiance E).
inline double mozLightmapToMapValue(const nlohmann::json& moz, const std::string& generator) {
  return mozLightmapIsOlderIrbake(moz, generator) ? 1.0 : kInvPi;
}

}  // namespace irbake
