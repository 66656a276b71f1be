#include "scene/ies_lights_gltf.h"

#include <cmath>
#include <fstream>
#include <iterator>

#include <tiny_gltf.h>

#include "common/base64.h"
#include "common/error.h"
#include "scene/scene_limits.h"

namespace irbake {

namespace {

using nlohmann::json;

constexpr uintmax_t kMaxProfileBytes = 16u << 20;  // far beyond any measured profile
constexpr const char* kIesMimeType = "application/x-ies-lm-63";

const json* member(const json& object, const char* key) {
  return object.is_object() && object.contains(key) ? &object[key] : nullptr;
}

}  // namespace

IesLightReader::IesLightReader(const GltfSource& source, const tinygltf::Model& model, std::string file)
    : source_(source), model_(model), file_(std::move(file)) {}

void IesLightReader::invalid(const std::string& message) const {
  throw Error(ErrorCode::InvalidData, file_, message);
}

std::shared_ptr<const IesProfile> IesLightReader::profile(int index) {
  if (auto it = profiles_.find(index); it != profiles_.end()) return it->second;
  const json* lights = member(source_.json, "extensions");
  lights = lights ? member(*lights, "EXT_lights_ies") : nullptr;
  lights = lights ? member(*lights, "lights") : nullptr;
  const std::string what = "EXT_lights_ies light " + std::to_string(index);
  if (!lights || !lights->is_array() || index < 0 || index >= static_cast<int>(lights->size()))
    invalid(what + ": no such light in the root's extensions.EXT_lights_ies.lights (it has " +
            std::to_string(lights && lights->is_array() ? lights->size() : 0) + ")");
  const json& entry = (*lights)[static_cast<size_t>(index)];
  std::string text, where;
  if (const json* uri = member(entry, "uri")) {
    if (!uri->is_string()) invalid(what + ": uri is not a string");
    const std::string u = uri->get<std::string>();
    if (u.rfind("data:", 0) == 0) {
      const size_t comma = u.find(',');
      if (comma == std::string::npos || u.substr(0, comma).find(";base64") == std::string::npos)
        invalid(what + ": a data URI must be base64");
      text = base64Decode(u.substr(comma + 1));
      where = "data URI";
    } else {
      const std::string decoded = decodeUriEscapes(u);
      if (!uriStaysInFolder(decoded)) invalid(what + ": uri '" + u.substr(0, 80) + "' leaves the scene's folder");
      const std::filesystem::path path = source_.folder / decoded;
      std::error_code ec;
      const uintmax_t size = std::filesystem::file_size(path, ec);
      if (ec) invalid(what + ": cannot read the profile " + path.string());
      if (size > kMaxProfileBytes) invalid(what + ": the profile " + path.string() + " is larger than 16 MiB");
      std::ifstream in(path, std::ios::binary);
      text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      where = path.string();
    }
  } else if (const json* view = member(entry, "bufferView")) {
    const json* mime = member(entry, "mimeType");
    if (!mime || !mime->is_string() || mime->get<std::string>() != kIesMimeType)
      invalid(what + ": a bufferView profile needs mimeType \"" + kIesMimeType + "\"");
    if (!view->is_number_integer() || view->get<int64_t>() < 0 ||
        view->get<int64_t>() >= static_cast<int64_t>(model_.bufferViews.size()))
      invalid(what + ": bufferView " + view->dump().substr(0, 40) + " is not a buffer view of the file");
    const int v = view->get<int>();
    const auto& bv = model_.bufferViews[static_cast<size_t>(v)];
    if (bv.buffer < 0 || bv.buffer >= static_cast<int>(model_.buffers.size()) ||
        bv.byteOffset + bv.byteLength > model_.buffers[static_cast<size_t>(bv.buffer)].data.size())
      invalid(what + ": bufferView " + std::to_string(v) + " lies outside its buffer");
    const auto& data = model_.buffers[static_cast<size_t>(bv.buffer)].data;
    text.assign(data.begin() + static_cast<std::ptrdiff_t>(bv.byteOffset),
                data.begin() + static_cast<std::ptrdiff_t>(bv.byteOffset + bv.byteLength));
    where = "bufferView " + std::to_string(v);
  } else {
    invalid(what + ": needs a uri or a bufferView");
  }
  try {
    return profiles_[index] = std::make_shared<const IesProfile>(parseIesProfile(text, where));
  } catch (const Error& e) {
    invalid(what + " (" + e.what() + ")");
  }
}

Light IesLightReader::light(int n, const json& ext, const glm::mat4& world) {
  const std::string node = "node " + std::to_string(n) + ": EXT_lights_ies";
  const json* index = member(ext, "light");
  if (!index || !index->is_number_integer()) invalid(node + " needs \"light\", an index into the root's lights");
  const int li = index->get<int>();
  Light light;
  light.type = LightType::Ies;
  light.profile = profile(li);
  const json& entry = source_.json["extensions"]["EXT_lights_ies"]["lights"][static_cast<size_t>(li)];
  if (const json* name = member(entry, "name"); name && name->is_string()) light.name = name->get<std::string>();
  if (light.name.empty() && n < static_cast<int>(model_.nodes.size())) light.name = model_.nodes[static_cast<size_t>(n)].name;
  if (const json* m = member(ext, "multiplier")) {
    if (!m->is_number() || !std::isfinite(m->get<double>()) || m->get<double>() < 0.0)
      invalid(node + ": multiplier " + m->dump().substr(0, 40) + " must be a finite number ≥ 0");
    light.intensity = m->get<float>();
  }
  if (const json* c = member(ext, "color")) {
    if (!c->is_array() || c->size() != 3) invalid(node + ": color must hold 3 numbers");
    for (int k = 0; k < 3; ++k) {
      const json& v = (*c)[static_cast<size_t>(k)];
      if (!v.is_number() || !std::isfinite(v.get<double>())) invalid(node + ": color " + c->dump().substr(0, 60) + " is not 3 finite numbers");
      light.color[k] = std::clamp(v.get<float>(), 0.0f, 1.0f);  // the specification clamps it to [0, 1]
    }
  }
  light.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
  const float far = glm::max(glm::abs(light.position.x), glm::max(glm::abs(light.position.y), glm::abs(light.position.z)));
  if (!(far <= kMaxSceneCoordinate * (1.0 + kSceneLimitSlack)))
    invalid(node + ": the light lies beyond the supported " + std::to_string(kMaxSceneCoordinate) + " m");
  // The node's rotation only: its −Z the nadir, its +X (made orthogonal to it) the horizontal angle 0.
  const glm::vec3 down = glm::vec3(world * glm::vec4(0, 0, -1, 0)), across = glm::vec3(world * glm::vec4(1, 0, 0, 0));
  if (!(glm::length(down) > 0.0f)) invalid(node + ": the node's transform collapses the light's axis");
  light.direction = glm::normalize(down);
  glm::vec3 x = across - light.direction * glm::dot(across, light.direction);
  if (!(glm::length(x) > 1e-6f * glm::length(across)) || !(glm::length(x) > 0.0f))
    x = std::abs(light.direction.x) < 0.9f ? glm::vec3(1, 0, 0) - light.direction * light.direction.x
                                           : glm::vec3(0, 1, 0) - light.direction * light.direction.y;
  light.profileAxisX = glm::normalize(x);
  light.node = n;
  return light;
}

}  // namespace irbake
