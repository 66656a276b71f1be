#include "scene/gltf_source.h"

#include <cmath>
#include <cstring>
#include <sstream>
#include <fstream>
#include <system_error>

#include "common/error.h"

namespace irbake {

namespace {

// A buffer or accessor larger than this is refused outright: no real scene comes near it, and
// trusting it would mean multi-gigabyte allocations from a few bytes of JSON.
constexpr uint64_t kAbsurdBytes = uint64_t(1) << 34;  // 16 GiB

uint32_t readU32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;  // GLB is little-endian, as is every machine we build for
}

[[noreturn]] void fail(ErrorCode code, const GltfSource& s, const std::string& message) {
  throw Error(code, s.path.string(), message);
}

// A byte count from the JSON for a message: an integer where it is one, else as written (1e+39): a
// double beyond 2^64 cast to an integer is undefined behaviour (found by tests/fuzz).
std::string byteCount(double bytes) {
  if (bytes >= 0.0 && bytes < 18446744073709549568.0 && bytes == std::floor(bytes))
    return std::to_string(static_cast<uint64_t>(bytes));
  std::ostringstream out;
  out << bytes;
  return out.str();
}

std::string firstLine(std::string s) {
  size_t nl = s.find('\n');
  if (nl != std::string::npos) s.resize(nl);
  return s;
}

// Decoded size of a base64 data URI payload (without decoding it).
uint64_t dataUriPayloadSize(const std::string& uri) {
  size_t comma = uri.find(',');
  if (comma == std::string::npos) return 0;
  uint64_t n = uri.size() - comma - 1;
  uint64_t pad = 0;
  if (n >= 1 && uri[uri.size() - 1] == '=') ++pad;
  if (n >= 2 && uri[uri.size() - 2] == '=') ++pad;
  return n / 4 * 3 - pad;
}

void checkUri(const GltfSource& s, const std::string& what, const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return;
  std::string decoded = decodeUriEscapes(uri);
  if (!uriStaysInFolder(decoded))
    fail(ErrorCode::InvalidData, s, what + " URI '" + uri + "' escapes the scene folder (absolute paths and '..' are refused)");
}

void checkBuffers(const GltfSource& s) {
  const auto& j = s.json;
  if (!j.contains("buffers")) return;
  if (!j["buffers"].is_array()) fail(ErrorCode::Parse, s, "'buffers' is not an array");
  const auto& buffers = j["buffers"];
  for (size_t i = 0; i < buffers.size(); ++i) {
    const auto& b = buffers[i];
    std::string what = "buffer " + std::to_string(i);
    if (!b.is_object() || !b.contains("byteLength") || !b["byteLength"].is_number())
      fail(ErrorCode::Parse, s, what + " has no numeric byteLength");
    double declaredD = b["byteLength"].get<double>();
    if (!(declaredD >= 0.0)) fail(ErrorCode::InvalidData, s, what + " has a negative byteLength");
    if (declaredD > static_cast<double>(kAbsurdBytes))
      fail(ErrorCode::InvalidData, s, what + " declares an absurd size (byteLength " + b["byteLength"].dump() + ")");
    uint64_t declared = static_cast<uint64_t>(declaredD);
    uint64_t actual = 0;
    std::string where;
    if (b.contains("uri")) {
      if (!b["uri"].is_string()) fail(ErrorCode::Parse, s, what + " uri is not a string");
      std::string uri = b["uri"].get<std::string>();
      checkUri(s, what, uri);
      if (uri.rfind("data:", 0) == 0) {
        actual = dataUriPayloadSize(uri);
        where = "data URI";
      } else {
        std::filesystem::path file = s.folder / decodeUriEscapes(uri);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec))
          fail(ErrorCode::Io, s, "missing buffer: " + what + " file '" + uri + "' not found");
        actual = std::filesystem::file_size(file, ec);
        where = "'" + uri + "'";
      }
    } else if (s.binary && i == 0) {
      actual = s.binSize;
      where = "GLB BIN chunk";
    } else if (isMeshoptPlaceholder(j, i)) {
      continue;  // no data: what reads it is decoded from elsewhere (scene/gltf_decompress.h)
    } else {
      fail(ErrorCode::InvalidData, s, "missing buffer: " + what + " has no uri and no GLB BIN chunk");
    }
    if (actual < declared)
      fail(ErrorCode::InvalidData, s,
           "short buffer: " + what + " (" + where + ") has " + std::to_string(actual) + " bytes, byteLength says " +
               std::to_string(declared));
  }
}

// tinygltf hands image buffer views to the image callback without a bounds check: check every view
// against its buffer's declared length (already known to be no longer than the real data).
void checkBufferViews(const GltfSource& s) {
  const auto& j = s.json;
  if (!j.contains("bufferViews")) return;
  if (!j["bufferViews"].is_array()) fail(ErrorCode::Parse, s, "'bufferViews' is not an array");
  const size_t bufferCount = j.contains("buffers") ? j["buffers"].size() : 0;
  const auto& views = j["bufferViews"];
  for (size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    std::string what = "buffer view " + std::to_string(i);
    if (!v.is_object() || !v.contains("buffer") || !v["buffer"].is_number_integer())
      fail(ErrorCode::Parse, s, what + " has no integer 'buffer'");
    int64_t b = v["buffer"].get<int64_t>();
    if (b < 0 || static_cast<size_t>(b) >= bufferCount)
      fail(ErrorCode::InvalidData, s, what + " references buffer " + std::to_string(b) + ", out of range");
    double offset = v.contains("byteOffset") && v["byteOffset"].is_number() ? v["byteOffset"].get<double>() : 0.0;
    double length = v.contains("byteLength") && v["byteLength"].is_number() ? v["byteLength"].get<double>() : -1.0;
    double bufferLength = j["buffers"][b]["byteLength"].get<double>();
    if (offset < 0.0 || length < 0.0) fail(ErrorCode::InvalidData, s, what + " has a negative or missing byteOffset/byteLength");
    if (offset + length > bufferLength)
      fail(ErrorCode::InvalidData, s,
           what + " is out of bounds: bytes " + byteCount(offset) + ".." + byteCount(offset + length) + " of buffer " +
               std::to_string(b) + " (" + byteCount(bufferLength) + " bytes)");
  }
}

void checkImages(const GltfSource& s) {
  const auto& j = s.json;
  if (!j.contains("images") || !j["images"].is_array()) return;
  const auto& images = j["images"];
  for (size_t i = 0; i < images.size(); ++i)
    if (images[i].is_object() && images[i].contains("uri") && images[i]["uri"].is_string())
      checkUri(s, "image " + std::to_string(i), images[i]["uri"].get<std::string>());
}

void checkRootExtras(const GltfSource& s) {
  const auto& j = s.json;
  if (!j.contains("extras") || !j["extras"].is_object() || !j["extras"].contains("lightmapPages")) return;
  const auto& pages = j["extras"]["lightmapPages"];
  if (!pages.is_array()) return;
  for (const auto& p : pages)
    if (p.is_string()) checkUri(s, "lightmap page", p.get<std::string>());
}

void splitGlb(GltfSource& s) {
  const auto& b = s.bytes;
  if (b.size() < 20) fail(ErrorCode::Parse, s, "bad GLB container: file is only " + std::to_string(b.size()) + " bytes");
  uint32_t version = readU32(&b[4]), length = readU32(&b[8]);
  if (version != 2) fail(ErrorCode::Parse, s, "bad GLB container: version " + std::to_string(version) + " (only 2 is supported)");
  if (length > b.size())
    fail(ErrorCode::Parse, s, "bad GLB container: header says " + std::to_string(length) + " bytes, file has " + std::to_string(b.size()));
  uint32_t jsonLen = readU32(&b[12]), jsonType = readU32(&b[16]);
  if (jsonType != 0x4E4F534Au) fail(ErrorCode::Parse, s, "bad GLB container: first chunk is not JSON");
  if (uint64_t(20) + jsonLen > length) fail(ErrorCode::Parse, s, "bad GLB container: JSON chunk runs past the end of the file");
  s.jsonOffset = 20;
  s.jsonSize = jsonLen;
  uint64_t next = 20 + uint64_t(jsonLen);
  next = (next + 3) & ~uint64_t(3);
  if (next + 8 <= length) {
    uint32_t binLen = readU32(&b[next]), binType = readU32(&b[next + 4]);
    if (binType == 0x004E4942u) {
      if (next + 8 + binLen > length) fail(ErrorCode::Parse, s, "bad GLB container: BIN chunk runs past the end of the file");
      s.binOffset = next + 8;
      s.binSize = binLen;
    }
  }
}

}  // namespace

std::vector<uint8_t> decodeDataUri(const std::string& uri) {
  size_t comma = uri.find(',');
  if (comma == std::string::npos || uri.find(";base64") == std::string::npos) return {};
  // Plain RFC 4648 base64 (the only data URI encoding glTF allows).
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    char c = uri[i];
    int v = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52
          : c == '+' ? 62 : c == '/' ? 63 : -1;
    if (v < 0) continue;  // padding and whitespace
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

bool isMeshoptPlaceholder(const nlohmann::json& j, size_t index) {
  const auto meshopt = [](const nlohmann::json& object) -> const nlohmann::json* {
    if (!object.is_object() || !object.contains("extensions") || !object["extensions"].is_object()) return nullptr;
    const auto& e = object["extensions"];
    return e.contains("EXT_meshopt_compression") ? &e["EXT_meshopt_compression"] : nullptr;
  };
  if (!j.contains("buffers") || !j["buffers"].is_array() || index >= j["buffers"].size()) return false;
  const auto& buffer = j["buffers"][index];
  if (!buffer.is_object() || buffer.contains("uri")) return false;
  const nlohmann::json* tag = meshopt(buffer);
  if (tag && tag->is_object() && tag->contains("fallback") && (*tag)["fallback"] == true) return true;
  // Untagged: a placeholder only when every view that reads it carries its own compressed data.
  if (!j.contains("bufferViews") || !j["bufferViews"].is_array()) return false;
  bool read = false;
  for (const auto& v : j["bufferViews"]) {
    if (!v.is_object() || !v.contains("buffer") || v["buffer"] != index) continue;
    if (!meshopt(v)) return false;
    read = true;
  }
  return read;
}

std::string decodeUriEscapes(const std::string& uri) {
  std::string out;
  out.reserve(uri.size());
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out.push_back(static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2])));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

bool uriStaysInFolder(const std::string& uri) {
  if (uri.empty()) return false;
  if (uri[0] == '/' || uri[0] == '\\' || uri[0] == '~') return false;
  // A scheme ("file:", "http:") or a drive letter ("C:") is never a relative reference.
  size_t colon = uri.find(':'), slash = uri.find_first_of("/\\");
  if (colon != std::string::npos && (slash == std::string::npos || colon < slash)) return false;
  size_t start = 0;
  while (start <= uri.size()) {
    size_t end = uri.find_first_of("/\\", start);
    if (end == std::string::npos) end = uri.size();
    if (uri.compare(start, end - start, "..") == 0 && end - start == 2) return false;
    start = end + 1;
  }
  return uri.find('\0') == std::string::npos;
}

// Arrays and objects nested deeper than this are refused before any JSON parser sees them: tinygltf
// parses recursively and overflows the stack (SIGSEGV) on an `extras` that nests 200,000 arrays.
// Real glTF nests about 8 levels; 64 leaves room for generous extras.
constexpr int kMaxJsonDepth = 64;

// One pass over the JSON text counting brackets outside strings (escapes inside strings skipped).
void checkJsonDepth(const GltfSource& s, const char* text, size_t size) {
  int depth = 0;
  bool inString = false;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') ++i;  // the escaped character cannot end the string
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        fail(ErrorCode::InvalidData, s, "JSON nests deeper than " + std::to_string(kMaxJsonDepth) +
                                            " arrays/objects (at byte " + std::to_string(s.jsonOffset + i) + ")");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

GltfSource readGltfSource(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(ErrorCode::Io, path.string(), "cannot read file: no such file");
  if (std::filesystem::is_directory(path, ec)) throw Error(ErrorCode::Io, path.string(), "cannot read file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::Io, path.string(), "cannot read file: permission denied or unreadable");
  in.seekg(0, std::ios::end);
  std::streamoff size = in.tellg();
  if (size < 0) throw Error(ErrorCode::Io, path.string(), "cannot read file");
  in.seekg(0);
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size))
    throw Error(ErrorCode::Io, path.string(), "cannot read file: read failed");
  return gltfSourceFromBytes(std::move(bytes), path);
}

GltfSource gltfSourceFromBytes(std::vector<uint8_t> bytes, const std::filesystem::path& path) {
  GltfSource s;
  s.path = path;
  s.folder = path.parent_path();
  s.bytes = std::move(bytes);

  if (s.bytes.size() >= 4 && std::memcmp(s.bytes.data(), "glTF", 4) == 0) {
    s.binary = true;
    splitGlb(s);
  } else {
    size_t first = 0;
    while (first < s.bytes.size() && std::isspace(s.bytes[first])) ++first;
    // A UTF-8 byte order mark is tolerated (some exporters write one).
    if (s.bytes.size() - first >= 3 && s.bytes[first] == 0xEF && s.bytes[first + 1] == 0xBB && s.bytes[first + 2] == 0xBF)
      first += 3;
    if (first >= s.bytes.size() || s.bytes[first] != '{')
      fail(ErrorCode::Parse, s, "not a glTF file (neither a JSON object nor a GLB container)");
    s.jsonOffset = first;
    s.jsonSize = s.bytes.size() - first;
  }
  const char* text = reinterpret_cast<const char*>(s.bytes.data()) + s.jsonOffset;
  checkJsonDepth(s, text, s.jsonSize);
  try {
    s.json = nlohmann::json::parse(text, text + s.jsonSize);
  } catch (const nlohmann::json::exception& e) {
    // parse_error for bad syntax, but also out_of_range (406) for a number too large for a double,
    // e.g. 1E4645: any of them is a malformed document (found by tests/fuzz).
    std::string msg = e.what();
    size_t at = msg.find("] ");
    fail(ErrorCode::Parse, s, "malformed JSON: " + firstLine(at == std::string::npos ? msg : msg.substr(at + 2)));
  }
  if (!s.json.is_object()) fail(ErrorCode::Parse, s, "not a glTF file: the JSON is not an object");
  if (!s.json.contains("asset") || !s.json["asset"].is_object())
    fail(ErrorCode::Parse, s, "not a glTF file: no \"asset\" object");
  const auto& asset = s.json["asset"];
  if (!asset.contains("version") || !asset["version"].is_string() || asset["version"].get<std::string>().rfind("2.", 0) != 0)
    fail(ErrorCode::Parse, s, "not a glTF 2.0 file: asset.version is " + (asset.contains("version") ? asset["version"].dump() : std::string("missing")));
  checkBuffers(s);
  checkBufferViews(s);
  checkImages(s);
  checkRootExtras(s);
  return s;
}

}  // namespace irbake
