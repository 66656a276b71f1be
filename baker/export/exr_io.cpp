// Float EXR pages through OpenImageIO (the imageio plugin), written to a temp name then renamed.
#include "export/exr_io.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "imageio/image_io.h"

namespace irbake {

void writeExrFile(const Lightmap& map, const std::filesystem::path& file, const std::filesystem::path& finalPath) {
  if (map.width <= 0 || map.height <= 0 || map.texels.size() != map.size())
    throw Error(ErrorCode::InvalidData, finalPath.string(),
                "light map page " + std::to_string(map.page) + " has no texels or a size mismatch");
  for (const glm::vec3& t : map.texels)
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
      throw Error(ErrorCode::NumericError, finalPath.string(), "light map page " + std::to_string(map.page) + " holds NaN/Inf");
  imageio::Pixels px;
  px.width = map.width;
  px.height = map.height;
  px.channels = 3;
  px.f32.assign(&map.texels[0].x, &map.texels[0].x + map.texels.size() * 3);
  imageio::api().writeFile(file.string(), "openexr", px, map.page, finalPath.string());
}

void writeExr(const Lightmap& map, const std::filesystem::path& path) {
  writeAtomically(path, [&](const std::filesystem::path& temp) { writeExrFile(map, temp, path); });
}

Lightmap readExr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(ErrorCode::Io, path.string(), "no such file");
  const imageio::Pixels px = imageio::api().readFile(path.string());
  Lightmap map;
  map.page = px.page;
  map.width = px.width;
  map.height = px.height;
  map.texels.resize(map.size());
  const int c = px.channels;
  for (size_t i = 0; i < map.size(); ++i) {
    const float* p = &px.f32[i * c];
    map.texels[i] = c >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  map.valid.assign(map.size(), 1);
  return map;
}

}  // namespace irbake
