// Float EXR pages: the exr map encoding (map_encoding_exr.cpp), written to a temp name then renamed.
#include "export/exr_io.h"

#include "common/atomic_file.h"
#include "export/map_encoding.h"

namespace irbake {

void writeExrFile(const Lightmap& map, const std::filesystem::path& file, const std::filesystem::path& finalPath) {
  mapEncoding(MapEncodingKind::Exr).writeFile(map, {}, file, finalPath);
}

void writeExr(const Lightmap& map, const std::filesystem::path& path) {
  writeAtomically(path, [&](const std::filesystem::path& temp) { writeExrFile(map, temp, path); });
}

Lightmap readExr(const std::filesystem::path& path) { return mapEncoding(MapEncodingKind::Exr).readFile(path, {}).map; }

}  // namespace irbake
