#include "scene/image_codec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "common/error.h"
#include "imageio/image_io.h"

namespace irbake {

float srgbToLinear(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

ImageFormat sniffImageFormat(const uint8_t* b, size_t n) {
  if (n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) return ImageFormat::Png;
  if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return ImageFormat::Jpeg;
  if (n >= 4 && b[0] == 0x76 && b[1] == 0x2F && b[2] == 0x31 && b[3] == 0x01) return ImageFormat::Exr;
  if (n >= 2 && b[0] == '#' && b[1] == '?') return ImageFormat::Hdr;
  if (n >= 12 && std::memcmp(b, "RIFF", 4) == 0 && std::memcmp(b + 8, "WEBP", 4) == 0) return ImageFormat::Webp;
  return ImageFormat::Unknown;
}

namespace {

// OpenImageIO reader names: create() with a file name would try to open that file, a format name does not.
const char* nameForFormat(ImageFormat f) {
  switch (f) {
    case ImageFormat::Png: return "png";
    case ImageFormat::Jpeg: return "jpeg";
    case ImageFormat::Exr: return "openexr";
    case ImageFormat::Hdr: return "hdr";
    case ImageFormat::Webp: return "webp";
    case ImageFormat::Unknown: break;
  }
  return "";
}

const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = srgbToLinear(i / 255.0f);
    return t;
  }();
  return table;
}

}  // namespace

Texture decodeImageToTexture(const uint8_t* bytes, size_t size, bool srgb, const std::string& name) {
  ImageFormat format = sniffImageFormat(bytes, size);
  if (format == ImageFormat::Unknown)
    throw Error(ErrorCode::InvalidData, name, "image is not PNG, JPEG, WebP, EXR or HDR");
  const imageio::Pixels px = imageio::api().decodeMemory(bytes, size, nameForFormat(format), name);
  const int w = px.width, h = px.height, nc = px.channels;
  Texture tex;
  tex.name = name;
  tex.width = w;
  tex.height = h;
  tex.texels.resize(static_cast<size_t>(w) * h);
  const bool isFloat = px.floatSource;
  const int gray = nc <= 2 ? 1 : 0;  // grey (+alpha): replicate the first channel
  const int alphaChannel = nc == 2 ? 1 : (nc >= 4 ? 3 : -1);
  if (!px.u8.empty()) {
    const auto& lut = srgbTable();
    for (size_t i = 0; i < tex.texels.size(); ++i) {
      const uint8_t* p = &px.u8[i * nc];
      glm::vec4 t;
      for (int c = 0; c < 3; ++c) {
        uint8_t v = p[gray ? 0 : c];
        t[c] = srgb ? lut[v] : v / 255.0f;
      }
      t.a = alphaChannel >= 0 ? p[alphaChannel] / 255.0f : 1.0f;
      tex.texels[i] = t;
    }
  } else {
    for (size_t i = 0; i < tex.texels.size(); ++i) {
      const float* p = &px.f32[i * nc];
      glm::vec4 t;
      for (int c = 0; c < 3; ++c) {
        float v = p[gray ? 0 : c];
        if (!std::isfinite(v)) v = 0.0f;  // no NaN may enter the scene
        t[c] = (srgb && !isFloat) ? srgbToLinear(v) : v;
      }
      t.a = alphaChannel >= 0 ? p[alphaChannel] : 1.0f;
      tex.texels[i] = t;
    }
  }
  return tex;
}

std::vector<uint8_t> encodePng(const Texture& texture, bool srgb, float scale) {
  const int w = texture.width, h = texture.height;
  if (w <= 0 || h <= 0 || texture.texels.size() != static_cast<size_t>(w) * h)
    throw Error(ErrorCode::InvalidData, texture.name, "cannot encode an empty texture as PNG");
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * 4);
  auto quantise = [](float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  for (size_t i = 0; i < texture.texels.size(); ++i) {
    const glm::vec4& t = texture.texels[i];
    for (int c = 0; c < 3; ++c) {
      float v = std::isfinite(t[c]) ? t[c] * scale : 0.0f;
      px[i * 4 + c] = quantise(srgb ? linearToSrgb(v) : v);
    }
    px[i * 4 + 3] = quantise(std::isfinite(t.a) ? t.a : 1.0f);
  }
  return imageio::api().encodePngMemory(px.data(), w, h, texture.name);
}

std::vector<uint8_t> encodePngRgba8(const std::vector<uint8_t>& rgba, int width, int height, const std::string& name) {
  if (width <= 0 || height <= 0 || rgba.size() != static_cast<size_t>(width) * height * 4)
    throw Error(ErrorCode::InvalidData, name, "cannot encode an empty image as PNG");
  return imageio::api().encodePngMemory(rgba.data(), width, height, name);
}

}  // namespace irbake
