// A stand-in for libirbake_imageio_oiio.so on machines without OpenImageIO (a GPU machine that gets only the
// bundle: OpenImageIO and its libraries are far larger than the rest of it). Bench use only, built by
// bench/gpu/make_bundle.sh; the project's plugin stays the OpenImageIO one.
//   decode: PNG, JPEG (8-bit) and Radiance HDR through Debian's libstb (stb_image), declared below since
//           Debian ships the library without headers;
//   encode: PNG through stb_image_write;
//   EXR:    our own writer and reader for the one layout irbake writes: single-part scanline, no
//           compression, FLOAT channels (OpenEXR file layout: openexr.com, "OpenEXR File Layout").
// Pixels and the irbake:page / irbake:content attributes as the OpenImageIO plugin writes them, so
// `irbake diff` and `merge` read these files; the bytes differ (no DateTime, other attribute order).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "common/error.h"
#include "imageio/image_io.h"

extern "C" {
unsigned char* stbi_load_from_memory(const unsigned char* buffer, int len, int* x, int* y, int* comp, int req);
float* stbi_loadf_from_memory(const unsigned char* buffer, int len, int* x, int* y, int* comp, int req);
void stbi_image_free(void* p);
const char* stbi_failure_reason(void);
typedef void stbi_write_func(void* context, void* data, int size);
int stbi_write_png_to_func(stbi_write_func* func, void* context, int w, int h, int comp, const void* data, int stride);
extern int stbi_write_png_compression_level;
}

namespace irbake::imageio {
namespace {

Pixels decodeMemory(const uint8_t* bytes, size_t size, const char* format, const std::string& name) {
  const std::string f = format;
  Pixels px;
  int w = 0, h = 0, c = 0;
  if (f == "png" || f == "jpeg") {
    unsigned char* p = stbi_load_from_memory(bytes, int(size), &w, &h, &c, 0);
    if (!p) throw Error(ErrorCode::InvalidData, name, std::string("cannot decode image: ") + stbi_failure_reason());
    px.u8.assign(p, p + size_t(w) * h * c);
    stbi_image_free(p);
  } else if (f == "hdr") {
    float* p = stbi_loadf_from_memory(bytes, int(size), &w, &h, &c, 0);
    if (!p) throw Error(ErrorCode::InvalidData, name, std::string("cannot decode image: ") + stbi_failure_reason());
    px.f32.assign(p, p + size_t(w) * h * c);
    px.floatSource = true;
    stbi_image_free(p);
  } else {
    throw Error(ErrorCode::InvalidData, name, "the minimal image plugin decodes PNG, JPEG and HDR only, not " + f);
  }
  px.width = w;
  px.height = h;
  px.channels = c;
  return px;
}

void appendBytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
}

std::vector<uint8_t> encodePngMemory(const uint8_t* rgba, int width, int height, const std::string& name) {
  std::vector<uint8_t> out;
  stbi_write_png_compression_level = 3;
  if (!stbi_write_png_to_func(appendBytes, &out, width, height, 4, rgba, width * 4))
    throw Error(ErrorCode::Io, name, "cannot encode PNG");
  return out;
}

const char* channelName(int i, int n) {
  static const char* rgba[] = {"R", "G", "B", "A"};
  if (n == 1) return "Y";
  return rgba[i];
}

template <class T>
void put(std::vector<uint8_t>& b, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}
void putString(std::vector<uint8_t>& b, const std::string& s) {
  b.insert(b.end(), s.begin(), s.end());
  b.push_back(0);
}
void attribute(std::vector<uint8_t>& b, const std::string& name, const std::string& type, const std::vector<uint8_t>& value) {
  putString(b, name);
  putString(b, type);
  put<int32_t>(b, int32_t(value.size()));
  b.insert(b.end(), value.begin(), value.end());
}

void writeExr(const std::string& file, const Pixels& px, int page, const std::string& name) {
  const int n = px.channels, w = px.width, h = px.height;
  if (n < 1 || n > 4 || px.f32.size() != size_t(w) * h * n)
    throw Error(ErrorCode::Io, name, "the minimal image plugin writes 1 to 4 float channels");
  // Channels in the file are sorted by name; order[k] = the interleaved index of the k-th file channel.
  std::map<std::string, int> sorted;
  for (int i = 0; i < n; ++i) sorted[channelName(i, n)] = i;
  std::vector<int> order;
  std::vector<uint8_t> head = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0}, v;
  for (auto& [cname, i] : sorted) {
    order.push_back(i);
    putString(v, cname);
    put<int32_t>(v, 2);  // FLOAT
    v.insert(v.end(), {0, 0, 0, 0});  // pLinear, reserved
    put<int32_t>(v, 1);
    put<int32_t>(v, 1);
  }
  v.push_back(0);
  attribute(head, "channels", "chlist", v);
  attribute(head, "compression", "compression", {0});
  v.clear();
  for (int32_t x : {0, 0, w - 1, h - 1}) put(v, x);
  attribute(head, "dataWindow", "box2i", v);
  attribute(head, "displayWindow", "box2i", v);
  attribute(head, "lineOrder", "lineOrder", {0});
  v.clear();
  put<float>(v, 1.0f);
  attribute(head, "pixelAspectRatio", "float", v);
  attribute(head, "screenWindowWidth", "float", v);
  v.clear();
  put<float>(v, 0.0f);
  put<float>(v, 0.0f);
  attribute(head, "screenWindowCenter", "v2f", v);
  if (page >= 0) {
    v.clear();
    put<int32_t>(v, page);
    attribute(head, "irbake:page", "int", v);
    const std::string content = "irradiance/pi, linear";
    attribute(head, "irbake:content", "string", std::vector<uint8_t>(content.begin(), content.end()));
  }
  head.push_back(0);
  const uint64_t lineBytes = 8 + uint64_t(w) * n * 4;
  // The offset table: one absolute offset per scanline (one line per block without compression).
  const uint64_t firstLine = head.size() + uint64_t(h) * 8;
  for (int y = 0; y < h; ++y) put<uint64_t>(head, firstLine + uint64_t(y) * lineBytes);
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(ErrorCode::Io, name, "cannot open for writing");
  out.write(reinterpret_cast<const char*>(head.data()), std::streamsize(head.size()));
  std::vector<float> line(size_t(w) * n);
  for (int y = 0; y < h; ++y) {
    const int32_t hdr[2] = {y, int32_t(size_t(w) * n * 4)};
    out.write(reinterpret_cast<const char*>(hdr), 8);
    for (int k = 0; k < n; ++k)
      for (int x = 0; x < w; ++x) line[size_t(k) * w + x] = px.f32[(size_t(y) * w + x) * n + order[k]];
    out.write(reinterpret_cast<const char*>(line.data()), std::streamsize(line.size() * 4));
  }
  if (!out) throw Error(ErrorCode::Io, name, "cannot write");
}

void writeFile(const std::string& file, const char* format, const Pixels& px, int page, const std::string& name) {
  if (std::string(format) == "openexr") return writeExr(file, px, page, name);
  if (std::string(format) == "png" && !px.u8.empty() && px.channels == 4) {
    const auto bytes = encodePngMemory(px.u8.data(), px.width, px.height, name);
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) throw Error(ErrorCode::Io, name, "cannot write");
    return;
  }
  throw Error(ErrorCode::Io, name, std::string("the minimal image plugin cannot write ") + format);
}

// Reads the files writeExr writes (uncompressed scanline FLOAT channels); anything else is refused.
Pixels readFile(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (b.size() < 8 || b[0] != 0x76 || b[1] != 0x2f || b[2] != 0x31 || b[3] != 0x01)
    throw Error(ErrorCode::Io, file, "not an OpenEXR file (the minimal image plugin reads its own EXRs only)");
  size_t at = 8;
  auto cstr = [&]() {
    const size_t start = at;
    while (at < b.size() && b[at]) ++at;
    if (at >= b.size()) throw Error(ErrorCode::InvalidData, file, "truncated EXR header");
    return std::string(reinterpret_cast<const char*>(b.data() + start), (at++) - start);
  };
  Pixels px;
  px.floatSource = true;
  std::vector<std::string> names;
  int32_t box[4] = {0, 0, -1, -1};
  for (;;) {
    const std::string aname = cstr();
    if (aname.empty()) break;
    const std::string type = cstr();
    int32_t size = 0;
    std::memcpy(&size, b.data() + at, 4);
    at += 4;
    if (size < 0 || at + size_t(size) > b.size()) throw Error(ErrorCode::InvalidData, file, "truncated EXR attribute");
    const uint8_t* v = b.data() + at;
    if (aname == "channels") {
      size_t p = 0;
      while (p < size_t(size) && v[p]) {
        const std::string cname(reinterpret_cast<const char*>(v + p));
        p += cname.size() + 1;
        int32_t t = 0;
        std::memcpy(&t, v + p, 4);
        if (t != 2) throw Error(ErrorCode::InvalidData, file, "the minimal image plugin reads FLOAT channels only");
        p += 16;
        names.push_back(cname);
      }
    } else if (aname == "compression" && v[0] != 0) {
      throw Error(ErrorCode::InvalidData, file, "the minimal image plugin reads uncompressed EXRs only");
    } else if (aname == "dataWindow") {
      std::memcpy(box, v, 16);
    } else if (aname == "irbake:page") {
      std::memcpy(&px.page, v, 4);
    }
    at += size_t(size);
  }
  px.width = box[2] - box[0] + 1;
  px.height = box[3] - box[1] + 1;
  px.channels = int(names.size());
  const int n = px.channels, w = px.width, h = px.height;
  if (n < 1 || n > 4 || w <= 0 || h <= 0) throw Error(ErrorCode::InvalidData, file, "unsupported EXR layout");
  // File channel k → interleaved index (R, G, B, A order; Y alone).
  std::vector<int> dest(n);
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i)
      if (names[k] == channelName(i, n)) dest[k] = i;
  px.f32.assign(size_t(w) * h * n, 0.0f);
  const size_t lineBytes = 8 + size_t(w) * n * 4;
  for (int y = 0; y < h; ++y) {
    uint64_t off = 0;
    std::memcpy(&off, b.data() + at + 8 * size_t(y), 8);
    if (off + lineBytes > b.size()) throw Error(ErrorCode::InvalidData, file, "truncated EXR scanline");
    const uint8_t* line = b.data() + off + 8;
    for (int k = 0; k < n; ++k)
      for (int x = 0; x < w; ++x)
        std::memcpy(&px.f32[(size_t(y) * w + x) * n + dest[k]], line + (size_t(k) * w + x) * 4, 4);
  }
  return px;
}

}  // namespace
}  // namespace irbake::imageio

IRBAKE_IMAGEIO_PLUGIN_ENTRY(irbake::imageio::decodeMemory, irbake::imageio::encodePngMemory, irbake::imageio::writeFile,
                            irbake::imageio::readFile)
