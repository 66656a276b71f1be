// MOZ_lightmap's units as irbake writes and reads them (docs/export.md, "MOZ_lightmap units").
// The extension's own rule: E = intensity × sRGBToLinear(texel) is the irradiance on the surface. irbake's map
// values are irradiance/π, so the export writes intensity = π × the 8-bit encoding's range and marks the
// extension with extras {"irbake": {"mozLightmap": "irradiance"}}. A file without the marker was written by an
// older irbake, whose intensity × texel is irradiance/π: readers keep reading it that way.
#pragma once
#include <nlohmann/json.hpp>

#include "common/maths.h"

namespace irbake {

inline constexpr const char* kMozLightmapMarkerKey = "irbake";          // MOZ_lightmap.extras.<key>
inline constexpr const char* kMozLightmapUnitKey = "mozLightmap";       // MOZ_lightmap.extras.irbake.<key>
inline constexpr const char* kMozLightmapIrradiance = "irradiance";     // its value: intensity × texel = E

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

// The factor that turns a MOZ_lightmap's intensity × texel into irbake's map value (irradiance/π): 1/π for a
// marked extension, 1 for an older bake's.
inline double mozLightmapToMapValue(const nlohmann::json& moz) { return mozLightmapIsIrradiance(moz) ? kInvPi : 1.0; }

}  // namespace irbake
