#include "scene/object_settings.h"

#include <cmath>

#include "common/error.h"

namespace irbake {

ObjectSettings ObjectSettings::over(const ObjectSettings& farther) const {
  ObjectSettings s = *this;
  if (!s.mode) s.mode = farther.mode;
  if (!s.lightmapScale) s.lightmapScale = farther.lightmapScale;
  return s;
}

namespace {

std::string shown(const nlohmann::json& value) { return value.dump().substr(0, 80); }

float lightmapScaleOf(const nlohmann::json& value, const std::string& what, const std::string& file) {
  const double scale = value.is_number() ? value.get<double>() : std::nan("");
  if (!value.is_number() || !std::isfinite(scale) || !(scale >= kMinLightmapScale && scale <= kMaxLightmapScale))
    throw Error(ErrorCode::InvalidData, file,
                what + ": extras.irbake.lightmapScale must be a number from 1/64 to 64 (got " + shown(value) + ")");
  return static_cast<float>(scale);
}

}  // namespace

ObjectSettings readObjectSettings(const nlohmann::json& object, const std::string& what, const std::string& file,
                                  std::vector<std::string>& unknownKeys) {
  ObjectSettings settings;
  if (!object.is_object()) return settings;
  auto extras = object.find("extras");
  if (extras == object.end() || !extras->is_object()) return settings;  // glTF allows extras of any type
  auto irbake = extras->find("irbake");
  if (irbake == extras->end()) return settings;
  if (!irbake->is_object())
    throw Error(ErrorCode::InvalidData, file, what + ": extras.irbake must be an object (got " + shown(*irbake) + ")");
  for (const auto& [key, value] : irbake->items()) {
    if (key == "mode") {
      ObjectMode mode = ObjectMode::Baked;
      if (!value.is_string() || !parseObjectMode(value.get<std::string>(), mode))
        throw Error(ErrorCode::InvalidData, file,
                    what + ": extras.irbake.mode must be \"baked\", \"shadow-only\", \"probes\" or \"off\" (got " +
                        shown(value) + ")");
      settings.mode = mode;
    } else if (key == "lightmapScale") {
      settings.lightmapScale = lightmapScaleOf(value, what, file);
    } else {
      unknownKeys.push_back(key);
    }
  }
  return settings;
}

}  // namespace irbake
