#include "scene/runtime_lights.h"

#include <cmath>

#include "common/error.h"

namespace irbake {

namespace {

using nlohmann::json;

[[noreturn]] void invalid(const std::string& file, const std::string& message) {
  throw Error(ErrorCode::InvalidData, file, message);
}

bool finiteVec3(const json* a, glm::vec3& out) {
  if (!a || !a->is_array() || a->size() != 3) return false;
  for (int c = 0; c < 3; ++c) {
    if (!(*a)[c].is_number()) return false;
    out[c] = (*a)[c].get<float>();
    if (!std::isfinite(out[c])) return false;
  }
  return true;
}

const json* member(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

// A directional light from {"direction": [travel], "irradiance": [W/m²]} (the command line's sun).
Light directionalLight(const json& j, const std::string& what, const std::string& file) {
  glm::vec3 d, e;
  if (!finiteVec3(member(j, "direction"), d) || !(glm::length(d) > 0.0f))
    invalid(file, what + ": needs a finite, non-zero \"direction\" [x, y, z]");
  if (!finiteVec3(member(j, "irradiance"), e) || e.x < 0.0f || e.y < 0.0f || e.z < 0.0f)
    invalid(file, what + ": needs a finite \"irradiance\" [r, g, b] ≥ 0");
  Light l;
  l.type = LightType::Directional;
  l.name = "sun";
  l.direction = glm::normalize(d);
  l.color = e;
  l.intensity = 1.0f;
  return l;
}

}  // namespace

std::vector<RuntimeLight> readRuntimeLights(const json& root, const std::vector<Light>& lights, size_t khrLightCount,
                                            const std::string& file) {
  std::vector<int> channelOfKhr(khrLightCount, -1);
  std::vector<RuntimeLight> out;
  bool maskedSun = false;
  const json* ext = member(root, "extensions");
  const json* mask = ext ? member(*ext, "IRBAKE_shadowmask") : nullptr;
  if (mask) {
    const json* entries = member(*mask, "lights");
    if (!entries || !entries->is_array())
      invalid(file, "root IRBAKE_shadowmask needs \"lights\": an array mapping lights to channels");
    for (size_t i = 0; i < entries->size(); ++i) {
      const json& e = (*entries)[i];
      const std::string what = "IRBAKE_shadowmask.lights[" + std::to_string(i) + "]";
      const json* channel = member(e, "channel");
      if (!channel || !channel->is_number_integer() || channel->get<int64_t>() < 0 || channel->get<int64_t>() > 3)
        invalid(file, what + ": channel must be an integer 0..3 (R, G, B, A)");
      const int c = channel->get<int>();
      if (const json* light = member(e, "light")) {
        if (!light->is_number_integer() || light->get<int64_t>() < 0 ||
            light->get<int64_t>() >= static_cast<int64_t>(khrLightCount))
          invalid(file, what + ": light " + light->dump() + " is not a KHR_lights_punctual light of the file (it has " +
                            std::to_string(khrLightCount) + ")");
        int& slot = channelOfKhr[light->get<size_t>()];
        if (slot >= 0 && slot != c) invalid(file, what + ": light " + light->dump() + " is given two channels");
        slot = c;
      } else if (const json* d = member(e, "directional")) {
        out.push_back({directionalLight(*d, what + ".directional", file), LightMode::ShadowMask, c});
        maskedSun = true;
      } else {
        invalid(file, what + ": needs \"light\" (a KHR_lights_punctual index) or \"directional\"");
      }
    }
  }
  for (const Light& l : lights) {
    if (l.gltfLight < 0 || static_cast<size_t>(l.gltfLight) >= khrLightCount) continue;
    const int c = channelOfKhr[static_cast<size_t>(l.gltfLight)];
    if (c >= 0) {
      out.push_back({l, LightMode::ShadowMask, c});
    } else if (l.hasExtrasMode && l.extrasMode != LightMode::Baked) {
      // A shadowmask light the channel map does not list was left without a channel: it shades unshadowed.
      out.push_back({l, LightMode::Indirect, -1});
    }
  }
  const json* extras = member(root, "extras");
  const json* sun = extras ? member(*extras, "irbakeSun") : nullptr;
  if (sun && !maskedSun) {
    const json* mode = member(*sun, "mode");
    LightMode m = LightMode::Baked;
    if (!mode || !mode->is_string() || !parseLightMode(mode->get<std::string>(), m))
      invalid(file, "extras.irbakeSun.mode must be \"baked\", \"indirect\" or \"shadowmask\"");
    if (m != LightMode::Baked) out.push_back({directionalLight(*sun, "extras.irbakeSun", file), LightMode::Indirect, -1});
  }
  return out;
}

}  // namespace irbake
