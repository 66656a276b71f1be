// Test helper (header only, used by tests): hand-made glTF documents built on GltfDocument, written
// under the build folder.
#pragma once
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "export/gltf_writer.h"

namespace irbake::testing {

// A folder for a test's files inside the build tree (tests run with the build folder as cwd).
inline std::filesystem::path testFolder(const std::string& name) {
  const char* bin = std::getenv("IRBAKE_BINARY_DIR");
  std::filesystem::path root = bin ? std::filesystem::path(bin) : std::filesystem::current_path();
  std::filesystem::path dir = root / "test_output" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// One mesh with one triangle-list primitive (positions and indices, normals optional) on node 0
// of scene 0. Returns the document; the mesh is mesh 0, its primitive meshes[0].primitives[0].
inline GltfDocument meshDocument(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                                 const std::vector<glm::vec3>& normals = {}) {
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

inline void writeDocument(const GltfDocument& doc, const std::filesystem::path& path) {
  writeAllAtomically(doc.files(path));
}

}  // namespace irbake::testing
