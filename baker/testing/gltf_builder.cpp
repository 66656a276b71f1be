#include "testing/gltf_builder.h"

#include <cstdlib>

namespace irbake::testing {

std::filesystem::path testFolder(const std::string& name) {
  const char* bin = std::getenv("IRBAKE_BINARY_DIR");
  std::filesystem::path root = bin ? std::filesystem::path(bin) : std::filesystem::current_path();
  std::filesystem::path dir = root / "test_output" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

GltfDocument meshDocument(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<glm::vec3>& normals) {
  GltfDocument doc;
  nlohmann::json attributes = {{"POSITION", doc.addPositions(positions)}};
  if (!normals.empty()) attributes["NORMAL"] = doc.addVec3(normals);
  nlohmann::json prim = {{"attributes", attributes}};
  if (!indices.empty()) prim["indices"] = doc.addIndices(indices);
  doc.append("meshes", {{"primitives", nlohmann::json::array({prim})}});
  doc.append("nodes", {{"mesh", 0}});
  doc.root["scenes"] = nlohmann::json::array({{{"nodes", {0}}}});
  doc.root["scene"] = 0;
  return doc;
}

void writeDocument(const GltfDocument& doc, const std::filesystem::path& path) { writeAllAtomically(doc.files(path)); }

}  // namespace irbake::testing
