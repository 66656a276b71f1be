// Hand-made glTF documents for the loader, export and command-line tests, built on GltfDocument and
// written under the build folder.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "export/gltf_writer.h"

namespace irbake::testing {

// A fresh, empty folder for a test's files inside the build tree (tests run with the build folder as cwd).
std::filesystem::path testFolder(const std::string& name);

// One mesh with one triangle-list primitive (positions and indices, normals optional) on node 0
// of scene 0. Returns the document; the mesh is mesh 0, its primitive meshes[0].primitives[0].
GltfDocument meshDocument(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<glm::vec3>& normals = {});

// The document's files (the .gltf and its buffers, or the .glb) written atomically at path.
void writeDocument(const GltfDocument& doc, const std::filesystem::path& path);

}  // namespace irbake::testing
