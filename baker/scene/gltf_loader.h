// glTF 2.0 (.gltf / .glb) → world-space Scene, with validation (see docs/scene.md).
#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

#include "scene/scene.h"

namespace irbake {

struct LoadOptions {
  bool decodeImages = true;      // decode base colour / emissive / lightmap images (false: textures stay empty)
  bool computeMissingNormals = true;  // flat normals when NORMAL is absent (the glTF rule; vertices split per face orientation)
  bool shadingMaps = false;      // also TANGENT, normalTexture and IRBAKE_lightmap_directional (the viewer's; a bake skips them)
};

// Loads a glTF or GLB file. Throws Error(Io | Parse | InvalidData | EmptyScene, path, one-line message).
// Warnings (skipped points/lines, undecodable images, ...) go to Scene::stats.warnings and the log.
Scene loadScene(const std::filesystem::path& path, const LoadOptions& options = {});
// The same from a file's bytes already in memory (the fuzz harness, tests/fuzz): `path` names the
// input in messages and its folder resolves relative URIs (buffers, images), as for loadScene.
Scene loadSceneFromBytes(std::vector<uint8_t> bytes, const std::filesystem::path& path, const LoadOptions& options = {});

// A bake needs light: throws Error(NoLight, path) when the scene has neither a punctual light nor an
// emissive material (the command line may add a light before calling this).
void requireLight(const Scene& scene, const std::filesystem::path& path);

}  // namespace irbake
