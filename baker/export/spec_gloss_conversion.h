// KHR_materials_pbrSpecularGlossiness → metal-rough on export, as glTF-Transform's `metalRough` converts it.
// The specular-glossiness extension (archived by Khronos) is one no other material extension may sit beside
// (the Khronos validator warns MULTIPLE_EXTENSIONS for MOZ_lightmap there), and importers that build a
// metal-rough material from it (Blender's) leave nothing to wire a light map into. Per converted material:
//   - pbrMetallicRoughness: baseColorFactor = diffuseFactor, baseColorTexture = diffuseTexture (either omitted
//     when the extension omits it), metallicFactor 0, roughnessFactor 1 − glossinessFactor; with a
//     specularGlossinessTexture, roughnessFactor 1 and a new metallicRoughnessTexture whose G channel is
//     1 − alpha × glossinessFactor (8-bit, rounded as glTF-Transform does), R and B 0;
//   - KHR_materials_specular: specularColorFactor = specularFactor, specularColorTexture = the
//     specularGlossinessTexture (the extension reads its RGB: the specular colour as it was);
//   - KHR_materials_ior: ior 1000, so that the dielectric F0 is the specular colour itself;
//   - the rest of the material (emission, normal and occlusion maps, alpha, extras, other extensions) kept.
// The extension leaves extensionsUsed and extensionsRequired.
#pragma once
#include <string>

#include "export/gltf_writer.h"

namespace irbake {

inline constexpr const char* kSpecularGlossinessExtension = "KHR_materials_pbrSpecularGlossiness";

// Converts every material of the document that carries the extension; returns how many. Image bytes are read
// from the document's buffer 0 (the export merged every image into it). Throws Error(InvalidData, file) naming
// the material and the field for a specular-glossiness object that is malformed (a factor of the wrong size or
// not finite, a texture that does not exist or whose image cannot be decoded).
int convertSpecularGlossiness(GltfDocument& doc, const std::string& file);

}  // namespace irbake
