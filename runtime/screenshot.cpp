#include "screenshot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbake::view {

ImageFormat imageFormatFor(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".exr") return ImageFormat::Exr;
  throw Error(ErrorCode::Usage, path.string(), "screenshot must end in .png or .exr");
}

float encodeSrgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

std::filesystem::path frameName(const std::filesystem::path& path, int frame) {
  char num[16];
  std::snprintf(num, sizeof num, "_%04d", frame);
  std::filesystem::path out = path.parent_path() / (path.stem().string() + num + path.extension().string());
  return out;
}

void writeScreenshot(const RgbaImage& image, const std::filesystem::path& path, float exposure) {
  const ImageFormat format = imageFormatFor(path);
  for (const auto& p : image.pixels)
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b))
      throw Error(ErrorCode::NumericError, path.string(), "rendered image has a non-finite pixel");
  const size_t n = static_cast<size_t>(image.width) * image.height;
  writeAtomically(path, [&](const std::filesystem::path& temp) {
    // The temp name has no image extension: name the format explicitly.
    auto out = OIIO::ImageOutput::create(format == ImageFormat::Png ? "png" : "openexr");
    if (!out) throw Error(ErrorCode::Io, path.string(), "no image writer: " + OIIO::geterror());
    bool ok = false;
    if (format == ImageFormat::Exr) {
      std::vector<float> rgb(n * 3);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = image.pixels[i][c];
      OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
      spec.attribute("compression", "zip");
      ok = out->open(temp.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, rgb.data());
    } else {
      const float scale = std::exp2(exposure);
      std::vector<unsigned char> rgb(n * 3);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
          rgb[i * 3 + c] = static_cast<unsigned char>(std::lround(255.0f * encodeSrgb(image.pixels[i][c] * scale)));
      OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
      ok = out->open(temp.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, rgb.data());
    }
    if (!ok) throw Error(ErrorCode::Io, path.string(), "cannot write image: " + out->geterror());
    if (!out->close()) throw Error(ErrorCode::Io, path.string(), "cannot write image: " + out->geterror());
  });
}

}  // namespace irbake::view
