// The registry of light-map encodings and the file I/O every encoding shares.
#include "export/map_encoding.h"

#include <fstream>
#include <iterator>

#include "common/error.h"
#include "common/maths.h"

namespace irbake {

double mozLightmapIntensity(const EncodedMap& image) { return kPi * double(image.metadata.intensity); }

// Each encoding's instance, defined in its own file.
const MapEncoding& png8MapEncoding();
const MapEncoding& exrMapEncoding();

const MapEncoding& mapEncoding(MapEncodingKind kind) {
  switch (kind) {
    case MapEncodingKind::Png8: return png8MapEncoding();
    case MapEncodingKind::Exr: return exrMapEncoding();
  }
  throw Error(ErrorCode::InvalidData, "", "unknown light-map encoding");
}

void MapEncoding::writeFile(const Lightmap& page, const MapEncodeOptions& options, const std::filesystem::path& file,
                            const std::filesystem::path& finalPath) const {
  const EncodedMap encoded = encode(page, options);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::Io, finalPath.string(), "cannot open for writing");
  out.write(reinterpret_cast<const char*>(encoded.bytes.data()), static_cast<std::streamsize>(encoded.bytes.size()));
  out.close();
  if (!out) throw Error(ErrorCode::Io, finalPath.string(), "write failed (disk full?)");
}

DecodedMap MapEncoding::readFile(const std::filesystem::path& path, const MapMetadata& metadata) const {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::Io, path.string(), std::filesystem::exists(path) ? "cannot open for reading" : "no such file");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return decode(bytes.data(), bytes.size(), metadata, path.string());
}

DecodedMap decodedFromTexture(const Texture& stored, int page, const std::function<glm::vec3(glm::vec3)>& value) {
  DecodedMap d;
  d.map.page = page;
  d.map.width = stored.width;
  d.map.height = stored.height;
  d.map.texels.resize(stored.texels.size());
  d.alpha.resize(stored.texels.size());
  for (size_t i = 0; i < stored.texels.size(); ++i) {
    d.map.texels[i] = value(glm::vec3(stored.texels[i]));
    d.alpha[i] = stored.texels[i].a;
  }
  d.map.valid.assign(d.map.texels.size(), 1);
  return d;
}

}  // namespace irbake
