// Per-object bake settings from glTF extras (docs/guide.md, "Per-object settings"): extras.irbake.mode and
// extras.irbake.lightmapScale on a node or a mesh, as Blender writes an object's and a mesh's custom properties.
// A node's setting holds for its descendants (a parent empty sets its children) until a nearer node sets its own;
// the node chain wins over the mesh's extras.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace irbake {

// The texel density multiplier's range: beyond it a scale is a typing error, not a setting (64× the density is
// 4096× the texels).
constexpr float kMinLightmapScale = 1.0f / 64.0f;
constexpr float kMaxLightmapScale = 64.0f;

struct ObjectSettings {
  std::optional<ObjectMode> mode;
  std::optional<float> lightmapScale;
  // These settings with the unset ones taken from `farther` (an ancestor node's, or the mesh's).
  ObjectSettings over(const ObjectSettings& farther) const;
};

// extras.irbake of a node's or mesh's JSON object (nothing set when absent). `what` names the object for
// messages ("node 3 ('Crate')"). A bad value throws Error(InvalidData, file, ...) naming the object, the key and
// the value; keys other than mode and lightmapScale are appended to `unknownKeys`.
ObjectSettings readObjectSettings(const nlohmann::json& object, const std::string& what, const std::string& file,
                                  std::vector<std::string>& unknownKeys);

}  // namespace irbake
