// Compressed glTF → plain glTF in memory. Every buffer view is copied (or, with EXT_meshopt_compression,
// decoded by meshoptimizer) into one new buffer; each KHR_draco_mesh_compression primitive is decoded by
// Draco and its accessors get views of their own over the decoded data, as the extension specifies. The
// result is a GLB container in memory, so tinygltf and the export read it like any file.
#include "scene/gltf_decompress.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include "common/error.h"
#include "scene/gltf_component_types.h"

namespace irbake {

namespace {

using json = nlohmann::json;

// A compressed view whose declared output is more than this many times its compressed bytes is refused
// before anything is allocated: meshoptimizer's codecs cannot reach such a ratio (an attribute stream
// spends at least 2 bits per 16 bytes), so only a broken or hostile file asks for it.
constexpr uint64_t kMaxMeshoptRatio = 256;

const json* extensionOf(const json& object, const char* name) {
  if (!object.is_object()) return nullptr;
  auto e = object.find("extensions");
  if (e == object.end() || !e->is_object()) return nullptr;
  auto x = e->find(name);
  return x == e->end() ? nullptr : &*x;
}

void eraseExtension(json& object, const char* name) {
  auto e = object.find("extensions");
  if (e == object.end() || !e->is_object()) return;
  e->erase(name);
  if (e->empty()) object.erase("extensions");
}

bool lists(const json& root, const char* list, const char* name) {
  auto l = root.find(list);
  return l != root.end() && l->is_array() && std::find(l->begin(), l->end(), json(name)) != l->end();
}

void unlist(json& root, const char* list, const char* name) {
  auto l = root.find(list);
  if (l == root.end() || !l->is_array()) return;
  l->erase(std::remove(l->begin(), l->end(), json(name)), l->end());
  if (l->empty()) root.erase(list);
}

bool anyViewCompressed(const json& root) {
  auto views = root.find("bufferViews");
  if (views == root.end() || !views->is_array()) return false;
  return std::any_of(views->begin(), views->end(), [](const json& v) { return extensionOf(v, kMeshoptCompression) != nullptr; });
}

bool anyPrimitiveCompressed(const json& root) {
  auto meshes = root.find("meshes");
  if (meshes == root.end() || !meshes->is_array()) return false;
  for (const json& m : *meshes) {
    if (!m.is_object() || !m.contains("primitives") || !m["primitives"].is_array()) continue;
    for (const json& p : m["primitives"])
      if (extensionOf(p, kDracoCompression)) return true;
  }
  return false;
}

// Members read before tinygltf has checked their types: a wrong type gives the fallback (and then a
// refusal naming it), never a JSON exception.
size_t sizeOr(const json& object, const char* key, size_t fallback) {
  auto it = object.is_object() ? object.find(key) : object.end();
  if (!object.is_object() || it == object.end() || !it->is_number() || !(it->get<double>() >= 0.0)) return fallback;
  return it->is_number_unsigned() ? it->get<size_t>() : static_cast<size_t>(it->get<double>());
}

std::string stringOr(const json& object, const char* key) {
  auto it = object.is_object() ? object.find(key) : object.end();
  return object.is_object() && it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

json memberOrNull(const json& object, const char* key) {
  return object.is_object() && object.contains(key) ? object[key] : json();
}

// One value of a Draco attribute as the accessor's component type, into `out`.
bool convertDracoValue(const draco::PointAttribute& a, draco::AttributeValueIndex i, int componentType, int n, uint8_t* out) {
  switch (componentType) {
    case 5120: return a.ConvertValue<int8_t>(i, static_cast<int8_t>(n), reinterpret_cast<int8_t*>(out));
    case 5121: return a.ConvertValue<uint8_t>(i, static_cast<int8_t>(n), out);
    case 5122: { int16_t v[16]; bool ok = a.ConvertValue<int16_t>(i, static_cast<int8_t>(n), v); std::memcpy(out, v, 2 * n); return ok; }
    case 5123: { uint16_t v[16]; bool ok = a.ConvertValue<uint16_t>(i, static_cast<int8_t>(n), v); std::memcpy(out, v, 2 * n); return ok; }
    case 5125: { uint32_t v[16]; bool ok = a.ConvertValue<uint32_t>(i, static_cast<int8_t>(n), v); std::memcpy(out, v, 4 * n); return ok; }
    case 5126: { float v[16]; bool ok = a.ConvertValue<float>(i, static_cast<int8_t>(n), v); std::memcpy(out, v, 4 * n); return ok; }
    default: return false;
  }
}

class Decompressor {
 public:
  explicit Decompressor(GltfSource& s) : s_(s), root_(s.json) {}

  GltfSource run() {
    const bool meshopt = lists(root_, "extensionsUsed", kMeshoptCompression) || lists(root_, "extensionsRequired", kMeshoptCompression) ||
                         anyViewCompressed(root_);
    const bool draco = lists(root_, "extensionsUsed", kDracoCompression) || lists(root_, "extensionsRequired", kDracoCompression) ||
                       anyPrimitiveCompressed(root_);
    readBuffers();
    copyViews();
    decodeDracoPrimitives();
    GltfSource out;
    out.path = s_.path;
    out.folder = s_.folder;
    out.decodedExtensions = s_.decodedExtensions;
    for (const auto& [used, name] : {std::pair{meshopt, kMeshoptCompression}, std::pair{draco, kDracoCompression}}) {
      if (!used) continue;
      unlist(root_, "extensionsUsed", name);
      unlist(root_, "extensionsRequired", name);
      out.decodedExtensions.push_back(name);
    }
    if (bin_.empty()) root_.erase("buffers");
    else root_["buffers"] = json::array({json::object({{"byteLength", bin_.size()}})});
    writeGlb(out);
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& message) const { throw Error(ErrorCode::InvalidData, s_.path.string(), message); }

  // Each buffer's bytes (readGltfSource checked every URI and length); a placeholder has none.
  void readBuffers() {
    auto buffers = root_.find("buffers");
    if (buffers == root_.end()) return;
    for (size_t i = 0; i < buffers->size(); ++i) {
      const json& b = (*buffers)[i];
      std::vector<uint8_t> bytes;
      const size_t length = sizeOr(b, "byteLength", 0);
      if (b.contains("uri")) {
        const std::string uri = b["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) {
          bytes = decodeDataUri(uri);
        } else {
          std::ifstream in(s_.folder / decodeUriEscapes(uri), std::ios::binary);
          bytes.resize(length);
          if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(length)))
            throw Error(ErrorCode::Io, s_.path.string(), "cannot read buffer " + std::to_string(i) + " ('" + uri + "')");
        }
      } else if (s_.binary && i == 0) {
        bytes.assign(s_.bytes.begin() + s_.binOffset, s_.bytes.begin() + s_.binOffset + s_.binSize);
      } else {
        hasData_.push_back(false);
        buffers_.emplace_back();
        continue;
      }
      if (bytes.size() < length) fail("buffer " + std::to_string(i) + " is shorter than its byteLength");
      bytes.resize(length);
      hasData_.push_back(true);
      buffers_.push_back(std::move(bytes));
    }
  }

  // Every view into the new buffer; a view keeps its offset's remainder mod 16, so accessors inside it
  // stay as aligned as they were.
  void copyViews() {
    auto views = root_.find("bufferViews");
    if (views == root_.end()) return;
    for (size_t i = 0; i < views->size(); ++i) {
      json& v = (*views)[i];
      const size_t offset = sizeOr(v, "byteOffset", 0), length = sizeOr(v, "byteLength", 0);
      const size_t buffer = v["buffer"].get<size_t>();
      std::vector<uint8_t> decoded;
      const uint8_t* data = nullptr;
      if (const json* m = extensionOf(v, kMeshoptCompression)) {
        decoded = decodeMeshopt(i, v, *m);
        data = decoded.data();
      } else {
        if (!hasData_[buffer])
          fail("buffer view " + std::to_string(i) + " reads buffer " + std::to_string(buffer) +
               ", an EXT_meshopt_compression fallback buffer without data, but carries no compressed data of its own");
        data = buffers_[buffer].data() + offset;
      }
      const size_t remainder = decoded.empty() ? offset % 16 : 0;
      while (bin_.size() % 16 != remainder) bin_.push_back(0);
      v["byteOffset"] = bin_.size();
      v["buffer"] = 0;
      bin_.insert(bin_.end(), data, data + length);
      eraseExtension(v, kMeshoptCompression);
    }
    buffers_.clear();
  }

  uint64_t meshoptInteger(const std::string& what, const json& m, const char* key, bool required, uint64_t fallback = 0) const {
    auto it = m.find(key);
    if (it == m.end()) {
      if (required) fail(what + "no '" + key + "'");
      return fallback;
    }
    if (!it->is_number_unsigned()) fail(what + key + " " + it->dump() + " is not a non-negative integer");
    return it->get<uint64_t>();
  }

  // The spec's validity rules for one compressed view, then the decode and its filter.
  std::vector<uint8_t> decodeMeshopt(size_t index, const json& view, const json& m) {
    const std::string what = std::string(kMeshoptCompression) + ": buffer view " + std::to_string(index) + ": ";
    if (!m.is_object()) fail(what + "the extension is not an object");
    const uint64_t buffer = meshoptInteger(what, m, "buffer", true), length = meshoptInteger(what, m, "byteLength", true);
    const uint64_t offset = meshoptInteger(what, m, "byteOffset", false), stride = meshoptInteger(what, m, "byteStride", true);
    const uint64_t count = meshoptInteger(what, m, "count", true);
    const std::string mode = m.contains("mode") && m["mode"].is_string() ? m["mode"].get<std::string>() : m.value("mode", json()).dump();
    const std::string filter = m.contains("filter") ? (m["filter"].is_string() ? m["filter"].get<std::string>() : m["filter"].dump()) : "NONE";
    if (buffer >= hasData_.size()) fail(what + "buffer " + std::to_string(buffer) + " is out of range");
    if (!hasData_[buffer]) fail(what + "its compressed data lies in buffer " + std::to_string(buffer) + ", which has no data (a fallback buffer)");
    if (offset + length > buffers_[buffer].size())
      fail(what + "compressed bytes " + std::to_string(offset) + ".." + std::to_string(offset + length) + " lie outside buffer " +
           std::to_string(buffer) + " (" + std::to_string(buffers_[buffer].size()) + " bytes)");
    if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
      fail(what + "mode " + mode + " is not ATTRIBUTES, TRIANGLES or INDICES");
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
      fail(what + "filter " + filter + " is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
    const std::string strideText = "byteStride " + std::to_string(stride);
    if (mode == "ATTRIBUTES" && (stride == 0 || stride % 4 != 0 || stride > 256))
      fail(what + strideText + ": mode ATTRIBUTES needs a multiple of 4 up to 256");
    if (mode != "ATTRIBUTES" && stride != 2 && stride != 4) fail(what + strideText + ": mode " + mode + " needs 2 or 4");
    if (mode == "TRIANGLES" && count % 3 != 0) fail(what + "count " + std::to_string(count) + ": mode TRIANGLES needs a multiple of 3");
    if (mode != "ATTRIBUTES" && filter != "NONE") fail(what + "filter " + filter + " with mode " + mode + " (filters apply to ATTRIBUTES only)");
    if ((filter == "OCTAHEDRAL" && stride != 4 && stride != 8) || (filter == "QUATERNION" && stride != 8))
      fail(what + strideText + " does not suit filter " + filter);
    if (view.contains("byteStride") && view["byteStride"] != stride)
      fail(what + strideText + " differs from the view's byteStride " + view["byteStride"].dump());
    const uint64_t size = stride * count;
    if (view.value("byteLength", json()) != size)
      fail(what + "the view's byteLength " + view.value("byteLength", json()).dump() + " is not byteStride × count = " + std::to_string(size));
    if (size > kMaxMeshoptRatio * length + 4096)
      fail(what + std::to_string(size) + " decoded bytes from " + std::to_string(length) + " compressed bytes: the stream is broken");
    std::vector<uint8_t> out(size);
    const uint8_t* src = buffers_[buffer].data() + offset;
    int rc = mode == "ATTRIBUTES" ? meshopt_decodeVertexBuffer(out.data(), count, stride, src, length)
           : mode == "TRIANGLES"  ? meshopt_decodeIndexBuffer(out.data(), count, stride, src, length)
                                  : meshopt_decodeIndexSequence(out.data(), count, stride, src, length);
    if (rc != 0) fail(what + "the " + mode + " stream does not decode (meshoptimizer error " + std::to_string(rc) + ")");
    if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
    if (filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
    if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
    return out;
  }

  void decodeDracoPrimitives() {
    auto meshes = root_.find("meshes");
    if (meshes == root_.end() || !meshes->is_array()) return;
    for (size_t m = 0; m < meshes->size(); ++m) {
      json& mesh = (*meshes)[m];
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
        json& prim = mesh["primitives"][p];
        if (!extensionOf(prim, kDracoCompression)) continue;
        decodeDraco(std::string(kDracoCompression) + ": mesh " + std::to_string(m) + " primitive " + std::to_string(p) + ": ", prim);
        eraseExtension(prim, kDracoCompression);
      }
    }
  }

  const json& accessor(const std::string& what, const json& index) const {
    auto accessors = root_.find("accessors");
    if (!index.is_number_unsigned() || accessors == root_.end() || !accessors->is_array() || index.get<size_t>() >= accessors->size())
      fail(what + "accessor " + index.dump() + " is out of range");
    return (*accessors)[index.get<size_t>()];
  }

  // A new view over `bytes` for the accessor: the accessor reads it from offset 0.
  void pointAccessorAt(size_t accessorIndex, const std::vector<uint8_t>& bytes, size_t stride) {
    while (bin_.size() % 16) bin_.push_back(0);
    json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes.size()}};
    if (stride) view["byteStride"] = stride;
    bin_.insert(bin_.end(), bytes.begin(), bytes.end());
    if (!root_.contains("bufferViews")) root_["bufferViews"] = json::array();
    root_["bufferViews"].push_back(view);
    json& a = root_["accessors"][accessorIndex];
    a["bufferView"] = root_["bufferViews"].size() - 1;
    a.erase("byteOffset");
  }

  std::unique_ptr<draco::Mesh> decodeDracoStream(const std::string& what, const json& ext) const {
    if (!ext.is_object() || !ext.contains("bufferView") || !ext["bufferView"].is_number_unsigned() || !root_.contains("bufferViews") ||
        ext["bufferView"].get<size_t>() >= root_["bufferViews"].size())
      fail(what + "bufferView " + ext.value("bufferView", json()).dump() + " is missing or out of range");
    const size_t viewIndex = ext["bufferView"].get<size_t>();
    const json& view = root_["bufferViews"][viewIndex];
    draco::DecoderBuffer stream;
    stream.Init(reinterpret_cast<const char*>(bin_.data() + sizeOr(view, "byteOffset", 0)), sizeOr(view, "byteLength", 0));
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&stream);
    if (!decoded.ok())
      fail(what + "the Draco stream in buffer view " + std::to_string(viewIndex) + " does not decode (" + decoded.status().error_msg_string() + ")");
    return std::move(decoded).value();
  }

  void decodeDraco(const std::string& what, json& prim) {
    const json& ext = *extensionOf(prim, kDracoCompression);
    const int mode = prim.value("mode", json(4)).is_number_integer() ? prim.value("mode", json(4)).get<int>() : -1;
    if (mode != 4 && mode != 5) fail(what + "mode " + prim.value("mode", json()).dump() + ": a Draco mesh decodes to triangles");
    if (!ext.is_object() || !ext.contains("attributes") || !ext["attributes"].is_object()) fail(what + "no 'attributes' map");
    std::unique_ptr<draco::Mesh> mesh = decodeDracoStream(what, ext);
    const json& attributes = prim.value("attributes", json::object());
    for (const auto& [semantic, id] : ext["attributes"].items()) {
      if (!attributes.contains(semantic)) fail(what + "attribute " + semantic + " is in the Draco map but not in the primitive");
      if (!attributes[semantic].is_number_unsigned()) fail(what + "attribute " + semantic + " names no accessor");
      const size_t a = attributes[semantic].get<size_t>();
      const std::string where = what + "accessor " + std::to_string(a) + " (" + semantic + "): ";
      const draco::PointAttribute* source = id.is_number_unsigned() ? mesh->GetAttributeByUniqueId(id.get<uint32_t>()) : nullptr;
      if (!source) fail(where + "Draco attribute id " + id.dump() + " is not in the stream");
      writeDracoAttribute(where, a, *source, mesh->num_points());
    }
    writeDracoIndices(what, prim, *mesh);
    prim["mode"] = 4;
  }

  void writeDracoAttribute(const std::string& where, size_t index, const draco::PointAttribute& source, uint32_t points) {
    const json& a = accessor(where, json(index));
    const int type = static_cast<int>(sizeOr(a, "componentType", 0)), n = static_cast<int>(gltfComponentCount(stringOr(a, "type")));
    const size_t element = gltfComponentSize(type) * n, stride = (element + 3) / 4 * 4;
    if (element == 0)
      fail(where + "componentType " + memberOrNull(a, "componentType").dump() + " / type " + memberOrNull(a, "type").dump() + " is not readable");
    if (memberOrNull(a, "count") != points)
      fail(where + "count " + memberOrNull(a, "count").dump() + ", but the Draco stream decodes " + std::to_string(points) + " points");
    std::vector<uint8_t> bytes(stride * points, 0);
    for (uint32_t i = 0; i < points; ++i)
      if (!convertDracoValue(source, source.mapped_index(draco::PointIndex(i)), type, n, bytes.data() + stride * i))
        fail(where + "the Draco attribute cannot be read as componentType " + std::to_string(type));
    pointAccessorAt(index, bytes, stride == element && n == 1 ? 0 : stride);
  }

  void writeDracoIndices(const std::string& what, json& prim, const draco::Mesh& mesh) {
    const uint64_t count = uint64_t(mesh.num_faces()) * 3;
    if (!prim.contains("indices")) {  // the decoded faces index the decoded points: they need an accessor
      root_["accessors"].push_back({{"componentType", 5125}, {"type", "SCALAR"}, {"count", count}});
      prim["indices"] = root_["accessors"].size() - 1;
    }
    const size_t index = prim["indices"].is_number_unsigned() ? prim["indices"].get<size_t>() : size_t(-1);
    const std::string where = what + "accessor " + prim["indices"].dump() + " (indices): ";
    const json& a = accessor(where, prim["indices"]);
    const int type = static_cast<int>(sizeOr(a, "componentType", 0));
    const size_t size = gltfComponentSize(type);
    if (stringOr(a, "type") != "SCALAR" || (type != 5121 && type != 5123 && type != 5125))
      fail(where + "indices must be unsigned SCALAR");
    if (memberOrNull(a, "count") != count)
      fail(where + "count " + memberOrNull(a, "count").dump() + ", but the Draco stream decodes " + std::to_string(count) + " indices");
    const uint64_t limit = size == 4 ? 0xFFFFFFFFull : (uint64_t(1) << (8 * size)) - 1;
    std::vector<uint8_t> bytes(count * size);
    for (uint32_t f = 0; f < mesh.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = mesh.face(draco::FaceIndex(f))[k].value();
        if (v > limit) fail(where + "index " + std::to_string(v) + " does not fit componentType " + std::to_string(type));
        std::memcpy(bytes.data() + (uint64_t(f) * 3 + k) * size, &v, size);  // little-endian: the low bytes
      }
    pointAccessorAt(index, bytes, 0);
  }

  // The document as a GLB container: JSON chunk (space-padded), BIN chunk (zero-padded).
  void writeGlb(GltfSource& out) {
    std::string text = root_.dump();
    while (text.size() % 4) text.push_back(' ');
    while (bin_.size() % 4) bin_.push_back(0);
    const auto u32 = [&](uint32_t v) {
      uint8_t b[4];
      std::memcpy(b, &v, 4);
      out.bytes.insert(out.bytes.end(), b, b + 4);
    };
    const size_t total = 12 + 8 + text.size() + (bin_.empty() ? 0 : 8 + bin_.size());
    if (total > 0xFFFFFFFFull) fail("the decoded scene is larger than a GLB container can hold (4 GiB)");
    out.bytes.reserve(total);
    out.bytes.insert(out.bytes.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(static_cast<uint32_t>(total));
    u32(static_cast<uint32_t>(text.size()));
    u32(0x4E4F534Au);
    out.jsonOffset = out.bytes.size();
    out.jsonSize = text.size();
    out.bytes.insert(out.bytes.end(), text.begin(), text.end());
    if (!bin_.empty()) {
      u32(static_cast<uint32_t>(bin_.size()));
      u32(0x004E4942u);
      out.binOffset = out.bytes.size();
      out.binSize = bin_.size();
      out.bytes.insert(out.bytes.end(), bin_.begin(), bin_.end());
    }
    out.binary = true;
    out.json = std::move(root_);
  }

  GltfSource& s_;
  json& root_;
  std::vector<std::vector<uint8_t>> buffers_;
  std::vector<bool> hasData_;
  std::vector<uint8_t> bin_;
};

}  // namespace

GltfSource decompressGltf(GltfSource source) {
  const json& root = source.json;
  const bool compressed = lists(root, "extensionsUsed", kMeshoptCompression) || lists(root, "extensionsRequired", kMeshoptCompression) ||
                          lists(root, "extensionsUsed", kDracoCompression) || lists(root, "extensionsRequired", kDracoCompression) ||
                          anyViewCompressed(root) || anyPrimitiveCompressed(root);
  if (!compressed) return source;
  return Decompressor(source).run();
}

std::string decodedExtensionWarning(const std::string& extension) {
  const std::string how = extension == kDracoCompression ? "gltf-transform draco" : "gltf-transform meshopt";
  return "input used " + extension + "; the output is uncompressed — recompress with " + how;
}

}  // namespace irbake
