// The bake's options: one struct per stage, each with its defaults; BakePlan (pipeline/bake_plan.h) settles
// what they leave automatic.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "common/progress.h"
#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator.h"
#include "pipeline/backend_choice.h"
#include "stages/error_estimate/error_estimate.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/gather/final_gather.h"
#include "stages/light_tail/light_tail.h"
#include "stages/probes/light_probes.h"
#include "stages/shadow_edges/shadow_edges.h"
#include "stages/shadow_mask/shadow_mask.h"
#include "stages/sky/sky_light.h"
#include "texels/texel_samples.h"
#include "transport/vpl_importance.h"
#include "vpl/vpl.h"

namespace irbake {

// How the bake bounds the VPL geometry term (VplEvalOptions::clampBound of every backend call).
enum class ClampMode {
  Derived,  // deriveClampBound from the scene and VPLs (k = BakeOptions::clampVplsPerMean)
  Off,      // no clamp
  Fixed,    // BakeOptions::clampBound
};

// Whether the clamp compensation's rays are traced while the GL backend bakes (on the CPU beside the GPU).
enum class OverlapCompensation {
  Auto,    // hardware renderers only: on llvmpipe both fight over the cores
  Never,   // after the VPL blocks
  Always,  // beside the VPL blocks, whatever the renderer
};

// Whether the bounced light of each texel is gathered from the baked map one bounce away (final gather,
// stages/gather) instead of read from the VPLs that reach it.
enum class FinalGatherMode {
  Off,   // the VPL sum (+ clamp compensation) is the map
  On,    // in every scene the VPL backends bake
  Auto,  // on where the scene has no emissive surface (the rays would find small emitters by chance) and no
         // see-through one (the gather reads the glass's own map, not what lies behind it)
};

// One --light-mode NAME=MODE: light is a selector of pipeline/light_modes.h ("*", "sun", "#i", a glTF light's
// name, or the explicit name:TEXT, index:I, option:sun).
struct LightModeRequest {
  std::string light;
  LightMode mode = LightMode::Baked;
  std::string origin = {};  // where it was given, for refusals: "" for the command line, "FILE: line N: key 'light-mode'"
};

// One --light-group NAME=LIGHTS (or the config file's light-group): sources are the comma-separated selectors of
// pipeline/light_groups.h.
struct LightGroupRequest {
  std::string name;
  std::vector<std::string> sources;
  std::string origin = {};  // where it was given, for refusals: "" for the command line, "FILE: line N: key 'light-group'"
};

// The default evaluation: bias compensation on, direct and VPLs (the clamp is set by BakeOptions::clamp).
inline VplEvalOptions compensatedEval() {
  VplEvalOptions e;
  e.biasCompensation = true;
  return e;
}

struct BakeOptions {
  BackendKind backend = BackendKind::Auto;  // auto (default), gl, embree, reference
  AtlasOptions atlas;                     // texel density, padding, page size
  std::string atlasFrom;                  // an earlier bake's glTF/GLB whose atlas this bake reuses instead of
                                          // unwrapping (atlas/atlas_from_bake.h); "": unwrap
  std::shared_ptr<const AtlasResult> atlasApplied;  // the scene already carries this atlas (uv1, pages): used as it
                                                    // is (a light group's bake after the first); null: unwrap or atlasFrom
  TexelSampleOptions texels;              // supersampling, leak control
  WalkOptions walk;                       // VPL paths, bounces, seed
  std::optional<int> finalGatherPaths;    // the walk's paths where the final gather runs (unset: walk.paths)
  VplImportanceOptions vplImportance;     // the walk's candidates thinned to where they matter (auto: where the
                                          // final gather runs, the pilot finds the walk uneven and the probes ×
                                          // candidates budget allows ≥ 2 candidates per VPL)
  VplEvalOptions eval = compensatedEval();  // bias compensation (on), direct, VPLs; its clampBound is not read
                                            // (the bake sets it from clamp)
  ClampCompensationOptions compensation;  // the gather that recovers the clamped energy (eval.biasCompensation)
  SkyLightOptions sky;                    // the sky's direct light (Scene::environment), traced
  ShadowEdgeOptions shadowEdges;          // punctual lights' shadow edges area-averaged (subSamples ≤ 1: off)
  LightCullOptions lightCull;             // each light's work only where it reaches (fraction 0: every light everywhere)
  LightTailOptions lightTail;             // the cut lights' left-out light, sampled back (samples 0: left out)
  FinalGatherMode finalGather = FinalGatherMode::Off;  // bounced light gathered from the map (stages/gather)
  FinalGatherOptions gather;              // its rays and filter
  ClampMode clamp = ClampMode::Derived;  // the geometry-term bound: derived from the scene, off, or clampBound
  float clampBound = 0.0f;                // the bound with ClampMode::Fixed (1/m², > 0)
  double clampVplsPerMean = 0.0;          // k of deriveClampBound (larger = tighter clamp); 0: with bias
                                          // compensation 256 (emissive surfaces) or 1024 (none), 16 without
  std::optional<int> interleave;          // n ≥ 1: VPLs split over n×n texel classes (Keller & Heidrich 2001),
                                          // 1 = off; unset: automatic (chooseInterleave: 1…6)
  GlBackendOptions gl;                    // GL backend: cube face size (unset = from the light map), VPLs per pass, biases
  OverlapCompensation overlapCompensation = OverlapCompensation::Auto;  // compensation rays beside the GL bake
  int vplBlock = 512;                     // VPLs per block of the exact VPL sum (within one interleave class):
                                          // the unit of shards and checkpoints, fixed by the options alone
  int referenceSpp = 256;                 // reference backend: paths per texel sample
  bool postDilate = true;                 // fill padding from valid texels
  bool postSeams = true;                  // stitch chart seams
  bool directional = false;               // also bake the L1 pages (BakeResult::directional) in the
                                          // backend's passes (4 coefficients in the exact sums); the map's
                                          // bytes are the same. Off: no extra work, the same bytes as before
  ProbeOptions probes;                    // irradiance probes read from the finished map (stages/probes); off:
                                          // none, and every other output the same bytes
  ShadowMaskOptions shadowMask;           // the shadow-mask lights' visibility pages (stages/shadow_mask)
  std::vector<LightModeRequest> lightModes;  // --light-mode in the order given (a name wins over "*", the last
                                            // of each over earlier ones; any over the glTF's extras.irbake.mode)
  std::vector<LightGroupRequest> lightGroups;  // --light-group in the order given (pipeline/light_groups.h); with
                                               // these or extras.irbake.group, bakeLightGroups bakes each group apart
  std::string onlyGroup;                  // bake this light group alone on atlasFrom's bake and carry its other
                                          // layers over (pipeline/only_group.h); "": every group
  ErrorEstimateOptions errorEstimate;     // the bake's own error from independent replicates of the walk, and
                                          // --target-error's rounds (off: one walk, the same bytes as before)
  double maxMemoryGB = 0.0;               // refuse up front a bake predicted to need more memory at its peak
                                          // (GB of 10^9 bytes; pipeline/bake_prediction.h); 0: no limit
  ProgressCallback progress;
};

}  // namespace irbake
