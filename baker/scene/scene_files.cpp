#include "scene/scene_files.h"

#include <algorithm>
#include <string>

#include "scene/gltf_source.h"

namespace irbake {

std::vector<std::filesystem::path> sceneInputFiles(const std::filesystem::path& scene) {
  const GltfSource source = readGltfSource(scene);
  std::vector<std::filesystem::path> files = {scene};
  for (const char* list : {"buffers", "images"}) {
    if (!source.json.contains(list) || !source.json[list].is_array()) continue;
    for (const auto& item : source.json[list]) {
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      const std::filesystem::path file = source.folder / decodeUriEscapes(uri);
      if (std::find(files.begin(), files.end(), file) == files.end()) files.push_back(file);
    }
  }
  return files;
}

}  // namespace irbake
