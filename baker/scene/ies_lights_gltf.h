// EXT_lights_ies in a glTF: the root's light profiles (uri: a file beside the glTF or a data URI; or bufferView
// with mimeType application/x-ies-lm-63), each parsed once, and the lights nodes place from them.
#pragma once
#include <map>
#include <memory>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scene/gltf_source.h"
#include "scene/scene.h"

namespace tinygltf {
class Model;
}

namespace irbake {

class IesLightReader {
 public:
  // `file` names the glTF in messages.
  IesLightReader(const GltfSource& source, const tinygltf::Model& model, std::string file);
  // The light of node n's EXT_lights_ies object `ext` (light, multiplier, color), placed by the node's world
  // matrix: its position, its nadir along −Z and its horizontal angle 0 along +X. Throws Error(InvalidData,
  // file, ...) naming the extension, the light and, for a malformed profile, its file or bufferView and line.
  Light light(int n, const nlohmann::json& ext, const glm::mat4& world);

 private:
  std::shared_ptr<const IesProfile> profile(int index);
  [[noreturn]] void invalid(const std::string& message) const;

  const GltfSource& source_;
  const tinygltf::Model& model_;
  std::string file_;
  std::map<int, std::shared_ptr<const IesProfile>> profiles_;
};

}  // namespace irbake
