// Light groups (docs/guide.md, "Scenarios and light groups"): every light source in one named group, each
// group's light (direct and bounced) baked into a layer of its own on one atlas, the maps the sum of the layers.
// The transport is linear in the sources, so the sum is a bake of all of them together up to each bake's noise
// and the clamp (below).
//
// A group comes from --light-group NAME=LIGHTS (LIGHTS: comma-separated selectors) or from extras
// {"irbake": {"group": "NAME"}} on a KHR_lights_punctual light or an emissive material. A selector is one of
// pipeline/light_modes.h's (`sun`, `#I`, a light's name, name:TEXT, index:I, option:sun), or
//   *               every source no other group names
//   sky             the sky of --sky / --env
//   emissive        every emissive material
//   emissive:NAME   the emissive material named NAME
// Refused before anything is traced (Error(Usage), naming the group and the source): a name not matching
// [A-Za-z0-9_-]{1,64}, a selector nothing answers to, a source in two groups, two `*` groups, a group left
// empty, and a source in no group when there is no `*` group.
//
// Where the sum differs from one bake of every source (beyond noise): each group's bake derives its own clamp
// bound from its own VPLs (a clamp is not linear; the compensation gathers the clamped part back, so what stays
// is the compensation's residue), and each cuts its lights without range against its own map level (the light
// tail samples the cut part back). FinalGatherMode::Auto and the clamp's k are settled once for the whole scene.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/bake.h"
#include "pipeline/bake_options.h"
#include "scene/scene.h"

namespace irbake {

struct LightGroup {
  std::string name;
  std::vector<size_t> lights;     // indices into Scene::lights (the --sun light among them)
  bool sky = false;               // the sky of --sky / --env
  std::vector<size_t> materials;  // emissive materials (indices into Scene::materials)
  nlohmann::json sources;         // the same as IRBAKE_lightmap_scenarios' `lights` list
  size_t size() const { return lights.size() + materials.size() + (sky ? 1 : 0); }
};

// The scene's groups from the requests and the file's extras, in the order first named (requests first); empty
// when neither names one. Throws Error(Usage) as above.
std::vector<LightGroup> resolveLightGroups(const Scene& scene, const std::vector<LightGroupRequest>& requests);

// `scene` with only the group's sources: the other lights removed, the other materials' emission zeroed, the
// sky only when the group has it.
Scene groupScene(Scene scene, const LightGroup& group);

// The bake with light groups: the first group's bake unwraps (or reads --atlas-from), every other group bakes on
// that atlas with the same options and seed; the result's maps and probes are the layers' sum (combineLayers),
// its layers the groups', its report the first group's with "lightGroups" (each group's times and estimated
// error) and the sum's estimatedError (the groups' absolute errors in quadrature). Throws Error(Usage) for what
// groups do not support yet: --directional, indirect or shadowmask lights.
BakeResult bakeLightGroups(Scene scene, const BakeOptions& options);

// Shared with the incremental bake of one group (pipeline/only_group.h).

// A group's bake, kept for the sum: its layer and what its report says.
struct GroupPart {
  LightLayer layer;
  nlohmann::json report;             // its bake's report (timings, estimatedError); a carried layer's: the earlier's
  ProbeSunLevel sun;                 // the probes' sun level where the layer holds the sun
  std::vector<ProbeEmitter> emitters;
  std::vector<Lightmap> standardError;
  bool carried = false;              // read from an earlier bake, not baked by this one
};

// `options` with what a grouped bake settles once for the whole scene (the final gather, the clamp's k, the
// automatic probe spacing) where they are left automatic. Throws Error(Usage) for what groups do not support.
BakeOptions settleGroupedOptions(const Scene& scene, const BakeOptions& options);
// The group's bake `r` as a part (its maps, probes, standard error and report moved out of r).
GroupPart groupPart(const LightGroup& group, const std::vector<Light>& lights, BakeResult& r);
// The parts' sum into `total` (scene, atlas and probe grid already set): its layers, maps and probes (combineLayers
// with `weights`, one per part), the probes' sun level (the sun's part's, times its weight), the exact emitters,
// the report (part reportFrom's, with "lightGroups" and the sum's estimatedError, dropped where a part has none).
void sumParts(std::vector<GroupPart>& parts, BakeResult& total, const std::vector<glm::vec3>& weights, size_t reportFrom);

}  // namespace irbake
