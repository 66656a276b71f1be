#include "pipeline/light_groups.h"

#include <cmath>
#include <map>
#include <memory>

#include "common/error.h"
#include "common/excerpt.h"
#include "common/log.h"
#include "pipeline/bake_plan.h"
#include "pipeline/light_modes.h"
#include "stages/error_estimate/error_estimate.h"
#include "stages/probes/light_probes.h"

namespace irbake {

namespace {

using json = nlohmann::json;

// One light source of the scene: a light (the --sun light included), the sky or an emissive material.
struct Source {
  enum Kind { LightSource, Sky, MaterialSource } kind = LightSource;
  size_t index = 0;  // into Scene::lights or Scene::materials
};

std::string describe(const Scene& scene, const Source& s) {
  if (s.kind == Source::Sky) return "the sky (--sky / --env)";
  if (s.kind == Source::MaterialSource)
    return "emissive material " + quotedExcerpt(scene.materials[s.index].name.empty() ? "#" + std::to_string(s.index)
                                                                                       : scene.materials[s.index].name);
  const Light& l = scene.lights[s.index];
  return isCommandLineSun(l) ? std::string("the --sun light") : "light " + quotedExcerpt(lightModeName(l));
}

json sourceJson(const Scene& scene, const Source& s) {
  if (s.kind == Source::Sky) return {{"sky", true}};
  if (s.kind == Source::MaterialSource)
    return {{"material", scene.materials[s.index].gltfMaterial}, {"name", scene.materials[s.index].name}};
  const Light& l = scene.lights[s.index];
  if (isCommandLineSun(l)) return {{"sun", true}};
  return {{"light", l.gltfLight}, {"name", l.name}};
}

// Emissive materials some baked object uses (an unused one lights nothing).
std::vector<size_t> emissiveMaterials(const Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (const Primitive& p : scene.primitives)
    if (p.mode != ObjectMode::Off) used[static_cast<size_t>(p.material)] = true;
  std::vector<size_t> out;
  for (size_t m = 0; m < scene.materials.size(); ++m)
    if (used[m] && scene.materials[m].isEmissive()) out.push_back(m);
  return out;
}

class GroupResolver {
 public:
  explicit GroupResolver(const Scene& scene) : scene_(scene), emissive_(emissiveMaterials(scene)) {
    for (size_t i = 0; i < scene.lights.size(); ++i) sources_.push_back({Source::LightSource, i});
    if (scene.environment.present()) sources_.push_back({Source::Sky, 0});
    for (const size_t m : emissive_) sources_.push_back({Source::MaterialSource, m});
    owner_.assign(sources_.size(), -1);
  }

  void request(const LightGroupRequest& r) {
    const std::string what = r.origin.empty() ? "--light-group " + quotedExcerpt(r.name) : r.origin;
    const int g = group(r.name, what);
    if (r.sources.empty()) throw Error(ErrorCode::Usage, scene_.sourcePath, what + ": names no light (NAME=LIGHTS)");
    for (const std::string& selector : r.sources) {
      if (selector == "*") {
        if (star_ >= 0 && star_ != g)
          throw Error(ErrorCode::Usage, scene_.sourcePath, what + ": '*' is already group '" + groups_[static_cast<size_t>(star_)].name + "'s");
        star_ = g;
        continue;
      }
      const std::vector<size_t> found = select(selector, what);
      if (found.empty()) refuseUnknown(selector, what);
      for (const size_t s : found) assign(s, g, what);
    }
  }

  void extras() {
    for (size_t s = 0; s < sources_.size(); ++s) {
      const Source& src = sources_[s];
      const std::string& name = src.kind == Source::LightSource ? scene_.lights[src.index].group
                                : src.kind == Source::MaterialSource ? scene_.materials[src.index].group
                                                                      : std::string();
      if (name.empty()) continue;
      const std::string what = describe(scene_, src) + ": extras.irbake.group";  // the Error names the file
      assign(s, group(name, what), what);
    }
  }

  std::vector<LightGroup> finish() {
    if (groups_.empty()) return {};
    std::string unplaced;
    for (size_t s = 0; s < sources_.size(); ++s) {
      if (owner_[s] >= 0) continue;
      if (star_ >= 0) owner_[s] = star_;
      else unplaced += (unplaced.empty() ? "" : ", ") + describe(scene_, sources_[s]);
    }
    if (!unplaced.empty())
      throw Error(ErrorCode::Usage, scene_.sourcePath,
                  "light groups: " + unplaced + " in no group (name it in one, or give a group '*' for the rest)");
    for (size_t s = 0; s < sources_.size(); ++s) {
      LightGroup& g = groups_[static_cast<size_t>(owner_[s])];
      const Source& src = sources_[s];
      if (src.kind == Source::LightSource) g.lights.push_back(src.index);
      else if (src.kind == Source::Sky) g.sky = true;
      else g.materials.push_back(src.index);
      g.sources.push_back(sourceJson(scene_, src));
    }
    for (const LightGroup& g : groups_)
      if (g.size() == 0)
        throw Error(ErrorCode::Usage, scene_.sourcePath, "light group '" + g.name + "' holds no light source" +
                                                             (star_ >= 0 ? "" : " (every source it names is in another group)"));
    return groups_;
  }

 private:
  int group(const std::string& name, const std::string& what) {
    if (!validLayerName(name))
      throw Error(ErrorCode::Usage, scene_.sourcePath,
                  what + ": the group name " + quotedExcerpt(name) + " must be 1 to 64 of A-Z a-z 0-9 _ -");
    if (otherPageName(name))
      throw Error(ErrorCode::Usage, scene_.sourcePath,
                  what + ": the group name " + quotedExcerpt(name) + " is what the shadow-mask or L1 pages are called");
    for (size_t g = 0; g < groups_.size(); ++g)
      if (groups_[g].name == name) return static_cast<int>(g);
    groups_.push_back(LightGroup{name, {}, false, {}, json::array()});
    return static_cast<int>(groups_.size() - 1);
  }

  void assign(size_t s, int g, const std::string& what) {
    if (owner_[s] >= 0 && owner_[s] != g)
      throw Error(ErrorCode::Usage, scene_.sourcePath,
                  what + ": " + describe(scene_, sources_[s]) + " is in group '" + groups_[static_cast<size_t>(owner_[s])].name +
                      "' already; a source belongs to one group only (not also '" + groups_[static_cast<size_t>(g)].name + "')");
    owner_[s] = g;
  }

  size_t sourceOfLight(size_t light) const { return light; }  // lights come first in sources_
  size_t sourceOfMaterial(size_t material) const {
    for (size_t s = 0; s < sources_.size(); ++s)
      if (sources_[s].kind == Source::MaterialSource && sources_[s].index == material) return s;
    return sources_.size();
  }

  std::vector<size_t> select(const std::string& selector, const std::string& what) const {
    std::vector<size_t> found;
    if (selector == "sky") {
      for (size_t s = 0; s < sources_.size(); ++s)
        if (sources_[s].kind == Source::Sky) found.push_back(s);
      return found;
    }
    if (selector == "emissive" || selector.rfind("emissive:", 0) == 0) {
      const std::string name = selector == "emissive" ? std::string() : selector.substr(9);
      for (const size_t m : emissive_)
        if (name.empty() || scene_.materials[m].name == name) found.push_back(sourceOfMaterial(m));
      return found;
    }
    for (const size_t l : lightsSelectedBy(scene_, selector, what)) found.push_back(sourceOfLight(l));
    return found;
  }

  [[noreturn]] void refuseUnknown(const std::string& selector, const std::string& what) const {
    std::string known = knownLightSelectors(scene_);
    if (scene_.environment.present()) known += std::string(known.empty() ? "" : ", ") + "sky";
    for (const size_t m : emissive_) known += (known.empty() ? "" : ", ") + ("emissive:" + scene_.materials[m].name);
    throw Error(ErrorCode::Usage, scene_.sourcePath,
                what + ": no light source answers to " + quotedExcerpt(selector) + " (" +
                    (known.empty() ? std::string("the scene has none") : "its sources: " + known) + ")");
  }

  const Scene& scene_;
  std::vector<size_t> emissive_;
  std::vector<Source> sources_;
  std::vector<int> owner_;  // per source: its group, -1 none yet
  std::vector<LightGroup> groups_;
  int star_ = -1;
};

// What groups do not support yet, refused before any work.
void checkGroupedOptions(const Scene& scene, const BakeOptions& options) {
  if (options.directional)
    throw Error(ErrorCode::Usage, scene.sourcePath, "light groups do not split --directional's L1 pages yet: drop one of them");
  if (!options.lightModes.empty())
    throw Error(ErrorCode::Usage, scene.sourcePath, "light groups bake every light's direct light: drop --light-mode");
  for (const Light& l : scene.lights)
    if (l.hasExtrasMode && l.extrasMode != LightMode::Baked)
      throw Error(ErrorCode::Usage, scene.sourcePath,
                  "light groups bake every light's direct light: light " + quotedExcerpt(lightModeName(l)) +
                      " has extras.irbake.mode \"" + toString(l.extrasMode) + "\"");
}

// The sum's estimatedError: independent groups, so their absolute errors add in quadrature; relative to the
// sum's own signal on the same bins.
void combineErrors(const std::vector<GroupPart>& parts, const std::vector<Lightmap>& sum, json& report) {
  double noise2 = 0.0;
  for (const GroupPart& p : parts) {
    if (!p.report.contains("estimatedError")) {  // an earlier bake's layer without its report: no sum to give
      report.erase("estimatedError");
      return;
    }
    const json& e = p.report["estimatedError"];
    const double absolute = e.value("relative", 0.0) * e.value("signalRms", 0.0);
    noise2 += absolute * absolute;
  }
  const int bin = report["estimatedError"].value("bin", 4);
  const BinnedError signal = replicateError({sum, sum}, &sum, bin);
  json e = report["estimatedError"];
  e["noiseRms"] = std::sqrt(noise2);
  e["signalRms"] = signal.signalRms;
  e["relative"] = signal.signalRms > 0.0 ? std::sqrt(noise2) / signal.signalRms : 0.0;
  e["method"] = "the light groups' estimates, absolute errors in quadrature";
  report["estimatedError"] = e;
}

// Per texel: the groups' standard errors in quadrature.
std::vector<Lightmap> combinedStandardError(const std::vector<GroupPart>& parts) {
  std::vector<Lightmap> out = parts.front().standardError;
  for (Lightmap& m : out)
    for (glm::vec3& t : m.texels) t *= t;
  for (size_t g = 1; g < parts.size(); ++g)
    for (size_t p = 0; p < out.size() && p < parts[g].standardError.size(); ++p)
      for (size_t t = 0; t < out[p].texels.size(); ++t) out[p].texels[t] += parts[g].standardError[p].texels[t] * parts[g].standardError[p].texels[t];
  for (Lightmap& m : out)
    for (glm::vec3& t : m.texels) t = glm::sqrt(t);
  return out;
}

}  // namespace

GroupPart groupPart(const LightGroup& group, const std::vector<Light>& lights, BakeResult& r) {
  GroupPart part;
  part.layer.name = group.name;
  part.layer.lights = group.sources;
  part.layer.maps = std::move(r.maps);
  part.layer.probes = r.probes.coefficients;
  for (const size_t l : group.lights) part.layer.holdsSun = part.layer.holdsSun || isCommandLineSun(lights[l]);
  part.layer.holdsSun = part.layer.holdsSun && r.probes.sun.present();
  part.sun = r.probes.sun;
  part.emitters = r.probes.emitters;
  part.standardError = std::move(r.standardError);
  part.report = std::move(r.report);
  return part;
}

void sumParts(std::vector<GroupPart>& parts, BakeResult& total, const std::vector<glm::vec3>& weights, size_t reportFrom) {
  for (GroupPart& p : parts) total.layers.push_back(p.layer);
  CombinedLayers sum = combineLayers(total.layers, weights);
  total.maps = std::move(sum.maps);
  total.probes.coefficients = std::move(sum.probes);
  total.probes.sun = {};
  total.probes.emitters.clear();
  for (size_t g = 0; g < parts.size(); ++g) {
    const GroupPart& p = parts[g];
    if (p.layer.holdsSun) {
      total.probes.sun = p.sun;
      total.probes.sun.irradiance *= weights[g];
      for (glm::vec3& c : total.probes.sun.sh) c *= weights[g];
    }
    total.probes.emitters.insert(total.probes.emitters.end(), p.emitters.begin(), p.emitters.end());
  }
  bool everyError = true;
  for (const GroupPart& p : parts) everyError = everyError && !p.standardError.empty();
  if (everyError) total.standardError = combinedStandardError(parts);
  json& report = total.report = parts[reportFrom].report;
  json list = json::array();
  double seconds = 0.0, cpuSeconds = 0.0;
  for (const GroupPart& p : parts) {
    json entry = {{"name", p.layer.name}, {"lights", p.layer.lights}, {"timings", p.report["timings"]}};
    if (p.report.contains("estimatedError")) entry["estimatedError"] = p.report["estimatedError"];
    if (p.report.contains("vpls")) entry["vpls"] = p.report["vpls"];
    if (p.carried) entry["carried"] = true;
    list.push_back(std::move(entry));
    seconds += p.report["timings"]["seconds"].value("bake", 0.0);
    cpuSeconds += p.report["timings"]["cpuSeconds"].value("bake", 0.0);
  }
  report["lightGroups"] = std::move(list);
  report["timings"]["seconds"]["bake"] = seconds;
  report["timings"]["cpuSeconds"]["bake"] = cpuSeconds;
  report["timings"]["memoryPeakMiB"] = peakMemoryMiB();
  if (report.contains("estimatedError")) combineErrors(parts, total.maps, report);
}

std::vector<LightGroup> resolveLightGroups(const Scene& scene, const std::vector<LightGroupRequest>& requests) {
  GroupResolver resolver(scene);
  for (const LightGroupRequest& r : requests) resolver.request(r);
  resolver.extras();
  return resolver.finish();
}

Scene groupScene(Scene scene, const LightGroup& group) {
  std::vector<Light> lights;
  for (const size_t l : group.lights) lights.push_back(scene.lights[l]);
  scene.lights = std::move(lights);
  if (!group.sky) scene.environment = Environment{};
  std::vector<bool> keep(scene.materials.size(), false);
  for (const size_t m : group.materials) keep[m] = true;
  for (size_t m = 0; m < scene.materials.size(); ++m)
    if (!keep[m]) scene.materials[m].emissiveFactor = glm::vec3(0.0f);
  return scene;
}

BakeOptions settleGroupedOptions(const Scene& scene, const BakeOptions& options) {
  checkGroupedOptions(scene, options);
  BakeOptions o = options;
  o.lightGroups.clear();
  // Settled once for the whole scene: a group without the emitters would otherwise gather, and clamp tighter,
// where the whole would not.
  if (o.finalGather == FinalGatherMode::Auto) o.finalGather = finalGatherAutoOn(scene) ? FinalGatherMode::On : FinalGatherMode::Off;
  if (!(o.clampVplsPerMean > 0.0)) o.clampVplsPerMean = autoClampVplsPerMean(scene, o.eval.biasCompensation);
  // The probe grid too: the layers' coefficients are summed probe by probe, and the automatic spacing follows the
  // lights (a directional light's shadows ask for a finer grid than a group of lamps would get).
  if (o.probes.enabled && !o.probes.spacing)
    o.probes.spacing = chooseProbeSpacing(o.probes.box ? *o.probes.box : scene.bounds(), autoProbeCount(o.probes, scene.lights));
  return o;
}

BakeResult bakeLightGroups(Scene scene, const BakeOptions& options) {
  const std::vector<LightGroup> groups = resolveLightGroups(scene, options.lightGroups);
  if (groups.empty()) return bake(std::move(scene), options);
  const BakeOptions o = settleGroupedOptions(scene, options);
  const std::vector<Light> lights = scene.lights;
  const std::vector<Material> materials = scene.materials;
  const Environment environment = scene.environment;
  std::vector<GroupPart> parts;
  BakeResult first;
  for (size_t g = 0; g < groups.size(); ++g) {
    log::info("light group '" + groups[g].name + "' (" + std::to_string(g + 1) + " of " + std::to_string(groups.size()) + ")");
    Scene base;
    if (g == 0) {
      base = std::move(scene);
    } else {  // the first group's scene carries the atlas: its geometry, the whole scene's sources
      base = first.scene;
      base.lights = lights;
      base.materials = materials;
      base.environment = environment;
    }
    BakeOptions go = o;
    if (g > 0) {
      go.atlasApplied = std::make_shared<const AtlasResult>(first.atlas);
      go.atlasFrom.clear();
    }
    BakeResult r = bake(groupScene(std::move(base), groups[g]), go);
    parts.push_back(groupPart(groups[g], lights, r));
    if (g == 0) first = std::move(r);
  }
  first.scene.lights = lights;
  first.scene.materials = materials;
  first.scene.environment = environment;
  first.lightModes.assign(lights.size(), LightMode::Baked);
  first.maskChannels = {};
  sumParts(parts, first, std::vector<glm::vec3>(parts.size(), glm::vec3(1.0f)), 0);
  return first;
}

}  // namespace irbake
