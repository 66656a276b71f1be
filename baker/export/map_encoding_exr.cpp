// exr: float32 EXR through OpenImageIO (the imageio plugin), RGB or RGBA, linear, exact. The page number
// travels in the file (attribute irbake:page). No metadata: intensity 1, no curve.
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "common/error.h"
#include "export/map_encoding.h"
#include "imageio/image_io.h"

namespace irbake {

namespace {

DecodedMap fromPixels(const imageio::Pixels& px, int page) {
  DecodedMap d;
  Lightmap& map = d.map;
  map.page = page;
  map.width = px.width;
  map.height = px.height;
  map.texels.resize(map.size());
  const int c = px.channels;
  for (size_t i = 0; i < map.size(); ++i) {
    const float* p = &px.f32[i * c];
    map.texels[i] = c >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  if (c >= 4) {
    d.alpha.resize(map.size());
    for (size_t i = 0; i < map.size(); ++i) d.alpha[i] = px.f32[i * c + 3];
  }
  map.valid.assign(map.size(), 1);
  return d;
}

class ExrEncoding final : public MapEncoding {
 public:
  MapEncodingKind kind() const override { return MapEncodingKind::Exr; }
  const char* name() const override { return "exr"; }
  const char* mimeType() const override { return ""; }  // glTF has no EXR image: a side file
  double tolerance(float, const MapMetadata&) const override { return 0.0; }

  // Through a scratch file in the temp folder ($TMPDIR): the imageio plugin writes EXRs only to files. The
  // export writes its pages with writeFile instead.
  EncodedMap encode(const Lightmap& page, const MapEncodeOptions& options) const override {
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path temp = std::filesystem::temp_directory_path() /
                                       (".irbake-exr." + std::to_string(::getpid()) + "." + std::to_string(counter++) + ".exr");
    EncodedMap e;
    e.metadata.page = page.page;
    try {
      writeFile(page, options, temp, temp);
      std::ifstream in(temp, std::ios::binary);
      e.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      if (!in.eof() && in.fail()) throw Error(ErrorCode::Io, temp.string(), "cannot read back");
    } catch (...) {
      std::filesystem::remove(temp);
      throw;
    }
    std::filesystem::remove(temp);
    return e;
  }

  DecodedMap decode(const uint8_t* bytes, size_t size, const MapMetadata& md, const std::string& name) const override {
    return fromPixels(imageio::api().decodeMemory(bytes, size, "openexr", name), md.page);
  }

  // Float values are stored as they are: the texture's RGB and alpha.
  DecodedMap fromStored(const Texture& t, const MapMetadata& md) const override {
    return decodedFromTexture(t, md.page, [](glm::vec3 v) { return v; });
  }

  void writeFile(const Lightmap& map, const MapEncodeOptions& options, const std::filesystem::path& file,
                 const std::filesystem::path& finalPath) const override {
    if (map.width <= 0 || map.height <= 0 || map.texels.size() != map.size() ||
        (options.alpha && options.alpha->texels.size() != map.size()))
      throw Error(ErrorCode::InvalidData, finalPath.string(),
                  "light map page " + std::to_string(map.page) + " has no texels or a size mismatch");
    for (const glm::vec3& t : map.texels)
      if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
        throw Error(ErrorCode::NumericError, finalPath.string(), "light map page " + std::to_string(map.page) + " holds NaN/Inf");
    imageio::Pixels px;
    px.width = map.width;
    px.height = map.height;
    px.channels = options.alpha ? 4 : 3;
    if (options.alpha) {
      px.f32.reserve(map.size() * 4);
      for (size_t i = 0; i < map.size(); ++i) {
        const glm::vec3& t = map.texels[i];
        const float a = options.alpha->texels[i].x;
        if (!std::isfinite(a))
          throw Error(ErrorCode::NumericError, finalPath.string(), "light map page " + std::to_string(map.page) + " holds NaN/Inf");
        px.f32.insert(px.f32.end(), {t.x, t.y, t.z, a});
      }
    } else {
      px.f32.assign(&map.texels[0].x, &map.texels[0].x + map.texels.size() * 3);
    }
    imageio::api().writeFile(file.string(), "openexr", px, map.page, finalPath.string());
  }

  DecodedMap readFile(const std::filesystem::path& path, const MapMetadata&) const override {
    if (!std::filesystem::exists(path)) throw Error(ErrorCode::Io, path.string(), "no such file");
    const imageio::Pixels px = imageio::api().readFile(path.string());
    return fromPixels(px, px.page);
  }
};

}  // namespace

const MapEncoding& exrMapEncoding() {
  static const ExrEncoding encoding;
  return encoding;
}

}  // namespace irbake
