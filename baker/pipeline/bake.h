// The bake: every stage in order, one way — scene → atlas → texels → VPLs → backend → post.
#pragma once
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "evaluators/bake_inputs.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/gather/final_gather.h"
#include "evaluators/gl/gl_backend.h"
#include "stages/shadow_edges/shadow_edges.h"
#include "stages/sky/sky_light.h"
#include "lightmap/lightmap.h"
#include "export/portable_export.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"
#include "pipeline/backend_choice.h"
#include "pipeline/vpl_sums.h"
#include "vpl/vpl.h"
#include "transport/vpl_importance.h"

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

// The default evaluation: bias compensation on, direct and VPLs (the clamp is set by BakeOptions::clamp).
inline VplEvalOptions compensatedEval() {
  VplEvalOptions e;
  e.biasCompensation = true;
  return e;
}

struct BakeOptions {
  BackendKind backend = BackendKind::Auto;  // auto (default), gl, embree, reference
  AtlasOptions atlas;                     // texel density, padding, page size
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
  ProgressCallback progress;
};

struct BakeResult {
  Scene scene;                       // with the atlas applied (uv1, lightmap pages)
  AtlasResult atlas;
  VplSet vpls;
  std::vector<Lightmap> maps;        // one per page, post-processed
  // With BakeOptions::directional: the L1x, L1y, L1z pages (transport/directional.h), one per page each,
  // from the backend's own passes and exact sums like maps, post-processed like them; empty otherwise.
  L1Pages directional;
  nlohmann::json report;             // times per stage, VPLs per bounce, power, texels, memory peak
};

// Runs the whole bake on a loaded scene. Throws Error on failure. = StagedBake: every block, then finish.
BakeResult bake(Scene scene, const BakeOptions& options);

// The bake in three steps, so a shard can stop after its VPL blocks and a merge (or a resumed bake) can
// pick up after them (docs/distributed.md):
//   prepare (the constructor): atlas, ray tracer, texel samples, VPLs, clamp, backend choice, VPL blocks;
//   evaluateBlocks: the VPL blocks [begin, end) through the backend, added exactly into an ExactVplSums;
//   finish: punctual lights, the interleave classes mixed, sky, clamp compensation, post, report.
// Block boundaries depend on the scene and options only, never on threads, shards or interruptions, and
// the sums are exact, so any split of the blocks gives the same bytes.
class StagedBake {
 public:
  StagedBake(Scene scene, const BakeOptions& options);
  ~StagedBake();
  StagedBake(const StagedBake&) = delete;
  StagedBake& operator=(const StagedBake&) = delete;

  size_t blockCount() const;       // VPL blocks of the whole bake (0 for the reference backend)
  BackendKind backend() const;     // the backend used (auto resolved)
  ExactVplSums emptySums() const;  // zero sums laid out like the pages
  // Evaluates blocks [begin, end) in order into sums; afterBlock(next) runs after each (next = index + 1).
  void evaluateBlocks(size_t begin, size_t end, ExactVplSums& sums,
                      const std::function<void(size_t next)>& afterBlock = {});
  // Backend counts of the blocks evaluated so far (report "gl"), for a partial to carry to the merge;
  // addBackendCounts adds a shard's.
  nlohmann::json backendCounts() const;
  void addBackendCounts(const nlohmann::json& counts);
  // Everything after the VPL blocks; sums must hold every block (moved in: freed once rounded). Call once.
  BakeResult finish(ExactVplSums sums);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// "auto" | "gl" | "embree" | "reference" (throws Error(Usage) otherwise), and back.
BackendKind parseBackend(const std::string& name);
const char* toString(BackendKind kind);

// A directional light from the command line (--sun): direction the light travels, irradiance W/m².
Light sunLight(const glm::vec3& direction, float irradiance);

struct OutputOptions {
  std::filesystem::path outDir;      // OUTDIR: lightmap_<page>.exr, scene.gltf
  std::filesystem::path reportPath;  // report JSON; empty = OUTDIR/report.json
  bool writeGltf = true;             // export scene.gltf (+ .bin, PNG maps) beside the EXR pages
  std::vector<std::filesystem::path> inputs;  // the bake's input files: never overwritten (Error(Usage))
  std::filesystem::path portablePath;  // also the portable GLB here (export/portable_export.h); empty: none
  PortableOptions portable;            // its exposure and texture limits
};

// Writes the EXR pages, the glTF (through exportGltf) and the report, each atomically. Returns the
// files written.
std::vector<std::filesystem::path> writeBakeOutputs(const BakeResult& result, const OutputOptions& options);

// Peak resident memory of this process so far (MiB, getrusage).
double peakMemoryMiB();

}  // namespace irbake
