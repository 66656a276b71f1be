#include "pipeline/light_modes.h"

#include "common/error.h"
#include "common/excerpt.h"

namespace irbake {

namespace {

bool isSun(const Light& light) {
  return light.node < 0 && light.gltfLight < 0 && light.name.rfind("sun (command line)", 0) == 0;
}

// The I of "#I" or "index:I" (digits only); -1 for anything else.
int lightIndex(const std::string& digits) {
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(digits);
}

// "#I" (appended, not "#" + text: GCC 12 warns falsely on that).
std::string hashIndex(int index) {
  std::string text = "#";
  text += std::to_string(index);
  return text;
}

// A glTF name that a plain selector would read as something else: it is addressed as name:TEXT.
bool nameNeedsPrefix(const std::string& name) {
  return name == "*" || name == "sun" || (name.size() > 1 && name[0] == '#' && lightIndex(name.substr(1)) >= 0) ||
         name.rfind("name:", 0) == 0 || name.rfind("index:", 0) == 0 || name.rfind("option:", 0) == 0;
}

// How a light is addressed without ambiguity, for the list of a refusal.
std::string selectorOf(const Scene& scene, const Light& light) {
  if (isSun(light)) {
    for (const Light& l : scene.lights)
      if (!isSun(l) && l.name == "sun") return "option:sun";
    return "sun";
  }
  if (light.name.empty()) return hashIndex(light.gltfLight);
  return nameNeedsPrefix(light.name) ? "name:" + light.name : light.name;
}

std::string describe(const Light& light) {
  if (isSun(light)) return "the --sun light";
  std::string d = "KHR light " + std::to_string(light.gltfLight);
  return light.name.empty() ? d : d + " (" + quotedExcerpt(light.name) + ")";
}

// "--light-mode NAME=MODE" as given on the command line, or where the config file gave it.
std::string requestText(const LightModeRequest& request) {
  const std::string entry = request.light + "=" + toString(request.mode);
  const std::string shown = quotedExcerpt(entry);
  if (!request.origin.empty()) return request.origin + " (" + shown + ")";
  return "--light-mode " + (shown == "'" + entry + "'" ? entry : shown);
}

// A request that names no punctual light: something that stays baked (the sky, an emitter), or nothing.
[[noreturn]] void refuseName(const Scene& scene, const LightModeRequest& request) {
  const std::string what = requestText(request), name = quotedExcerpt(request.light);
  if (request.light == "sky" || request.light == "env")
    throw Error(ErrorCode::Usage, scene.sourcePath, what + ": " + name + " is not a punctual light (the sky and emitters stay baked)");
  for (const Primitive& p : scene.primitives) {
    const Material& m = scene.materials[static_cast<size_t>(p.material)];
    if ((p.name == request.light || m.name == request.light) && m.isEmissive())
      throw Error(ErrorCode::Usage, scene.sourcePath,
                  what + ": " + name + " is an emissive surface, not a punctual light (emitters stay baked)");
  }
  const std::string known = knownLightSelectors(scene);
  throw Error(ErrorCode::Usage, scene.sourcePath,
              what + ": no punctual light is named " + name + " (" +
                  (known.empty() ? std::string("the scene has none") : "its punctual lights: " + known) + ")");
}

// The lights a selector other than "*" addresses. Throws Error(Usage) when a plain `sun` or `#I` also is the
// glTF name of another light.
std::vector<size_t> selectedLights(const Scene& scene, const std::string& text, const std::string& what) {
  auto where = [&](auto&& test) {
    std::vector<size_t> found;
    for (size_t i = 0; i < scene.lights.size(); ++i)
      if (test(scene.lights[i])) found.push_back(i);
    return found;
  };
  auto named = [&](const std::string& name) { return where([&](const Light& l) { return !isSun(l) && l.name == name; }); };
  auto indexed = [&](int index) { return where([&](const Light& l) { return index >= 0 && l.gltfLight == index; }); };
  auto sun = [&] { return where(isSun); };
  if (text.rfind("name:", 0) == 0) return named(text.substr(5));
  if (text.rfind("index:", 0) == 0) return indexed(lightIndex(text.substr(6)));
  if (text == "option:sun") return sun();
  std::vector<size_t> keyword;
  std::string explicitForm;
  if (text == "sun") {
    keyword = sun();
    explicitForm = "option:sun";
  } else if (text.size() > 1 && text[0] == '#' && lightIndex(text.substr(1)) >= 0) {
    keyword = indexed(lightIndex(text.substr(1)));
    explicitForm = "index:" + text.substr(1);
  }
  const std::vector<size_t> byName = named(text);
  if (!keyword.empty() && !byName.empty() && keyword != byName)
    throw Error(ErrorCode::Usage, scene.sourcePath,
                what + ": '" + text + "' is ambiguous: it addresses " +
                    describe(scene.lights[keyword[0]]) + " and the light named '" + text + "', " +
                    describe(scene.lights[byName[0]]) + "; write " + explicitForm + " for the first, name:" + text +
                    " for the second");
  return keyword.empty() ? byName : keyword;
}

}  // namespace

std::vector<size_t> lightsSelectedBy(const Scene& scene, const std::string& selector, const std::string& what) {
  return selectedLights(scene, selector, what);
}

std::string knownLightSelectors(const Scene& scene) {
  std::string known;
  for (const Light& l : scene.lights) known += (known.empty() ? "" : ", ") + selectorOf(scene, l);
  return known;
}

bool isCommandLineSun(const Light& light) { return isSun(light); }

std::string lightModeName(const Light& light) {
  if (isSun(light)) return "sun";
  if (!light.name.empty()) return light.name;
  return hashIndex(light.gltfLight);
}

std::vector<RequestedLightMode> resolveLightModes(const Scene& scene, const std::vector<LightModeRequest>& requests) {
  std::vector<RequestedLightMode> modes(scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    modes[i].reason = "default";
    if (l.hasExtrasMode) modes[i] = {l.extrasMode, "extras.irbake.mode in the glTF", true};
  }
  // "*" first, then the named ones: a name wins over "*" whatever the order; within each, the last wins.
  for (const bool star : {true, false})
    for (const LightModeRequest& r : requests) {
      if ((r.light == "*") != star) continue;
      if (star && scene.lights.empty())
        throw Error(ErrorCode::Usage, scene.sourcePath, requestText(r) + ": the scene has no punctual light");
      std::vector<size_t> lights;
      if (star) {
        for (size_t i = 0; i < scene.lights.size(); ++i) lights.push_back(i);
      } else {
        lights = selectedLights(scene, r.light, requestText(r));
      }
      if (lights.empty()) refuseName(scene, r);
      for (const size_t i : lights) modes[i] = {r.mode, requestText(r), true};
    }
  // No client shades an IES profile in real time: its direct light stays in the map.
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].type == LightType::Ies && modes[i].mode != LightMode::Baked)
      modes[i] = {LightMode::Baked, "an EXT_lights_ies light stays baked (" + modes[i].reason + " ignored)", true};
  return modes;
}

}  // namespace irbake
