// Light-map encodings behind one interface. An encoding turns a page of linear values (Lightmap texels:
// irradiance/π, an L1 axis, a shadow mask) into bytes plus the metadata a client needs to read them back
// (MOZ_lightmap's intensity, the colour space), and decodes bytes plus that metadata back to linear values:
//   value = decode(stored) × intensity          (signed maps: value = (2 · decode(stored) − 1) × intensity)
// The encodings, chosen by MapEncodingKind in mapEncoding() (map_encoding.cpp):
//   png8  8-bit PNG, sRGB or linear, range picked per page (map_encoding_png8.cpp): the MOZ_lightmap image,
//         the directional L1 and shadow-mask images.
//   exr   float32 EXR, exact (map_encoding_exr.cpp): the float pages beside the glTF.
// A new encoding (RGBM, KTX2) is its own map_encoding_<name>.cpp, one entry in MapEncodingKind and in
// mapEncoding(), and the clients that choose it (docs/architecture.md, "Export").
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "lightmap/lightmap.h"
#include "scene/scene.h"

namespace irbake {

enum class MapEncodingKind { Png8, Exr };

// How an 8-bit encoding maps a page's values onto [0, 1] (float encodings store the values as they are).
enum class MapRange {
  Percentile,  // values ≥ 0: stored = value / intensity, intensity = a percentile of the covered texels' largest channel
  SignedMax,   // signed values: stored = (value / intensity + 1) / 2, intensity = the largest |value| over valid texels
  Unit,        // values in [0, 1] (a visibility): stored as they are, intensity 1
};

struct MapEncodeOptions {
  bool srgb = true;                    // sRGB-encode the normalised value (decode with the sRGB curve); png8 only
  double percentile = 99.9;            // MapRange::Percentile: this percentile of the covered texels' largest channel (100: the maximum)
  MapRange range = MapRange::Percentile;  // how an 8-bit encoding picks its range
  const Lightmap* alpha = nullptr;     // a fourth channel (its texels' x), or null: RGB only (png8: alpha 1)
  std::string name;                    // the image's name (empty: "lightmap_<page>")
};

// What a client needs besides the bytes (the MOZ_lightmap / extension fields).
struct MapMetadata {
  float intensity = 1.0f;     // value = decoded × intensity (MOZ_lightmap intensity, an L1 page's scale)
  bool srgb = false;          // stored with the sRGB curve (MOZ_lightmap extras.colorSpace "srgb")
  bool signedValues = false;  // stored s in [0, 1] stands for 2s − 1 (L1 pages)
  int page = 0;               // the light-map page
};

struct EncodedMap {
  Texture stored;              // the values as stored before quantisation, linear (png8: normalised to [0, 1])
  MapMetadata metadata;
  std::vector<uint8_t> bytes;  // the encoded file
};

// MOZ_lightmap's `intensity` for an 8-bit map: the PNG holds map value (E/π) / range, so intensity × sRGB⁻¹(texel)
// is the irradiance E when the intensity is π × the range (docs/export.md, "MOZ_lightmap: what a client does").
double mozLightmapIntensity(const EncodedMap& image);

struct DecodedMap {
  Lightmap map;                // linear values (valid = 1 everywhere)
  std::vector<float> alpha;    // the fourth channel, empty when the file has none
};

// A stored texture as a decoded page: each texel's RGB through `value`, its alpha as stored, every texel valid.
DecodedMap decodedFromTexture(const Texture& stored, int page, const std::function<glm::vec3(glm::vec3)>& value);

class MapEncoding {
 public:
  virtual ~MapEncoding() = default;
  virtual MapEncodingKind kind() const = 0;
  virtual const char* name() const = 0;       // "png8", "exr"
  virtual const char* mimeType() const = 0;   // the glTF image mimeType ("" where glTF has none)
  // The largest |decoded − value| of a value in the encoded range, for a page with this metadata.
  virtual double tolerance(float value, const MapMetadata& metadata) const = 0;
  virtual EncodedMap encode(const Lightmap& page, const MapEncodeOptions& options) const = 0;
  // Throws Error(InvalidData, name) when the bytes cannot be decoded.
  virtual DecodedMap decode(const uint8_t* bytes, size_t size, const MapMetadata& metadata, const std::string& name) const = 0;
  // The values of a page whose image a client has unpacked itself (the scene loader: 8-bit codes to [0, 1],
  // the sRGB curve applied where metadata.srgb says): what decode() returns once it has read the bytes.
  virtual DecodedMap fromStored(const Texture& stored, const MapMetadata& metadata) const = 0;
  // Writes the encoded page straight to `file` (a temp of a set written with writeAllAtomically); messages
  // name `finalPath`. Throws Error(Io/NumericError/InvalidData).
  virtual void writeFile(const Lightmap& page, const MapEncodeOptions& options, const std::filesystem::path& file,
                         const std::filesystem::path& finalPath) const;
  // Reads and decodes a file. Throws Error(Io) naming it.
  virtual DecodedMap readFile(const std::filesystem::path& path, const MapMetadata& metadata) const;
};

// The one place an encoding is chosen.
const MapEncoding& mapEncoding(MapEncodingKind kind);

// What png8 loses, over the covered (valid) texels with a positive value.
struct Png8Error {
  double zeroFraction = 0.0;  // fraction of covered texels with a channel > 0 that decodes to exactly 0
  double relErrorP90 = 0.0;   // 90th percentile of |decoded − value| / value over covered channels > 0
  double relErrorP50 = 0.0;   // median of the same
  double clippedFraction = 0.0;  // fraction of covered texels with a channel above the range (clipped)
};

// The range of MapRange::Percentile from the texels' largest channels (`peaks`, those > 0; reordered): their
// nearest-rank `percentile`, 1 when there is none. The one rule for every 8-bit range: the MOZ_lightmap PNG's
// intensity and the portable GLB's range (export/portable_export.h).
float rangeAtPercentile(std::vector<float>& peaks, double percentile);

// Quantises `map` as png8 would with MapRange::Percentile (decoding the 8-bit codes) and measures the error.
Png8Error measurePng8(const Lightmap& map, const MapEncodeOptions& options = {});

}  // namespace irbake
