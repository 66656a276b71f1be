// The OpenImageIO side of imageio/image_io.h, built as libirbake_imageio_oiio.so and opened with
// dlopen on first use (see image_io.h for why).
#include <cstdlib>
#include <ctime>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "common/error.h"
#include "imageio/image_io.h"

namespace irbake::imageio {
namespace {

namespace OIIO = OIIO_NAMESPACE;

Pixels decodeMemory(const uint8_t* bytes, size_t size, const char* format, const std::string& name) {
  OIIO::Filesystem::IOMemReader reader(bytes, size);
  // The memory proxy must be attached before open().
  auto in = OIIO::ImageInput::create(format);
  if (!in || !in->supports("ioproxy") || !in->set_ioproxy(&reader))
    throw Error(ErrorCode::InvalidData, name, "no OpenImageIO reader decodes this image from memory");
  OIIO::ImageSpec spec;
  if (!in->open(format, spec)) throw Error(ErrorCode::InvalidData, name, "cannot decode image: " + in->geterror());
  Pixels px;
  px.width = spec.width;
  px.height = spec.height;
  px.channels = spec.nchannels;
  if (px.width <= 0 || px.height <= 0 || px.channels <= 0 || static_cast<int64_t>(px.width) * px.height > (int64_t(1) << 28))
    throw Error(ErrorCode::InvalidData, name, "image has an absurd size " + std::to_string(px.width) + "x" + std::to_string(px.height));
  const auto base = spec.format.basetype;
  px.floatSource = base == OIIO::TypeDesc::FLOAT || base == OIIO::TypeDesc::HALF || base == OIIO::TypeDesc::DOUBLE;
  const size_t count = static_cast<size_t>(px.width) * px.height * px.channels;
  bool ok = false;
  if (base == OIIO::TypeDesc::UINT8) {
    px.u8.resize(count);
    ok = in->read_image(0, 0, 0, px.channels, OIIO::TypeDesc::UINT8, px.u8.data());
  } else {
    px.f32.resize(count);
    ok = in->read_image(0, 0, 0, px.channels, OIIO::TypeDesc::FLOAT, px.f32.data());
  }
  if (!ok) throw Error(ErrorCode::InvalidData, name, "cannot decode image: " + in->geterror());
  in->close();
  return px;
}

std::vector<uint8_t> encodePngMemory(const uint8_t* rgba, int width, int height, const std::string& name) {
  // zlib level 3, not libpng's 6: a page is encoded serially at the end of the bake, and level 3 takes much
  // less time for a slightly larger file; level 1 saves no more time.
  constexpr int level = 3;
  std::vector<unsigned char> out;
  OIIO::Filesystem::IOVecOutput writer(out);
  // The PNG writer takes the memory proxy through create(); the name only selects the format.
  auto png = OIIO::ImageOutput::create("png", &writer);
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", level);
  if (!png || !png->open("image.png", spec))
    throw Error(ErrorCode::Io, name, "cannot encode PNG: " + OIIO::geterror());
  if (!png->write_image(OIIO::TypeDesc::UINT8, rgba) || !png->close())
    throw Error(ErrorCode::Io, name, "cannot encode PNG: " + png->geterror());
  return std::vector<uint8_t>(out.begin(), out.end());
}

// "YYYY:MM:DD HH:MM:SS" (UTC) of SOURCE_DATE_EPOCH, or of 0 when it is unset or not a number.
std::string reproducibleDateTime() {
  std::time_t t = 0;
  if (const char* e = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    const long long v = std::strtoll(e, &end, 10);
    if (end && *end == '\0' && v >= 0) t = static_cast<std::time_t>(v);
  }
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &utc);
  return text;
}

void writeFile(const std::string& file, const char* format, const Pixels& px, int page, const std::string& name) {
  // The file is usually a temp name without an image extension: the format is named explicitly.
  auto out = OIIO::ImageOutput::create(format);
  if (!out) throw Error(ErrorCode::Io, name, std::string("OpenImageIO has no ") + format + " writer: " + OIIO::geterror());
  const bool isFloat = px.u8.empty();
  OIIO::ImageSpec spec(px.width, px.height, px.channels, isFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  // No compression: a light map's float noise hardly compresses, and zip costs a noticeable share of the bake.
  if (std::string(format) == "openexr") spec.attribute("compression", "none");
  // Byte-identical outputs for identical bakes: OpenEXR's writer stamps the current time (capDate) unless a
  // DateTime is given, so give the reproducible-builds one: SOURCE_DATE_EPOCH when set, else the epoch.
  spec.attribute("DateTime", reproducibleDateTime());
  if (page >= 0) {
    spec.attribute("irbake:page", page);
    spec.attribute("irbake:content", "irradiance/pi, linear");
  }
  if (!out->open(file, spec)) throw Error(ErrorCode::Io, name, "cannot open for writing: " + out->geterror());
  const bool ok = isFloat ? out->write_image(OIIO::TypeDesc::FLOAT, px.f32.data())
                          : out->write_image(OIIO::TypeDesc::UINT8, px.u8.data());
  if (!ok) throw Error(ErrorCode::Io, name, "cannot write: " + out->geterror());
  if (!out->close()) throw Error(ErrorCode::Io, name, "cannot close: " + out->geterror());
}

Pixels readFile(const std::string& file) {
  auto in = OIIO::ImageInput::open(file);
  if (!in) throw Error(ErrorCode::Io, file, "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1 || spec.depth > 1)
    throw Error(ErrorCode::InvalidData, file, "not a 2D image with channels");
  if (static_cast<double>(spec.width) * spec.height > 1 << 28) throw Error(ErrorCode::InvalidData, file, "image too large");
  Pixels px;
  px.width = spec.width;
  px.height = spec.height;
  px.channels = spec.nchannels;
  px.floatSource = true;
  px.page = spec.get_int_attribute("irbake:page", 0);
  px.f32.resize(static_cast<size_t>(px.width) * px.height * px.channels);
  if (!in->read_image(0, 0, 0, px.channels, OIIO::TypeDesc::FLOAT, px.f32.data()))
    throw Error(ErrorCode::Io, file, "cannot decode: " + in->geterror());
  in->close();
  return px;
}

}  // namespace
}  // namespace irbake::imageio

IRBAKE_IMAGEIO_PLUGIN_ENTRY(irbake::imageio::decodeMemory, irbake::imageio::encodePngMemory, irbake::imageio::writeFile,
                            irbake::imageio::readFile)
