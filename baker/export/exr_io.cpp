// Float EXR pages through OpenImageIO, written to a temp name then renamed.
#include "export/exr_io.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbake {

void writeExr(const Lightmap& map, const std::filesystem::path& path) {
  if (map.width <= 0 || map.height <= 0 || map.texels.size() != map.size())
    throw Error(ErrorCode::InvalidData, path.string(),
                "light map page " + std::to_string(map.page) + " has no texels or a size mismatch");
  for (const glm::vec3& t : map.texels)
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
      throw Error(ErrorCode::NumericError, path.string(), "light map page " + std::to_string(map.page) + " holds NaN/Inf");
  writeAtomically(path, [&](const std::filesystem::path& temp) {
    // The temp name has no .exr extension: ask for the format by name.
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out) throw Error(ErrorCode::Io, path.string(), "OpenImageIO has no EXR writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(map.width, map.height, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    spec.attribute("irbake:page", map.page);
    spec.attribute("irbake:content", "irradiance/pi, linear");
    if (!out->open(temp.string(), spec))
      throw Error(ErrorCode::Io, path.string(), "cannot open for writing: " + out->geterror());
    if (!out->write_image(OIIO::TypeDesc::FLOAT, map.texels.data()))
      throw Error(ErrorCode::Io, path.string(), "cannot write: " + out->geterror());
    if (!out->close()) throw Error(ErrorCode::Io, path.string(), "cannot close: " + out->geterror());
  });
}

Lightmap readExr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(ErrorCode::Io, path.string(), "no such file");
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw Error(ErrorCode::Io, path.string(), "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1 || spec.depth > 1)
    throw Error(ErrorCode::InvalidData, path.string(), "not a 2D image with channels");
  if (static_cast<double>(spec.width) * spec.height > 1 << 28)
    throw Error(ErrorCode::InvalidData, path.string(), "image too large");
  Lightmap map;
  map.page = spec.get_int_attribute("irbake:page", 0);
  map.width = spec.width;
  map.height = spec.height;
  std::vector<float> pixels(map.size() * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw Error(ErrorCode::Io, path.string(), "cannot decode: " + in->geterror());
  in->close();
  map.texels.resize(map.size());
  const int c = spec.nchannels;
  for (size_t i = 0; i < map.size(); ++i) {
    const float* p = &pixels[i * c];
    map.texels[i] = c >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  map.valid.assign(map.size(), 1);
  return map;
}

}  // namespace irbake
