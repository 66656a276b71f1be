// The files a glTF scene is made of: the scene file itself and every local file its buffers and images
// name (URIs decoded, resolved in the scene's folder). What the output checks protect and the scene
// hash reads.
#pragma once
#include <filesystem>
#include <vector>

namespace irbake {

// The scene file first, then each distinct local file of its buffers and images (data: URIs are inside
// the scene file). Throws Error like readGltfSource when the scene cannot be read or is not glTF.
std::vector<std::filesystem::path> sceneInputFiles(const std::filesystem::path& scene);

}  // namespace irbake
