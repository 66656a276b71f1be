// Float EXR pages (the exr map encoding, export/map_encoding.h): RGB float, linear, written atomically.
#pragma once
#include <filesystem>

#include "lightmap/lightmap.h"

namespace irbake {

// Writes map.texels as a 32-bit float RGB EXR (row 0 = v = 0 at the top). Throws Error(Io/NumericError).
void writeExr(const Lightmap& map, const std::filesystem::path& path);
// The same, written straight to `file` (a temp of a set written with writeAllAtomically); messages name
// `finalPath`.
void writeExrFile(const Lightmap& map, const std::filesystem::path& file, const std::filesystem::path& finalPath);
// Reads an EXR written by writeExr (valid = 1 everywhere). Throws Error(Io) naming the file.
Lightmap readExr(const std::filesystem::path& path);

}  // namespace irbake
