// Image decoding and PNG encoding through OpenImageIO, from and to memory (glTF images live in
// buffers and data URIs as often as in files).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace irbake {

enum class ImageFormat { Png, Jpeg, Exr, Hdr, Webp, Unknown };

// Sniffs the container from its first bytes (glTF mimeTypes are optional and sometimes wrong).
ImageFormat sniffImageFormat(const uint8_t* bytes, size_t size);

// Decodes an encoded image (PNG, JPEG, EXR, HDR, WebP) into linear RGBA float texels, row 0 at the top.
// srgb: decode 8/16-bit values with the sRGB transfer curve (colour textures); float formats are
// taken as linear regardless. Grey and grey+alpha are expanded; missing alpha is 1.
// Throws Error(InvalidData, name) when the bytes cannot be decoded.
Texture decodeImageToTexture(const uint8_t* bytes, size_t size, bool srgb, const std::string& name);

// Encodes linear texels as an 8-bit RGBA PNG. srgb: apply the sRGB curve before quantising
// (colour textures); otherwise values are quantised linearly (light maps: the MOZ_lightmap PNG).
// scale multiplies every RGB value first (alpha is kept). Values are clamped to [0,1].
std::vector<uint8_t> encodePng(const Texture& texture, bool srgb, float scale = 1.0f);

// Encodes 8-bit RGBA pixels (width × height × 4 bytes, row 0 at the top) as a PNG.
std::vector<uint8_t> encodePngRgba8(const std::vector<uint8_t>& rgba, int width, int height, const std::string& name);

// The sRGB transfer curve and its inverse on [0,1].
float srgbToLinear(float c);
float linearToSrgb(float c);

}  // namespace irbake
