// glTF → Scene. Two passes: readGltfSource() checks the container, JSON, URIs and buffers before
// tinygltf reads anything, and decompressGltf() decodes meshopt and Draco data into a plain document;
// tinygltf then parses the document (images kept as encoded bytes), and this file flattens nodes to
// world space while validating accessors, indices and values.
#include "scene/gltf_loader.h"
#include "common/maths.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <tuple>
#include <thread>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include "common/error.h"
#include "common/log.h"
#include "scene/gltf_decompress.h"
#include "scene/gltf_source.h"
#include "scene/ies_lights_gltf.h"
#include "scene/image_codec.h"
#include "scene/moz_lightmap_units.h"
#include "scene/object_settings.h"
#include "scene/runtime_lights.h"
#include "scene/scene_limits.h"

namespace irbake {

namespace {

using json = nlohmann::json;

// Accessors declaring more than this many times their whole buffer are "absurd" rather than merely
// out of bounds: the declared count cannot be a near miss.
constexpr double kAbsurdFactor = 64.0;
constexpr int kMaxNodeDepth = 1024;
constexpr size_t kMaxNodeInstances = 1000000;

// The scene sizes a bake handles (docs/refusals.md), in metres after node transforms. Below 1e-4 m the ray
// tracer's smallest offset (1e-8 m) becomes a visible part of the scene and brightens it.
constexpr double kMinSceneExtent = 1e-4;
// Above 1e9 m a triangle's squared cross product can pass float's 3.4e38: its normal vanishes and Embree
// aborts on the rays built from it. The same bound holds for every vertex and punctual light coordinate.
constexpr double kMaxSceneExtent = 1e9;
constexpr double kMaxCoordinate = kMaxSceneCoordinate;
// A scene farther from the origin than this many times its size gets a warning: float spacing there
// (and the ray tracer's offsets, which follow it) reaches a visible fraction of the scene.
constexpr double kFarFromOriginRatio = 1e4;
// Relative slack on those bounds, so that a scale of exactly 1e-4 or 1e9 (rounded to float) is inside.
constexpr double kBoundSlack = kSceneLimitSlack;

// glTF extensions this loader reads (or, for KHR_mesh_quantization, whose accessor types it reads like
// any other): the only ones a file may list in extensionsRequired.
const char* const kSupportedExtensions[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                            "KHR_materials_transmission", "KHR_mesh_quantization", "MOZ_lightmap",
                                            "IRBAKE_lightmap_directional", "KHR_texture_transform",
                                            "EXT_mesh_gpu_instancing", "EXT_texture_webp", "EXT_lights_ies",
                                            "KHR_materials_pbrSpecularGlossiness"};

// tinygltf image callback: keep the encoded bytes (decoded later, in parallel, only for the images a
// material uses). EXR and unknown formats load too; they are simply recorded.
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

const json* child(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

const json* path(const json& j, std::initializer_list<const char*> keys) {
  const json* cur = &j;
  for (const char* k : keys) {
    cur = child(*cur, k);
    if (!cur) return nullptr;
  }
  return cur;
}

const json* element(const json& j, const char* arrayKey, size_t index) {
  const json* a = child(j, arrayKey);
  if (!a || !a->is_array() || index >= a->size()) return nullptr;
  return &(*a)[index];
}

double numberOr(const json* j, double fallback) { return (j && j->is_number()) ? j->get<double>() : fallback; }

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
  }
  return 0;
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
  }
  return 0;
}

float readComponent(const uint8_t* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? *p / 255.0f : *p;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return static_cast<float>(v);
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0.0f;
}

uint32_t readIndex(const uint8_t* p, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0;
}

WrapMode wrapFromGl(int mode) {
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WrapMode::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WrapMode::MirroredRepeat;
  }
  return WrapMode::Repeat;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Every component finite and ≥ 0 (colours, factors).
bool finiteNonNegative(const glm::vec4& v) {
  for (int c = 0; c < 4; ++c)
    if (!std::isfinite(v[c]) || v[c] < 0.0f) return false;
  return true;
}

// A length in short scientific notation for messages: "3.2e-8", "1e9".
std::string scientific(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1e", x);
  std::string s(text);
  const size_t e = s.find('e');
  if (e == std::string::npos) return s;  // inf or nan
  std::string mantissa = s.substr(0, e);
  if (mantissa.size() >= 2 && mantissa.compare(mantissa.size() - 2, 2, ".0") == 0) mantissa.resize(mantissa.size() - 2);
  return mantissa + "e" + std::to_string(std::stoi(s.substr(e + 1)));
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

std::string rgb(const glm::vec3& c) {
  std::string text = "(";
  text += number(c.x) + ", " + number(c.y) + ", " + number(c.z) + ")";
  return text;
}

// A primitive's data in mesh space, read once per (mesh, primitive) however many nodes instance it.
struct LocalPrimitive {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uv0, uv1;
  std::vector<glm::vec4> tangents;  // TANGENT (LoadOptions::shadingMaps only)
  std::vector<uint32_t> indices;  // triangle list (strips and fans expanded)
  int material = -1;
  LightmapRef lightmap;
  bool skipped = false;           // points or lines
};

class Loader {
 public:
  Loader(GltfSource source, const LoadOptions& options)
      : src_(decompressGltf(std::move(source))), options_(options), file_(src_.path.string()) {}

  Scene load() {
    parseWithTinygltf();
    scene_.sourcePath = file_;
    scene_.stats.decodedExtensions = src_.decodedExtensions;
    for (const std::string& e : src_.decodedExtensions) warn(decodedExtensionWarning(e));
    checkRequiredExtensions();
    materialMap_.assign(model_.materials.size(), -1);
    // Scene material i is glTF material i (the default material, when needed, comes after them).
    for (size_t i = 0; i < model_.materials.size(); ++i) materialIndex(static_cast<int>(i), "scene");
    std::vector<int> roots = rootNodes();
    checkNodeGraph(roots);
    checkInstanceCount(roots);
    for (int r : roots) visitNode(r, glm::mat4(1.0f), 0, ObjectSettings{});
    if (scene_.triangleCount() == 0) {
      std::string why = std::to_string(scene_.stats.primitivesSkipped) + " point/line primitives skipped, " +
                        std::to_string(scene_.stats.trianglesDropped) + " degenerate triangles dropped";
      throw Error(ErrorCode::EmptyScene, file_, "no triangles to bake (" + why + ")");
    }
    checkSceneExtent();
    // Not through warn(): this count must survive its cap on repeated warnings.
    if (scene_.stats.trianglesDropped > 0)
      scene_.stats.warnings.push_back(std::to_string(scene_.stats.trianglesDropped) +
                                      " degenerate triangles (zero area or a repeated corner) dropped");
    decodeTextures();
    readLightmapPages();
    readSky();
    if (options_.shadingMaps) readRuntimeLightsOfExport();
    for (const auto& w : scene_.stats.warnings) log::warn(file_ + ": " + w);
    return std::move(scene_);
  }

 private:
  [[noreturn]] void invalid(const std::string& message) const { throw Error(ErrorCode::InvalidData, file_, message); }

  // glTF 2.0 (3.12): a loader must refuse a file that requires an extension it does not support.
  void checkRequiredExtensions() const {
    const json* required = child(src_.json, "extensionsRequired");
    if (!required) return;
    if (!required->is_array()) invalid("extensionsRequired is not an array");
    for (const json& e : *required) {
      if (!e.is_string()) invalid("extensionsRequired holds a non-string entry " + e.dump());
      const std::string name = e.get<std::string>();
      if (std::find(std::begin(kSupportedExtensions), std::end(kSupportedExtensions), name) == std::end(kSupportedExtensions))
        invalid("the file requires extension " + name + ", which irbake does not support (extensionsRequired)");
    }
  }

  // The flattened scene's size must lie in [kMinSceneExtent, kMaxSceneExtent] (vertex coordinates were
  // checked against kMaxCoordinate as they were transformed).
  void checkSceneExtent() {
    const Bounds3 b = scene_.bounds();
    const glm::vec3 e = b.extent();
    const double extent = std::max({e.x, e.y, e.z});
    if (!(extent >= kMinSceneExtent * (1.0 - kBoundSlack)) || !(extent <= kMaxSceneExtent * (1.0 + kBoundSlack)))
      invalid("scene extent " + scientific(extent) + " m (largest side of its bounding box) is outside the supported " +
              scientific(kMinSceneExtent) + " … " + scientific(kMaxSceneExtent) + " m: rescale the scene (node scale)");
    const double magnitude = std::max(glm::length(b.min), glm::length(b.max));
    if (magnitude > kFarFromOriginRatio * extent)
      warn("the scene lies " + scientific(magnitude) + " m from the origin, " + scientific(magnitude / extent) +
           " times its size: float spacing there is about " + scientific(magnitude * 1.2e-7) +
           " m; move it nearer the origin (node translation)");
  }

  void warn(const std::string& message) {
    // Many identical warnings (one per primitive) are summarised by the count in LoadStats.
    if (scene_.stats.warnings.size() < 32) scene_.stats.warnings.push_back(message);
  }

  void parseWithTinygltf() {
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepEncodedImage, nullptr);
    std::string err, warn;
    bool ok;
    std::string base = src_.folder.string();
    if (src_.binary) {
      ok = gltf.LoadBinaryFromMemory(&model_, &err, &warn, src_.bytes.data(), static_cast<unsigned>(src_.bytes.size()), base,
                                     tinygltf::REQUIRE_VERSION);
    } else {
      ok = gltf.LoadASCIIFromString(&model_, &err, &warn, reinterpret_cast<const char*>(src_.bytes.data()) + src_.jsonOffset,
                                    static_cast<unsigned>(src_.jsonSize), base, tinygltf::REQUIRE_VERSION);
    }
    if (!ok) {
      std::string line = err.substr(0, err.find('\n'));
      throw Error(ErrorCode::Parse, file_, "invalid glTF: " + (line.empty() ? std::string("tinygltf refused the file") : line));
    }
    size_t start = 0;
    while (start < warn.size()) {
      size_t end = warn.find('\n', start);
      if (end == std::string::npos) end = warn.size();
      if (end > start) this->warn(warn.substr(start, end - start));
      start = end + 1;
    }
  }

  std::vector<int> rootNodes() {
    const int nodeCount = static_cast<int>(model_.nodes.size());
    auto checkNode = [&](int n, const std::string& from) {
      if (n < 0 || n >= nodeCount) invalid(from + " references node " + std::to_string(n) + ", out of range (" + std::to_string(nodeCount) + " nodes)");
    };
    for (int i = 0; i < nodeCount; ++i)
      for (int c : model_.nodes[i].children) checkNode(c, "node " + std::to_string(i));
    if (!model_.scenes.empty()) {
      int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (s >= static_cast<int>(model_.scenes.size())) invalid("default scene " + std::to_string(s) + " out of range");
      for (int n : model_.scenes[s].nodes) checkNode(n, "scene " + std::to_string(s));
      return model_.scenes[s].nodes;
    }
    // No scenes: every node that is nobody's child is a root.
    std::vector<char> isChild(nodeCount, 0);
    for (const auto& n : model_.nodes)
      for (int c : n.children) isChild[c] = 1;
    std::vector<int> roots;
    for (int i = 0; i < nodeCount; ++i)
      if (!isChild[i]) roots.push_back(i);
    if (roots.empty() && nodeCount > 0) invalid("recursive node graph: every node is some node's child");
    return roots;
  }

  // Depth-first walk with an on-stack mark: a node met again while it is on the stack is a cycle.
  void checkNodeGraph(const std::vector<int>& roots) {
    std::vector<uint8_t> state(model_.nodes.size(), 0);  // 0 new, 1 on stack, 2 done
    std::vector<std::pair<int, size_t>> stack;
    for (int r : roots) {
      if (state[r] == 2) continue;
      stack.push_back({r, 0});
      state[r] = 1;
      while (!stack.empty()) {
        auto& [n, next] = stack.back();
        const auto& children = model_.nodes[n].children;
        if (next < children.size()) {
          int c = children[next++];
          if (state[c] == 1)
            invalid("recursive node graph: node " + std::to_string(c) + nodeName(c) + " is its own ancestor");
          if (state[c] == 0) {
            if (stack.size() >= kMaxNodeDepth) invalid("node hierarchy deeper than " + std::to_string(kMaxNodeDepth) + " levels");
            state[c] = 1;
            stack.push_back({c, 0});
          }
        } else {
          state[n] = 2;
          stack.pop_back();
        }
      }
    }
  }

  // A node may have several parents (a DAG is not a cycle), so flattening can multiply instances:
  // count them without expanding (memoised over the acyclic graph) and refuse absurd totals.
  void checkInstanceCount(const std::vector<int>& roots) {
    std::vector<double> count(model_.nodes.size(), -1.0);
    std::function<double(int)> instances = [&](int n) {
      if (count[n] >= 0.0) return count[n];
      double c = 1.0;
      for (int child : model_.nodes[n].children) c += instances(child);
      return count[n] = c;
    };
    double total = 0.0;
    for (int r : roots) total += instances(r);
    if (total > static_cast<double>(kMaxNodeInstances))
      invalid("absurd size: the node graph instantiates " + std::to_string(static_cast<unsigned long long>(std::min(total, 1e19))) + " nodes (more than " +
              std::to_string(kMaxNodeInstances) + ")");
  }

  std::string nodeName(int n) const {
    const std::string& name = model_.nodes[n].name;
    return name.empty() ? std::string() : " ('" + name + "')";
  }

  glm::mat4 localMatrix(int n) {
    const auto& node = model_.nodes[n];
    glm::mat4 m(1.0f);
    if (node.matrix.size() == 16) {
      for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[i]);  // both column-major
    } else {
      glm::mat4 t(1.0f), r(1.0f), s(1.0f);
      if (node.translation.size() == 3)
        t = glm::translate(glm::mat4(1.0f), glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
      if (node.rotation.size() == 4) {
        glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                    static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
        float len = glm::length(q);
        if (len > 0.0f && std::isfinite(len)) r = glm::mat4_cast(q / len);
        else if (!std::isfinite(len)) invalid("node " + std::to_string(n) + nodeName(n) + " has a non-finite rotation");
      }
      if (node.scale.size() == 3) s = glm::scale(glm::mat4(1.0f), glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
      m = t * r * s;
    }
    for (int i = 0; i < 16; ++i)
      if (!std::isfinite(glm::value_ptr(m)[i])) invalid("node " + std::to_string(n) + nodeName(n) + " has a NaN/Inf in its transform");
    return m;
  }

  // extras.irbake of node n over what its ancestors set (scene/object_settings.h).
  ObjectSettings nodeSettings(int n, const ObjectSettings& inherited) {
    std::vector<std::string> unknown;
    const ObjectSettings own = readObjectSettings(nodeJson(n), "node " + std::to_string(n) + nodeName(n), file_, unknown);
    warnUnknownSettings(unknown, "node " + std::to_string(n) + nodeName(n));
    return own.over(inherited);
  }

  const ObjectSettings& meshSettings(int meshIndex) {
    auto it = meshSettings_.find(meshIndex);
    if (it != meshSettings_.end()) return it->second;
    static const json empty = json::object();
    const json* mesh = element(src_.json, "meshes", static_cast<size_t>(meshIndex));
    const std::string& name = model_.meshes[meshIndex].name;
    const std::string what = "mesh " + std::to_string(meshIndex) + (name.empty() ? "" : " ('" + name + "')");
    std::vector<std::string> unknown;
    ObjectSettings settings = readObjectSettings(mesh ? *mesh : empty, what, file_, unknown);
    warnUnknownSettings(unknown, what);
    return meshSettings_.emplace(meshIndex, settings).first->second;
  }

  // Each unknown key under extras.irbake is named once per file (the first object that has it).
  void warnUnknownSettings(const std::vector<std::string>& keys, const std::string& what) {
    std::string fresh;
    for (const std::string& k : keys)
      if (unknownSettingsWarned_.insert(k).second) fresh += (fresh.empty() ? "\"" : ", \"") + k + "\"";
    if (!fresh.empty())
      warn(what + ": extras.irbake has unknown key(s) " + fresh + ", ignored (known: mode, lightmapScale)");
  }

  void visitNode(int n, const glm::mat4& parent, int depth, const ObjectSettings& inherited) {
    const auto& node = model_.nodes[n];
    glm::mat4 world = parent * localMatrix(n);
    const ObjectSettings settings = nodeSettings(n, inherited);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model_.meshes.size()))
        invalid("node " + std::to_string(n) + nodeName(n) + " references mesh " + std::to_string(node.mesh) + ", out of range");
      if (const json* gpu = path(nodeJson(n), {"extensions", "EXT_mesh_gpu_instancing"})) {
        const std::vector<glm::mat4> instances = gpuInstances(n, *gpu);
        for (size_t i = 0; i < instances.size(); ++i)
          addMeshInstance(n, node.mesh, world * instances[i], settings, static_cast<int>(i), instances[i]);
      } else {
        addMeshInstance(n, node.mesh, world, settings);
      }
    }
    if (node.camera >= 0) addCamera(n, world);
    if (const json* l = path(nodeJson(n), {"extensions", "KHR_lights_punctual", "light"})) addLight(n, l, world);
    if (const json* ies = path(nodeJson(n), {"extensions", "EXT_lights_ies"})) {
      if (!iesLights_) iesLights_ = std::make_unique<IesLightReader>(src_, model_, file_);
      scene_.lights.push_back(iesLights_->light(n, *ies, world));
    }
    for (int c : node.children) visitNode(c, world, depth + 1, settings);
  }

  // EXT_mesh_gpu_instancing: one transform per instance, T · R · S from the TRANSLATION, ROTATION (unit
  // quaternion) and SCALE accessors, applied before the node's world matrix. Each instance becomes a mesh
  // instance of the scene of its own (and so its own light-map region). Broken data is refused, naming
  // the extension, the node and the accessor.
  std::vector<glm::mat4> gpuInstances(int n, const json& ext) {
    const std::string what = "node " + std::to_string(n) + nodeName(n) + ": EXT_mesh_gpu_instancing";
    const json* attributes = child(ext, "attributes");
    if (!attributes || !attributes->is_object()) invalid(what + " has no \"attributes\" object");
    std::vector<glm::vec3> translation, scale;
    std::vector<glm::vec4> rotation;
    size_t count = 0;
    bool first = true;
    for (const auto& [name, index] : attributes->items()) {
      const int want = name == "ROTATION" ? 4 : (name == "TRANSLATION" || name == "SCALE") ? 3 : 0;
      if (want == 0) continue;  // custom attributes (_ID, ...) do not move the instance
      if (!index.is_number_integer()) invalid(what + " attribute " + name + " is not an accessor index");
      int components;
      size_t elements;
      const std::vector<float> v = readAccessor(index.get<int>(), what + " " + name, components, elements);
      const std::string accessor = "accessor " + index.dump() + " (" + what + " " + name + ")";
      if (components != want) invalid(accessor + " has " + std::to_string(components) + " components, the extension needs " + std::to_string(want));
      checkInstanceComponentType(model_.accessors[index.get<int>()], name, accessor);
      if (!first && elements != count)
        invalid(accessor + " has " + std::to_string(elements) + " elements, another attribute " + std::to_string(count) + ": every attribute needs one per instance");
      count = elements;
      first = false;
      for (float x : v)
        if (!std::isfinite(x)) invalid(accessor + " holds a NaN/Inf");
      for (size_t i = 0; i < elements; ++i) {
        if (want == 4) rotation.emplace_back(v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]);
        else (name == "SCALE" ? scale : translation).emplace_back(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
      }
    }
    if (first) invalid(what + " has none of TRANSLATION, ROTATION and SCALE");
    if (count == 0) invalid(what + " has no instances (its accessors hold 0 elements)");
    gpuInstanceTotal_ += count;
    if (gpuInstanceTotal_ > kMaxNodeInstances)
      invalid(what + ": absurd size, more than " + std::to_string(kMaxNodeInstances) + " instances in the file");
    ++scene_.stats.gpuInstancedNodes;
    scene_.stats.gpuInstances += count;
    std::vector<glm::mat4> out(count, glm::mat4(1.0f));
    for (size_t i = 0; i < count; ++i) {
      glm::mat4 r(1.0f);
      if (!rotation.empty()) {
        const glm::quat q(rotation[i].w, rotation[i].x, rotation[i].y, rotation[i].z);
        const float len = glm::length(q);
        if (!(len > 0.0f)) invalid(what + " ROTATION of instance " + std::to_string(i) + " is a zero quaternion");
        r = glm::mat4_cast(q / len);
      }
      const glm::mat4 t = translation.empty() ? glm::mat4(1.0f) : glm::translate(glm::mat4(1.0f), translation[i]);
      const glm::mat4 sc = scale.empty() ? glm::mat4(1.0f) : glm::scale(glm::mat4(1.0f), scale[i]);
      out[i] = t * r * sc;
    }
    return out;
  }

  // The extension's component types: float; a normalized signed byte or short for ROTATION; and with
  // KHR_mesh_quantization any byte or short for TRANSLATION and SCALE.
  void checkInstanceComponentType(const tinygltf::Accessor& a, const std::string& name, const std::string& accessor) const {
    const int type = a.componentType;
    if (type == TINYGLTF_COMPONENT_TYPE_FLOAT) return;
    const bool signedSmall = type == TINYGLTF_COMPONENT_TYPE_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT;
    if (name == "ROTATION" && signedSmall && a.normalized) return;
    const bool small = signedSmall || type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    const auto& used = model_.extensionsUsed;
    if (name != "ROTATION" && small && std::find(used.begin(), used.end(), "KHR_mesh_quantization") != used.end()) return;
    invalid(accessor + " has component type " + std::to_string(type) + (a.normalized ? " (normalized)" : "") +
            ", which the extension does not allow for " + name);
  }

  const json& nodeJson(int n) const {
    static const json empty = json::object();
    const json* j = element(src_.json, "nodes", n);
    return j ? *j : empty;
  }

  void addCamera(int n, const glm::mat4& world) {
    int ci = model_.nodes[n].camera;
    if (ci >= static_cast<int>(model_.cameras.size()))
      invalid("node " + std::to_string(n) + nodeName(n) + " references camera " + std::to_string(ci) + ", out of range");
    const auto& c = model_.cameras[ci];
    if (c.type != "perspective") {
      warn("camera " + std::to_string(ci) + " is " + c.type + "; only perspective cameras are used");
      return;
    }
    Camera cam;
    cam.name = c.name.empty() ? model_.nodes[n].name : c.name;
    // Keep rotation and translation; a scaled camera node would distort the view.
    glm::mat4 m = world;
    for (int i = 0; i < 3; ++i) {
      float len = glm::length(glm::vec3(m[i]));
      if (len > 0.0f) m[i] /= len;
    }
    cam.cameraToWorld = m;
    cam.yfov = c.perspective.yfov > 0.0 ? static_cast<float>(c.perspective.yfov) : cam.yfov;
    cam.aspectRatio = static_cast<float>(c.perspective.aspectRatio);
    cam.znear = c.perspective.znear > 0.0 ? static_cast<float>(c.perspective.znear) : cam.znear;
    cam.zfar = static_cast<float>(c.perspective.zfar);
    cam.node = n;
    scene_.cameras.push_back(cam);
  }

  // extras: {"irbake": {"mode": "baked" | "indirect" | "shadowmask", "group": NAME}} on the glTF light (either
  // or both). A bad value is a bake setting the user must fix (exit 2, as --light-mode's), not a broken file.
  void readExtrasMode(int li, const std::string& what, Light& light) const {
    const json* lights = path(src_.json, {"extensions", "KHR_lights_punctual", "lights"});
    if (!lights || !lights->is_array() || li >= static_cast<int>(lights->size())) return;
    const json* irbake = path((*lights)[static_cast<size_t>(li)], {"extras", "irbake"});
    if (!irbake) return;
    const json* mode = child(*irbake, "mode");
    const json* group = child(*irbake, "group");
    if (!mode && !group)
      throw Error(ErrorCode::Usage, file_, what + ": extras.irbake must be an object with a \"mode\" or a \"group\" (got " +
                                               irbake->dump().substr(0, 80) + ")");
    if (group) light.group = extrasGroup(*group, what);
    if (!mode) return;
    if (!mode->is_string() || !parseLightMode(mode->get<std::string>(), light.extrasMode))
      throw Error(ErrorCode::Usage, file_, what + ": extras.irbake.mode must be \"baked\", \"indirect\" or \"shadowmask\" (got " +
                                               mode->dump().substr(0, 80) + ")");
    light.hasExtrasMode = true;
  }

  // extras.irbake.group: a light group's name (pipeline/light_groups.h checks the name itself).
  std::string extrasGroup(const json& group, const std::string& what) const {
    if (!group.is_string() || group.get<std::string>().empty())
      throw Error(ErrorCode::Usage, file_, what + ": extras.irbake.group must be a light group's name (got " +
                                               group.dump().substr(0, 80) + ")");
    return group.get<std::string>();
  }

  void addLight(int n, const json* lightRef, const glm::mat4& world) {
    if (!lightRef->is_number_integer()) invalid("node " + std::to_string(n) + nodeName(n) + " has a non-integer light index");
    int li = lightRef->get<int>();
    if (li < 0 || li >= static_cast<int>(model_.lights.size()))
      invalid("node " + std::to_string(n) + nodeName(n) + " references light " + std::to_string(li) + ", out of range");
    const auto& l = model_.lights[li];
    Light light;
    light.name = l.name.empty() ? model_.nodes[n].name : l.name;
    if (l.type == "point") light.type = LightType::Point;
    else if (l.type == "spot") light.type = LightType::Spot;
    else if (l.type == "directional") light.type = LightType::Directional;
    else invalid("light " + std::to_string(li) + " has unknown type '" + l.type + "'");
    if (l.color.size() == 3) light.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
    light.intensity = static_cast<float>(l.intensity);
    light.range = static_cast<float>(l.range);
    light.innerConeAngle = static_cast<float>(l.spot.innerConeAngle);
    light.outerConeAngle = static_cast<float>(l.spot.outerConeAngle);
    const std::string what = "light " + std::to_string(li) + (l.name.empty() ? "" : " ('" + l.name + "')");
    // Each colour component on its own must be ≥ 0: light is never negative.
    if (!finiteNonNegative(glm::vec4(light.color, 0.0f)))
      invalid(what + " has a negative or non-finite colour " + rgb(light.color));
    if (!std::isfinite(light.intensity) || light.intensity < 0.0f || !(light.range >= 0.0f))
      invalid(what + " has a negative or non-finite intensity or range");
    // KHR_lights_punctual: 0 ≤ innerConeAngle < outerConeAngle ≤ π/2 (a little slack above π/2 for a float π/2).
    if (light.type == LightType::Spot &&
        !(l.spot.innerConeAngle >= 0.0 && l.spot.innerConeAngle < l.spot.outerConeAngle && l.spot.outerConeAngle <= kPi / 2.0 + 1e-6))
      invalid(what + " has spot cone angles inner " + number(l.spot.innerConeAngle) + ", outer " +
              number(l.spot.outerConeAngle) + ": KHR_lights_punctual needs 0 ≤ innerConeAngle < outerConeAngle ≤ π/2");
    light.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    const float far = glm::max(glm::abs(light.position.x), glm::max(glm::abs(light.position.y), glm::abs(light.position.z)));
    if (light.type != LightType::Directional && !(far <= kMaxCoordinate * (1.0 + kBoundSlack)))
      invalid(what + " on node " + std::to_string(n) + nodeName(n) + " is at a coordinate of " + scientific(far) +
              " m, beyond the supported " + scientific(kMaxCoordinate) + " m: rescale the scene (node scale)");
    glm::vec3 dir = glm::vec3(world * glm::vec4(0, 0, -1, 0));
    float len = glm::length(dir);
    light.direction = len > 0.0f ? dir / len : glm::vec3(0, 0, -1);
    light.node = n;
    light.gltfLight = li;
    readExtrasMode(li, what, light);
    scene_.lights.push_back(light);
  }

  // Reads an accessor as floats (count × components), sparse substitution applied, bounds checked.
  std::vector<float> readAccessor(int index, const std::string& what, int& components, size_t& count) {
    if (index < 0 || index >= static_cast<int>(model_.accessors.size()))
      invalid(what + " references accessor " + std::to_string(index) + ", out of range (" + std::to_string(model_.accessors.size()) + " accessors)");
    const auto& a = model_.accessors[index];
    std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    components = componentCount(a.type);
    int csize = componentSize(a.componentType);
    if (components == 0 || csize == 0) invalid(name + " has an unsupported type or component type");
    count = a.count;
    const size_t elemSize = static_cast<size_t>(components) * csize;
    std::vector<float> out;
    if (a.bufferView >= 0) {
      const uint8_t* base;
      size_t viewLength, stride;
      viewBytes(a.bufferView, name, base, viewLength, stride);
      if (stride == 0) stride = elemSize;
      if (stride < elemSize) invalid(name + " has byteStride " + std::to_string(stride) + " smaller than its element");
      double need = static_cast<double>(a.byteOffset) + static_cast<double>(stride) * (count ? count - 1 : 0) + elemSize;
      const auto& buffer = model_.buffers[model_.bufferViews[a.bufferView].buffer];
      if (count > 0 && need > kAbsurdFactor * static_cast<double>(buffer.data.size()) + 1024.0)
        invalid(name + " declares an absurd size: " + std::to_string(count) + " elements (" + std::to_string(need / 1e6) +
                " MB) in a buffer of " + std::to_string(buffer.data.size()) + " bytes");
      if (count > 0 && need > static_cast<double>(viewLength))
        invalid(name + " is out of bounds: needs " + std::to_string(static_cast<uint64_t>(need)) + " bytes of buffer view " +
                std::to_string(a.bufferView) + ", which has " + std::to_string(viewLength));
      out.resize(count * components);
      for (size_t i = 0; i < count; ++i) {
        const uint8_t* p = base + a.byteOffset + i * stride;
        for (int c = 0; c < components; ++c) out[i * components + c] = readComponent(p + c * csize, a.componentType, a.normalized);
      }
    } else {
      if (count > (size_t(1) << 28)) invalid(name + " declares an absurd size: " + std::to_string(count) + " elements and no buffer");
      out.assign(count * components, 0.0f);  // no buffer view: zeros (sparse may fill some)
    }
    if (a.sparse.isSparse) applySparse(a, name, components, csize, out);
    return out;
  }

  void applySparse(const tinygltf::Accessor& a, const std::string& name, int components, int csize, std::vector<float>& out) {
    const size_t n = static_cast<size_t>(std::max(0, a.sparse.count));
    const uint8_t *ib, *vb;
    size_t il, vl, stride;
    viewBytes(a.sparse.indices.bufferView, name + " sparse indices", ib, il, stride);
    viewBytes(a.sparse.values.bufferView, name + " sparse values", vb, vl, stride);
    int isize = componentSize(a.sparse.indices.componentType);
    if (isize == 0 || a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE)
      invalid(name + " has sparse indices of an invalid component type");
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0 ||
        a.sparse.indices.byteOffset + n * isize > il || a.sparse.values.byteOffset + n * components * csize > vl)
      invalid(name + " sparse data is out of bounds of its buffer views");
    for (size_t k = 0; k < n; ++k) {
      uint32_t target = readIndex(ib + a.sparse.indices.byteOffset + k * isize, a.sparse.indices.componentType);
      if (target >= a.count) invalid(name + " sparse index " + std::to_string(target) + " out of range");
      for (int c = 0; c < components; ++c)
        out[target * components + c] =
            readComponent(vb + a.sparse.values.byteOffset + (k * components + c) * csize, a.componentType, a.normalized);
    }
  }

  void viewBytes(int viewIndex, const std::string& name, const uint8_t*& base, size_t& length, size_t& stride) {
    if (viewIndex < 0 || viewIndex >= static_cast<int>(model_.bufferViews.size()))
      invalid(name + " references buffer view " + std::to_string(viewIndex) + ", out of range");
    const auto& v = model_.bufferViews[viewIndex];
    if (v.buffer < 0 || v.buffer >= static_cast<int>(model_.buffers.size()))
      invalid("buffer view " + std::to_string(viewIndex) + " references buffer " + std::to_string(v.buffer) + ", out of range");
    const auto& b = model_.buffers[v.buffer];
    if (static_cast<double>(v.byteOffset) + static_cast<double>(v.byteLength) > static_cast<double>(b.data.size()))
      invalid("buffer view " + std::to_string(viewIndex) + " is out of bounds: bytes " + std::to_string(v.byteOffset) + ".." +
              std::to_string(v.byteOffset + v.byteLength) + " of buffer " + std::to_string(v.buffer) + " (" +
              std::to_string(b.data.size()) + " bytes)");
    base = b.data.data() + v.byteOffset;
    length = v.byteLength;
    stride = v.byteStride;
  }

  std::vector<uint32_t> readIndices(int index, const std::string& what) {
    if (index < 0 || index >= static_cast<int>(model_.accessors.size()))
      invalid(what + " references index accessor " + std::to_string(index) + ", out of range");
    const auto& a = model_.accessors[index];
    if (a.type != TINYGLTF_TYPE_SCALAR || (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                           a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                           a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      invalid("accessor " + std::to_string(index) + " (" + what + ") is not an unsigned integer scalar accessor");
    if (a.sparse.isSparse || a.bufferView < 0) {
      int comps;
      size_t count;
      std::vector<float> f = readAccessor(index, what, comps, count);
      std::vector<uint32_t> out(count);
      for (size_t i = 0; i < count; ++i) out[i] = static_cast<uint32_t>(f[i]);
      return out;
    }
    std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    const uint8_t* base;
    size_t length, stride;
    viewBytes(a.bufferView, name, base, length, stride);
    const size_t csize = componentSize(a.componentType);
    if (stride == 0) stride = csize;
    double need = static_cast<double>(a.byteOffset) + static_cast<double>(stride) * (a.count ? a.count - 1 : 0) + csize;
    const auto& buffer = model_.buffers[model_.bufferViews[a.bufferView].buffer];
    if (a.count > 0 && need > kAbsurdFactor * static_cast<double>(buffer.data.size()) + 1024.0)
      invalid(name + " declares an absurd size: " + std::to_string(a.count) + " indices in a buffer of " +
              std::to_string(buffer.data.size()) + " bytes");
    if (a.count > 0 && need > static_cast<double>(length))
      invalid(name + " is out of bounds: needs " + std::to_string(static_cast<uint64_t>(need)) + " bytes of buffer view " +
              std::to_string(a.bufferView) + ", which has " + std::to_string(length));
    std::vector<uint32_t> out(a.count);
    for (size_t i = 0; i < a.count; ++i) out[i] = readIndex(base + a.byteOffset + i * stride, a.componentType);
    return out;
  }

  const LocalPrimitive& localPrimitive(int meshIndex, int primIndex) {
    auto key = std::make_pair(meshIndex, primIndex);
    auto it = localCache_.find(key);
    if (it != localCache_.end()) return it->second;
    LocalPrimitive& lp = localCache_[key];
    const auto& mesh = model_.meshes[meshIndex];
    const auto& prim = mesh.primitives[primIndex];
    std::string what = "mesh " + std::to_string(meshIndex) + (mesh.name.empty() ? "" : " '" + mesh.name + "'") + " primitive " +
                       std::to_string(primIndex);
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      lp.skipped = true;
      ++scene_.stats.primitivesSkipped;
      warn(what + " is made of points or lines (mode " + std::to_string(mode) + "): skipped");
      return lp;
    }
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) invalid(what + " has no POSITION attribute");
    int comps;
    size_t vertexCount;
    std::vector<float> p = readAccessor(pos->second, what + " POSITION", comps, vertexCount);
    if (comps != 3) invalid(what + " POSITION is not VEC3");
    lp.positions.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) {
      lp.positions[i] = glm::vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      if (!finite(lp.positions[i]))
        invalid(what + " has a NaN/Inf position at vertex " + std::to_string(i) + " (accessor " + std::to_string(pos->second) + ")");
    }
    auto readVec = [&](const char* attr, int want, auto& dst) {
      auto a = prim.attributes.find(attr);
      if (a == prim.attributes.end()) return;
      int c;
      size_t n;
      std::vector<float> v = readAccessor(a->second, what + " " + attr, c, n);
      if (c != want) invalid(what + " " + attr + " has " + std::to_string(c) + " components, expected " + std::to_string(want));
      if (n != vertexCount)
        invalid(what + " " + attr + " has " + std::to_string(n) + " elements but POSITION has " + std::to_string(vertexCount));
      dst.resize(n);
      for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < want; ++k) {
          float x = v[i * want + k];
          dst[i][k] = std::isfinite(x) ? x : 0.0f;  // a bad normal/UV is repaired, never propagated
        }
    };
    readVec("NORMAL", 3, lp.normals);
    readVec("TEXCOORD_0", 2, lp.uv0);
    readVec("TEXCOORD_1", 2, lp.uv1);
    if (options_.shadingMaps) readVec("TANGENT", 4, lp.tangents);

    std::vector<uint32_t> raw;
    if (prim.indices >= 0) {
      raw = readIndices(prim.indices, what + " indices");
      for (size_t i = 0; i < raw.size(); ++i)
        if (raw[i] >= vertexCount)
          invalid(what + " index " + std::to_string(raw[i]) + " at position " + std::to_string(i) + " is out of range (" +
                  std::to_string(vertexCount) + " vertices)");
    } else {
      raw.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) raw[i] = static_cast<uint32_t>(i);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (raw.size() % 3 != 0) warn(what + " has " + std::to_string(raw.size()) + " indices, not a multiple of 3: the tail is ignored");
      lp.indices.assign(raw.begin(), raw.begin() + raw.size() / 3 * 3);
    } else {
      for (size_t i = 0; i + 2 < raw.size(); ++i) {
        uint32_t a, b, c;
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
          // Odd triangles of a strip swap their first two vertices to keep the winding.
          a = (i % 2 == 0) ? raw[i] : raw[i + 1];
          b = (i % 2 == 0) ? raw[i + 1] : raw[i];
          c = raw[i + 2];
        } else {
          a = raw[0];
          b = raw[i + 1];
          c = raw[i + 2];
        }
        lp.indices.insert(lp.indices.end(), {a, b, c});
      }
    }
    lp.material = prim.material;
    if (const json* rec = primitiveExtras(meshIndex, primIndex)) {
      lp.lightmap.page = static_cast<int>(numberOr(child(*rec, "page"), -1));
      lp.lightmap.width = static_cast<int>(numberOr(child(*rec, "width"), 0));
      lp.lightmap.height = static_cast<int>(numberOr(child(*rec, "height"), 0));
    }
    return lp;
  }

  const json* primitiveExtras(int meshIndex, int primIndex) const {
    const json* mesh = element(src_.json, "meshes", meshIndex);
    if (!mesh) return nullptr;
    const json* prim = element(*mesh, "primitives", primIndex);
    if (!prim) return nullptr;
    const json* rec = path(*prim, {"extras", "lightmap"});
    return (rec && rec->is_object()) ? rec : nullptr;
  }

  // An irbake export's probe-lit primitive (extras.lightProbes, docs/export.md): the viewer lights it from the probes.
  bool exportMarksProbeLit(int meshIndex, int primIndex) const {
    const json* mesh = element(src_.json, "meshes", meshIndex);
    const json* prim = mesh ? element(*mesh, "primitives", primIndex) : nullptr;
    const json* mark = prim ? path(*prim, {"extras", "lightProbes"}) : nullptr;
    return mark && mark->is_boolean() && mark->get<bool>();
  }

  void addMeshInstance(int nodeIndex, int meshIndex, const glm::mat4& world, const ObjectSettings& fromNodes,
                       int instance = -1, const glm::mat4& instanceToNode = glm::mat4(1.0f)) {
    const auto& mesh = model_.meshes[meshIndex];
    const ObjectSettings settings = fromNodes.over(meshSettings(meshIndex));
    const glm::mat3 linear(world);
    const float det = glm::determinant(linear);
    const glm::mat3 normalMatrix = std::abs(det) > 0.0f ? glm::transpose(glm::inverse(linear)) : linear;
    for (int pi = 0; pi < static_cast<int>(mesh.primitives.size()); ++pi) {
      const LocalPrimitive& lp = localPrimitive(meshIndex, pi);
      if (lp.skipped) continue;
      Primitive out;
      out.name = mesh.name.empty() ? "mesh" + std::to_string(meshIndex) : mesh.name;
      if (mesh.primitives.size() > 1) out.name += "/" + std::to_string(pi);
      out.node = nodeIndex;
      out.gltfMesh = meshIndex;
      out.gltfPrimitive = pi;
      out.nodeToWorld = world;
      out.instance = instance;
      out.instanceToNode = instanceToNode;
      out.mode = settings.mode.value_or(ObjectMode::Baked);
      if (options_.shadingMaps && exportMarksProbeLit(meshIndex, pi)) out.mode = ObjectMode::Probes;
      out.lightmapScale = settings.lightmapScale.value_or(1.0f);
      out.material = materialIndex(lp.material, "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(pi));
      out.lightmap = lp.lightmap;
      out.uv0 = lp.uv0;
      out.uv1 = lp.uv1;
      out.positions.resize(lp.positions.size());
      const std::string meshLabel = mesh.name.empty() ? std::string() : " ('" + mesh.name + "')";
      for (size_t i = 0; i < lp.positions.size(); ++i) {
        out.positions[i] = glm::vec3(world * glm::vec4(lp.positions[i], 1.0f));
        const glm::vec3 a = glm::abs(out.positions[i]);
        const float far = glm::max(a.x, glm::max(a.y, a.z));
        if (!finite(out.positions[i]))
          invalid("node " + std::to_string(nodeIndex) + nodeName(nodeIndex) + " puts a vertex of mesh " + std::to_string(meshIndex) +
                  meshLabel + " at NaN/Inf in world space");
        if (far > kMaxCoordinate * (1.0 + kBoundSlack))
          invalid("node " + std::to_string(nodeIndex) + nodeName(nodeIndex) + " puts a vertex of mesh " + std::to_string(meshIndex) +
                  meshLabel + " at a coordinate of " + scientific(far) + " m, beyond the supported " +
                  scientific(kMaxCoordinate) + " m: rescale the scene (node scale)");
      }
      // A mirroring transform (det < 0) turns counter-clockwise into clockwise: swap two corners.
      const bool mirrored = det < 0.0f;
      out.indices.reserve(lp.indices.size());
      for (size_t t = 0; t + 2 < lp.indices.size(); t += 3) {
        uint32_t a = lp.indices[t], b = lp.indices[t + 1], c = lp.indices[t + 2];
        if (mirrored) std::swap(b, c);
        const glm::vec3 &pa = out.positions[a], &pb = out.positions[b], &pc = out.positions[c];
        glm::vec3 e0 = pb - pa, e1 = pc - pa, e2 = pc - pb;
        float cross = glm::length(glm::cross(e0, e1));
        float scale = glm::dot(e0, e0) + glm::dot(e1, e1) + glm::dot(e2, e2);
        // Zero area relative to the triangle's own size (so millimetre triangles are not dropped).
        if (a == b || b == c || a == c || !(cross > 1e-7f * scale)) {
          ++scene_.stats.trianglesDropped;
          continue;
        }
        out.indices.insert(out.indices.end(), {a, b, c});
      }
      if (out.indices.empty()) continue;
      scene_.stats.trianglesKept += out.indices.size() / 3;
      worldTangents(lp, linear, mirrored, out);
      finishNormals(lp, normalMatrix, out);
      scene_.primitives.push_back(std::move(out));
    }
  }

  // TANGENT to world space: xyz through the node's linear part (tangents follow the surface, unlike normals),
  // w = ±1, flipped by a mirroring node (the bitangent cross(n, t)·w must stay the mirrored one). A zero or
  // non-finite tangent drops the attribute: the viewer then generates the frame from the UVs.
  void worldTangents(const LocalPrimitive& lp, const glm::mat3& linear, bool mirrored, Primitive& out) {
    if (lp.tangents.size() != lp.positions.size()) return;
    out.tangents.resize(lp.tangents.size());
    for (size_t i = 0; i < lp.tangents.size(); ++i) {
      const glm::vec3 t = linear * glm::vec3(lp.tangents[i]);
      const float len = glm::length(t);
      if (!(len > 0.0f) || !std::isfinite(len)) {
        out.tangents.clear();
        warn("mesh " + std::to_string(out.gltfMesh) + " has a zero or non-finite TANGENT: tangents are generated instead");
        return;
      }
      const float w = (lp.tangents[i].w < 0.0f) != mirrored ? -1.0f : 1.0f;
      out.tangents[i] = glm::vec4(t / len, w);
    }
  }

  // glTF 2.0 (3.7.2.1): "When normals are not specified, client implementations MUST calculate flat
  // normals." Each corner takes its face's normal; a vertex shared by faces of different orientation (a box
  // corner) is split, one copy per orientation, while coplanar faces keep sharing (sourceVertex records
  // the accessor vertex). Smooth normals here bent a box's shading normals by up to 55° at its corners.
  void flatNormals(Primitive& out) {
    const size_t n = out.positions.size();
    const bool hasUv0 = out.uv0.size() == n, hasUv1 = out.uv1.size() == n, hasTangents = out.tangents.size() == n;
    Primitive split;
    std::map<std::tuple<uint32_t, int, int, int>, uint32_t> copies;  // (vertex, quantised normal) → new vertex
    split.indices.reserve(out.indices.size());
    for (size_t t = 0; t < out.indices.size(); t += 3) {
      const uint32_t a = out.indices[t], b = out.indices[t + 1], c = out.indices[t + 2];
      const glm::vec3 f = glm::normalize(glm::cross(out.positions[b] - out.positions[a], out.positions[c] - out.positions[a]));
      const glm::ivec3 q(glm::round(f * 1e4f));  // faces within ~1e-4 rad share a vertex
      for (uint32_t v : {a, b, c}) {
        auto [it, fresh] = copies.try_emplace({v, q.x, q.y, q.z}, static_cast<uint32_t>(split.positions.size()));
        if (fresh) {
          split.positions.push_back(out.positions[v]);
          split.normals.push_back(f);
          if (hasUv0) split.uv0.push_back(out.uv0[v]);
          if (hasUv1) split.uv1.push_back(out.uv1[v]);
          if (hasTangents) split.tangents.push_back(out.tangents[v]);
          split.sourceVertex.push_back(v);
        }
        split.indices.push_back(it->second);
      }
    }
    out.positions.swap(split.positions);
    out.normals.swap(split.normals);
    if (hasUv0) out.uv0.swap(split.uv0);
    if (hasUv1) out.uv1.swap(split.uv1);
    if (hasTangents) out.tangents.swap(split.tangents);
    out.indices.swap(split.indices);
    out.sourceVertex.swap(split.sourceVertex);
  }

  // Provided normals go through the inverse-transpose; missing ones are flat (flatNormals); zero or
  // non-finite ones in a provided attribute come from the area-weighted adjacent face normals.
  void finishNormals(const LocalPrimitive& lp, const glm::mat3& normalMatrix, Primitive& out) {
    const size_t n = out.positions.size();
    std::vector<glm::vec3> computed;
    auto faceWeighted = [&]() {
      computed.assign(n, glm::vec3(0.0f));
      for (size_t t = 0; t < out.indices.size(); t += 3) {
        uint32_t a = out.indices[t], b = out.indices[t + 1], c = out.indices[t + 2];
        glm::vec3 f = glm::cross(out.positions[b] - out.positions[a], out.positions[c] - out.positions[a]);  // |f| = 2·area
        computed[a] += f;
        computed[b] += f;
        computed[c] += f;
      }
      for (auto& v : computed) {
        float len = glm::length(v);
        v = len > 0.0f ? v / len : glm::vec3(0, 1, 0);
      }
    };
    out.normals.resize(n);
    if (lp.normals.empty() && options_.computeMissingNormals) {
      flatNormals(out);
      out.normalsComputed = true;
      ++scene_.stats.normalsComputed;
      return;
    }
    for (size_t i = 0; i < n; ++i) {
      glm::vec3 v = lp.normals.empty() ? glm::vec3(0.0f) : normalMatrix * lp.normals[i];
      float len = glm::length(v);
      if (len > 0.0f && std::isfinite(len)) {
        out.normals[i] = v / len;
      } else {
        if (computed.empty()) faceWeighted();
        out.normals[i] = computed[i];
      }
    }
  }

  // glTF material index → Scene material index (created on first use; -1 → the default material).
  int materialIndex(int gltfMaterial, const std::string& what) {
    if (gltfMaterial < 0) {
      if (defaultMaterial_ < 0) {
        Material m;
        m.name = "default";
        defaultMaterial_ = static_cast<int>(scene_.materials.size());
        scene_.materials.push_back(m);
      }
      return defaultMaterial_;
    }
    if (gltfMaterial >= static_cast<int>(model_.materials.size()))
      invalid(what + " references material " + std::to_string(gltfMaterial) + ", out of range");
    int& slot = materialMap_[gltfMaterial];
    if (slot < 0) {
      slot = static_cast<int>(scene_.materials.size());
      scene_.materials.push_back(convertMaterial(gltfMaterial));
    }
    return slot;
  }

  Material convertMaterial(int index) {
    const auto& g = model_.materials[index];
    Material m;
    m.name = g.name.empty() ? "material" + std::to_string(index) : g.name;
    m.gltfMaterial = index;
    const auto& pbr = g.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      m.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    if (pbr.baseColorTexture.index >= 0) {
      m.baseColorTexture = textureIndex(pbr.baseColorTexture.index, true, m.name);
      m.baseColorTexCoord = pbr.baseColorTexture.texCoord;
    }
    if (g.emissiveFactor.size() == 3) m.emissiveFactor = glm::vec3(g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]);
    if (g.emissiveTexture.index >= 0) {
      m.emissiveTexture = textureIndex(g.emissiveTexture.index, true, m.name);
      m.emissiveTexCoord = g.emissiveTexture.texCoord;
    }
    const json* mj = element(src_.json, "materials", index);
    if (mj) {
      readTextureTransforms(index, g.name, *mj, m);
      m.emissiveStrength = static_cast<float>(numberOr(path(*mj, {"extensions", "KHR_materials_emissive_strength", "emissiveStrength"}), 1.0));
      m.transmission = static_cast<float>(
          std::clamp(numberOr(path(*mj, {"extensions", "KHR_materials_transmission", "transmissionFactor"}), 0.0), 0.0, 1.0));
      const json* sg = path(*mj, {"extensions", "KHR_materials_pbrSpecularGlossiness"});
      if (sg && !child(*mj, "pbrMetallicRoughness")) readDiffuse(index, g.name, *sg, m);
      if (const json* moz = path(*mj, {"extensions", "MOZ_lightmap"})) readMozLightmap(index, g.name, *moz, m);
      if (options_.shadingMaps) readShadingMaps(g, *mj, m);
      if (const json* group = path(*mj, {"extras", "irbake", "group"}))
        m.group = extrasGroup(*group, "material " + std::to_string(index) + (g.name.empty() ? "" : " ('" + g.name + "')"));
    }
    if (g.alphaMode == "MASK") m.alphaMode = AlphaMode::Mask;
    else if (g.alphaMode == "BLEND") m.alphaMode = AlphaMode::Blend;
    m.alphaCutoff = static_cast<float>(g.alphaCutoff);
    m.doubleSided = g.doubleSided;
    const std::string what = "material " + std::to_string(index) + (g.name.empty() ? "" : " ('" + g.name + "')");
    if (!finiteNonNegative(m.baseColorFactor))
      invalid(what + " has a negative or non-finite baseColorFactor " + rgb(glm::vec3(m.baseColorFactor)) +
              " alpha " + number(m.baseColorFactor.a));
    if (!finiteNonNegative(glm::vec4(m.emissiveFactor, 0.0f)))
      invalid(what + " has a negative or non-finite emissiveFactor " + rgb(m.emissiveFactor));
    if (!std::isfinite(m.emissiveStrength) || m.emissiveStrength < 0.0f)
      invalid(what + ": KHR_materials_emissive_strength emissiveStrength must be ≥ 0 and finite (it is " +
              number(m.emissiveStrength) + ")");
    return m;
  }

  // KHR_texture_transform on the base colour and emissive textures, which every reader applies (a given
  // texCoord replaces the textureInfo's). On a texture that no reader transforms (the viewer's normal map
  // and light map) it is named in a warning, once per file, rather than shown untransformed in silence.
  void readTextureTransforms(int index, const std::string& gltfName, const json& mj, Material& m) {
    const std::string what = "material " + std::to_string(index) + (gltfName.empty() ? "" : " ('" + gltfName + "')");
    if (const json* t = path(mj, {"pbrMetallicRoughness", "baseColorTexture", "extensions", "KHR_texture_transform"}))
      m.baseColorUvTransform = readTextureTransform(*t, what + " baseColorTexture", m.baseColorTexCoord);
    if (const json* t = path(mj, {"emissiveTexture", "extensions", "KHR_texture_transform"}))
      m.emissiveUvTransform = readTextureTransform(*t, what + " emissiveTexture", m.emissiveTexCoord);
    if (!options_.shadingMaps || warnedTextureTransform_) return;
    for (const char* texture : {"normalTexture", "occlusionTexture"})
      if (path(mj, {texture, "extensions", "KHR_texture_transform"})) {
        warnedTextureTransform_ = true;
        warn(what + " " + texture + ": KHR_texture_transform is applied to base colour and emissive textures only; "
             "this texture is shown untransformed");
        return;
      }
    if (path(mj, {"extensions", "MOZ_lightmap", "extensions", "KHR_texture_transform"})) {
      warnedTextureTransform_ = true;
      warn(what + " MOZ_lightmap: KHR_texture_transform on the light map is not applied");
    }
  }

  UvTransform readTextureTransform(const json& ext, const std::string& what, int& texCoord) {
    const std::string name = what + ": KHR_texture_transform";
    if (!ext.is_object()) invalid(name + " is not an object");
    auto pair = [&](const char* key, glm::vec2 fallback) {
      const json* a = child(ext, key);
      if (!a) return fallback;
      if (!a->is_array() || a->size() != 2 || !(*a)[0].is_number() || !(*a)[1].is_number())
        invalid(name + " " + key + " must be an array of two numbers (got " + a->dump().substr(0, 80) + ")");
      const glm::vec2 v((*a)[0].get<float>(), (*a)[1].get<float>());
      if (!std::isfinite(v.x) || !std::isfinite(v.y)) invalid(name + " " + key + " is not finite");
      return v;
    };
    UvTransform t;
    t.present = true;
    t.offset = pair("offset", glm::vec2(0.0f));
    t.scale = pair("scale", glm::vec2(1.0f));
    if (const json* r = child(ext, "rotation")) {
      if (!r->is_number() || !std::isfinite(r->get<float>())) invalid(name + " rotation must be a finite number of radians");
      t.rotation = r->get<float>();
    }
    if (const json* tc = child(ext, "texCoord")) {
      if (!tc->is_number_integer() || tc->get<int64_t>() < 0 || tc->get<int64_t>() > 255)
        invalid(name + " texCoord " + tc->dump() + " is not a UV set index");
      texCoord = tc->get<int>();
    }
    return t;
  }

  // MOZ_lightmap (docs/export.md). A light map is never dropped silently: a missing texture and an intensity
  // that is not a number ≥ 0 are refused here; the texCoord is recorded (irview refuses any but 1); the
  // intensity is read in the specification's units, or an older irbake's (scene/moz_lightmap_units.h).
  // KHR_materials_pbrSpecularGlossiness without a metal-rough fallback: its diffuse colour is the surface's
  // albedo; the export converts the material to metal-rough with that colour as its base colour
  // (export/spec_gloss_conversion.h). A material with a fallback is read from the fallback, as before: exporters
  // write the two alike, but some put the opacity in the fallback only (Sibenik's glass).
  void readDiffuse(int index, const std::string& gltfName, const json& sg, Material& m) {
    const std::string what = "material " + std::to_string(index) + (gltfName.empty() ? "" : " ('" + gltfName + "')") +
                             ": KHR_materials_pbrSpecularGlossiness";
    if (!sg.is_object()) invalid(what + " is not an object");
    m.baseColorFactor = glm::vec4(1.0f);
    m.baseColorTexture = -1;
    m.baseColorTexCoord = 0;
    if (const json* f = child(sg, "diffuseFactor")) {
      bool ok = f->is_array() && f->size() == 4;
      for (size_t i = 0; ok && i < 4; ++i) ok = (*f)[i].is_number() && std::isfinite((*f)[i].get<double>());
      if (!ok) invalid(what + " diffuseFactor " + f->dump() + " must be 4 finite numbers");
      m.baseColorFactor = glm::vec4((*f)[0].get<float>(), (*f)[1].get<float>(), (*f)[2].get<float>(), (*f)[3].get<float>());
    }
    if (const json* t = child(sg, "diffuseTexture")) {
      const json* ti = t->is_object() ? child(*t, "index") : nullptr;
      if (!ti || !ti->is_number_integer()) invalid(what + " diffuseTexture has no texture index");
      const json* tc = child(*t, "texCoord");
      if (tc && (!tc->is_number_integer() || tc->get<int64_t>() < 0 || tc->get<int64_t>() > 255))
        invalid(what + " diffuseTexture has texCoord " + tc->dump() + ", not a UV set index");
      m.baseColorTexture = textureIndex(static_cast<int>(std::clamp<int64_t>(ti->get<int64_t>(), -1, 1 << 30)), true, m.name);
      m.baseColorTexCoord = tc ? tc->get<int>() : 0;
    }
  }

  void readMozLightmap(int index, const std::string& gltfName, const json& moz, Material& m) {
    const std::string what = "material " + std::to_string(index) + (gltfName.empty() ? "" : " ('" + gltfName + "')") +
                             ": MOZ_lightmap";
    if (!moz.is_object()) invalid(what + " is not an object");
    const json* ti = child(moz, "index");
    if (!ti || !ti->is_number_integer()) invalid(what + " has no texture index");
    const int textures = static_cast<int>(model_.textures.size());
    if (ti->get<int64_t>() < 0 || ti->get<int64_t>() >= textures)
      invalid(what + " names texture " + ti->dump() + ", which does not exist (the file has " + std::to_string(textures) +
              ")");
    // irbake's PNG is sRGB-encoded and says so in MOZ_lightmap.extras.colorSpace (docs/export.md).
    const json* cs = path(moz, {"extras", "colorSpace"});
    const bool srgb = cs && cs->is_string() && cs->get<std::string>() == "srgb";
    m.lightmapTexture = textureIndex(ti->get<int>(), srgb, m.name);
    if (const json* tc = child(moz, "texCoord")) {
      if (!tc->is_number_integer() || tc->get<int64_t>() < 0 || tc->get<int64_t>() > 255)
        invalid(what + " has texCoord " + tc->dump() + ", not a UV set index");
      m.lightmapTexCoord = tc->get<int>();
    }
    if (const json* in = child(moz, "intensity")) {
      const double v = in->is_number() ? in->get<double>() : std::nan("");
      if (!std::isfinite(v) || v < 0.0 || !std::isfinite(static_cast<float>(v)))
        invalid(what + " intensity " + in->dump() + " must be a finite number ≥ 0");
      m.lightmapIntensity = static_cast<float>(v);
    }
    // Material::lightmapIntensity scales the texel to irbake's map value (irradiance/π): the specification's
    // intensity carries π, an older irbake's (generator irbake, no marker) does not.
    m.lightmapIntensity = static_cast<float>(m.lightmapIntensity * mozLightmapToMapValue(moz, model_.asset.generator));
  }

  // The viewer's maps (LoadOptions::shadingMaps): the normal texture and IRBAKE_lightmap_directional
  // (docs/export.md), all linear. An incomplete directional extension is ignored with a warning.
  void readShadingMaps(const tinygltf::Material& g, const json& mj, Material& m) {
    if (g.normalTexture.index >= 0) {
      m.normalTexture = textureIndex(g.normalTexture.index, false, m.name);
      m.normalTexCoord = g.normalTexture.texCoord;
      m.normalScale = std::isfinite(g.normalTexture.scale) ? static_cast<float>(g.normalTexture.scale) : 1.0f;
    }
    readShadowMask(mj, m);
    const json* ext = path(mj, {"extensions", "IRBAKE_lightmap_directional"});
    if (!ext || !ext->is_object()) return;
    const json* l1 = child(*ext, "l1");
    bool complete = l1 && l1->is_array() && l1->size() == 3;
    for (int k = 0; complete && k < 3; ++k) {
      const json* index = child((*l1)[k], "index");
      const double scale = numberOr(child((*l1)[k], "scale"), 1.0);
      if (!index || !index->is_number_integer() || !std::isfinite(scale) || !(scale >= 0.0)) {
        complete = false;
        break;
      }
      m.directionalTextures[k] = textureIndex(index->get<int>(), false, m.name);
      m.directionalScales[k] = static_cast<float>(scale);
    }
    if (!complete) {
      m.directionalTextures = {-1, -1, -1};
      warn("material '" + m.name + "': IRBAKE_lightmap_directional needs three l1 textures with a finite scale: ignored");
      return;
    }
    const json* exr = child(*ext, "exr");
    if (exr && exr->is_array() && exr->size() == 3 && (*exr)[0].is_string() && (*exr)[1].is_string() && (*exr)[2].is_string())
      for (int k = 0; k < 3; ++k)
        m.directionalExrPaths[k] = (src_.folder / decodeUriEscapes((*exr)[k].get<std::string>())).string();
  }

  // IRBAKE_shadowmask on a material (docs/export.md): its RGBA mask page, linear, on the light map's TEXCOORD_1.
  void readShadowMask(const json& mj, Material& m) {
    const json* ext = path(mj, {"extensions", "IRBAKE_shadowmask"});
    if (!ext) return;
    const std::string what = "material '" + m.name + "': IRBAKE_shadowmask";
    const json* index = child(*ext, "index");
    if (!index || !index->is_number_integer() || index->get<int64_t>() < 0 ||
        index->get<int64_t>() >= static_cast<int64_t>(model_.textures.size()))
      invalid(what + " needs \"index\", a texture of the file");
    if (numberOr(child(*ext, "texCoord"), 1.0) != 1.0) invalid(what + ": texCoord must be 1 (the light map's)");
    m.shadowMaskTexture = textureIndex(index->get<int>(), false, m.name);
  }

  // The lights an export leaves to the client (scene/runtime_lights.h); a mask without the root's light map
  // to channels could not be shaded, so it is refused.
  void readRuntimeLightsOfExport() {
    const json* khr = path(src_.json, {"extensions", "KHR_lights_punctual", "lights"});
    const size_t khrCount = khr && khr->is_array() ? khr->size() : 0;
    scene_.runtimeLights = readRuntimeLights(src_.json, scene_.lights, khrCount, file_);
    if (!path(src_.json, {"extensions", "IRBAKE_shadowmask"}))
      for (const Material& m : scene_.materials)
        if (m.shadowMaskTexture >= 0)
          invalid("material '" + m.name + "': IRBAKE_shadowmask without the root IRBAKE_shadowmask that maps lights to channels");
  }

  // (glTF texture, colour space) → Scene texture; texels are filled by decodeTextures().
  int textureIndex(int gltfTexture, bool srgb, const std::string& materialName) {
    if (gltfTexture < 0 || gltfTexture >= static_cast<int>(model_.textures.size()))
      invalid("material '" + materialName + "' references texture " + std::to_string(gltfTexture) + ", out of range");
    auto key = std::make_pair(gltfTexture, srgb);
    auto it = textureMap_.find(key);
    if (it != textureMap_.end()) return it->second;
    const auto& t = model_.textures[gltfTexture];
    const int webp = webpSource(gltfTexture);
    if (webp < 0 && (t.source < 0 || t.source >= static_cast<int>(model_.images.size())))
      invalid("texture " + std::to_string(gltfTexture) + " references image " + std::to_string(t.source) + ", out of range");
    const int fallback = webp >= 0 && t.source >= 0 && t.source < static_cast<int>(model_.images.size()) ? t.source : -1;
    const int source = webp >= 0 ? webp : t.source;
    Texture tex;
    const auto& img = model_.images[source];
    tex.name = !img.name.empty() ? img.name : !img.uri.empty() ? img.uri : "image" + std::to_string(source);
    tex.gltfImage = source;
    if (t.sampler >= 0) {
      if (t.sampler >= static_cast<int>(model_.samplers.size())) invalid("texture " + std::to_string(gltfTexture) + " references a missing sampler");
      tex.wrapS = wrapFromGl(model_.samplers[t.sampler].wrapS);
      tex.wrapT = wrapFromGl(model_.samplers[t.sampler].wrapT);
    }
    int index = static_cast<int>(scene_.textures.size());
    scene_.textures.push_back(std::move(tex));
    textureSrgb_.push_back(srgb);
    fallbackImage_.push_back(fallback);
    textureWebp_.push_back(webp >= 0);
    textureMap_[key] = index;
    return index;
  }

  // EXT_texture_webp: the texture's WebP image (-1: the extension is absent). A source that is no image of
  // the file is refused, naming the extension.
  int webpSource(int gltfTexture) const {
    const json* tj = element(src_.json, "textures", static_cast<size_t>(gltfTexture));
    const json* ext = tj ? path(*tj, {"extensions", "EXT_texture_webp"}) : nullptr;
    if (!ext) return -1;
    const json* source = child(*ext, "source");
    const int64_t images = static_cast<int64_t>(model_.images.size());
    if (!source || !source->is_number_integer() || source->get<int64_t>() < 0 || source->get<int64_t>() >= images)
      invalid("texture " + std::to_string(gltfTexture) + ": EXT_texture_webp source " + (source ? source->dump() : "(missing)") +
              " is not an image of the file (" + std::to_string(images) + " images)");
    return source->get<int>();
  }

  // Decodes every used texture, in parallel (JPEG/PNG decoding dominates load time on textured scenes).
  void decodeTextures() {
    if (!options_.decodeImages || scene_.textures.empty()) return;
    const size_t n = scene_.textures.size();
    std::vector<std::string> failures(n);
    std::atomic<size_t> next{0};
    auto work = [&]() {
      for (size_t i = next++; i < n; i = next++) {
        Texture& tex = scene_.textures[i];
        const auto& img = model_.images[tex.gltfImage];
        if (img.image.empty() && !textureWebp_[i]) {
          failures[i] = "image " + std::to_string(tex.gltfImage) + " '" + tex.name + "' has no data (file missing?): treated as white";
          continue;
        }
        try {
          decodeInto(tex, img.image, textureSrgb_[i]);
        } catch (const Error& e) {
          if (!textureWebp_[i]) {
            failures[i] = "image " + std::to_string(tex.gltfImage) + " '" + tex.name + "' cannot be decoded (treated as white): " + e.what();
            continue;
          }
          const int fallback = fallbackImage_[i];
          if (fallback < 0 || model_.images[fallback].image.empty()) {
            failures[i] = "EXT_texture_webp: image " + std::to_string(tex.gltfImage) + " '" + tex.name +
                          "' cannot be read (" + e.what() + ") and the texture has no fallback source";
            continue;
          }
          failures[i] = "EXT_texture_webp: image " + std::to_string(tex.gltfImage) + " '" + tex.name +
                        "' cannot be read; its fallback image " + std::to_string(fallback) + " is used";
          try {
            decodeInto(tex, model_.images[fallback].image, textureSrgb_[i]);
          } catch (const Error& e2) {
            failures[i] += ", which cannot be decoded either (treated as white): " + std::string(e2.what());
          }
        }
      }
    };
    unsigned threads = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), static_cast<unsigned>(n)));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    for (size_t i = 0; i < n; ++i)
      if (textureWebp_[i] && scene_.textures[i].texels.empty()) invalid(failures[i]);
    for (const auto& f : failures)
      if (!f.empty()) warn(f);
  }

  static void decodeInto(Texture& tex, const std::vector<unsigned char>& bytes, bool srgb) {
    Texture decoded = decodeImageToTexture(bytes.data(), bytes.size(), srgb, tex.name);
    tex.width = decoded.width;
    tex.height = decoded.height;
    tex.texels = std::move(decoded.texels);
  }

  // An irbake export's sky (root extras "irbakeSky", export/gltf_export.h): a uniform sky is restored; for a
  // map the mean radiance stands in (the viewer's background) unless the file is still there.
  void readSky() {
    const json* sky = path(src_.json, {"extras", "irbakeSky"});
    if (!sky || !sky->is_object()) return;
    auto rgb = [](const json* a, glm::vec3& out) {
      if (!a || !a->is_array() || a->size() != 3) return false;
      for (int c = 0; c < 3; ++c) {
        if (!(*a)[c].is_number()) return false;
        out[c] = (*a)[c].get<float>();
        if (!(out[c] >= 0.0f) || !std::isfinite(out[c])) return false;
      }
      return true;
    };
    glm::vec3 L(0.0f);
    if (rgb(child(*sky, "radiance"), L)) {
      scene_.environment = Environment::uniform(L);
      return;
    }
    const json* file = child(*sky, "environment");
    const bool hasMean = rgb(child(*sky, "meanRadiance"), L);
    if (file && file->is_string() && std::filesystem::exists(file->get<std::string>())) {
      const float degrees = static_cast<float>(numberOr(child(*sky, "rotation"), 0.0) * 180.0 / kPi);
      scene_.environment = loadEnvironment(file->get<std::string>(), 1.0f, degrees);
      // The export records no --env-intensity, but its mean radiance is the file's × intensity: recover it.
      const glm::dvec3 fileMean = scene_.environment.integral() / (4.0 * kPi);
      const double fileSum = fileMean.x + fileMean.y + fileMean.z, intensity = (double(L.x) + L.y + L.z) / fileSum;
      if (hasMean && fileSum > 0.0 && std::isfinite(intensity) && std::abs(intensity - 1.0) > 1e-6) {
        const Environment& e = scene_.environment;  // scaled from the texels already read, not read again
        scene_.environment = Environment::fromEquirect(e.width(), e.height(), e.texels(), static_cast<float>(intensity),
                                                       e.rotation(), e.source());
      }
      return;
    }
    if (hasMean) scene_.environment = Environment::uniform(L);
  }

  void readLightmapPages() {
    const json* pages = path(src_.json, {"extras", "lightmapPages"});
    if (!pages || !pages->is_array()) return;
    for (const auto& p : *pages)
      if (p.is_string()) scene_.lightmapExrPaths.push_back((src_.folder / decodeUriEscapes(p.get<std::string>())).string());
  }

  GltfSource src_;
  const LoadOptions& options_;
  std::string file_;
  std::unique_ptr<IesLightReader> iesLights_;  // EXT_lights_ies, made by the first node that has one
  tinygltf::Model model_;
  Scene scene_;
  std::map<std::pair<int, int>, LocalPrimitive> localCache_;
  std::vector<int> materialMap_;
  int defaultMaterial_ = -1;
  std::map<std::pair<int, bool>, int> textureMap_;
  std::vector<bool> textureSrgb_;
  std::vector<int> fallbackImage_;   // per scene texture: EXT_texture_webp's fallback image (-1 none)
  std::vector<bool> textureWebp_;    // per scene texture: read through EXT_texture_webp
  bool warnedTextureTransform_ = false;
  std::map<int, ObjectSettings> meshSettings_;      // extras.irbake of each mesh, read once
  std::set<std::string> unknownSettingsWarned_;     // unknown extras.irbake keys already named
  size_t gpuInstanceTotal_ = 0;
};

}  // namespace

Scene loadScene(const std::filesystem::path& path, const LoadOptions& options) {
  return Loader(readGltfSource(path), options).load();
}

Scene loadSceneFromBytes(std::vector<uint8_t> bytes, const std::filesystem::path& path, const LoadOptions& options) {
  return Loader(gltfSourceFromBytes(std::move(bytes), path), options).load();
}

void requireLight(const Scene& scene, const std::filesystem::path& path) {
  if (!scene.hasLightOrEmitter())
    throw Error(ErrorCode::NoLight, path.string(),
                "no light and no emissive material: add KHR_lights_punctual lights or emissive materials, "
                "or give a light on the command line (--sun DIRX,DIRY,DIRZ,IRRADIANCE)");
}

}  // namespace irbake
