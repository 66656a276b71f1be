#include "screenshot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>


#include "common/atomic_file.h"
#include "common/error.h"
#include "imageio/image_io.h"

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

OutputGuard viewerOutputGuard(const ViewerScene& scene) {
  OutputGuard guard;
  guard.addInputs(scene.inputFiles);
  return guard;
}

void writeScreenshot(const RgbaImage& image, const std::filesystem::path& path, float exposure, const OutputGuard& guard) {
  const ImageFormat format = imageFormatFor(path);
  for (const auto& p : image.pixels)
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b))
      throw Error(ErrorCode::NumericError, path.string(), "rendered image has a non-finite pixel");
  const size_t n = static_cast<size_t>(image.width) * image.height;
  guard.write(path, [&](const std::filesystem::path& temp) {
    imageio::Pixels px;
    px.width = image.width;
    px.height = image.height;
    px.channels = 3;
    if (format == ImageFormat::Exr) {
      px.f32.resize(n * 3);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) px.f32[i * 3 + c] = image.pixels[i][c];
    } else {
      const float scale = std::exp2(exposure);
      px.u8.resize(n * 3);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
          px.u8[i * 3 + c] = static_cast<unsigned char>(std::lround(255.0f * encodeSrgb(image.pixels[i][c] * scale)));
    }
    imageio::api().writeFile(temp.string(), format == ImageFormat::Png ? "png" : "openexr", px, -1, path.string());
  });
}

}  // namespace irbake::view
