// The bake: every stage in order, one way — scene → atlas → texels → VPLs → backend → post.
#pragma once
#include "common/output_guard.h"
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "export/light_layers.h"
#include "export/portable_export.h"
#include "lightmap/lightmap.h"
#include "pipeline/bake_options.h"
#include "stages/shadow_mask/shadow_mask.h"
#include "pipeline/bake_plan.h"
#include "pipeline/vpl_sums.h"
#include "scene/scene.h"
#include "vpl/vpl.h"

namespace irbake {

struct BakeState;  // what the stages produced so far (pipeline/bake_state.h)

struct BakeResult {
  Scene scene;                       // with the atlas applied (uv1, lightmap pages)
  AtlasResult atlas;
  VplSet vpls;
  std::vector<Lightmap> maps;        // one per page, post-processed
  // With BakeOptions::directional: the L1x, L1y, L1z pages (transport/directional.h), one per page each,
  // from the backend's own passes and exact sums like maps, post-processed like them; empty otherwise.
  L1Pages directional;
  LightProbeGrid probes;             // with BakeOptions::probes enabled: the grid, baked; size() 0 otherwise
  // With shadow-mask lights (BakeOptions::lightModes): their visibility per page, post-processed like maps;
  // ShadowMaskChannels in lightModes says which light is in which channel. Empty otherwise.
  ShadowMaskPages shadowMask;
  std::vector<LightMode> lightModes;   // per scene light, as settled (fallbacks applied)
  ShadowMaskChannels maskChannels;
  // With an error estimate: per page, the standard error of each texel's value (the two halves' spread; the
  // map's units, before post); empty otherwise.
  std::vector<Lightmap> standardError;
  // With light groups (pipeline/light_groups.h): each group's layer; maps and probes hold their sum. Empty otherwise.
  std::vector<LightLayer> layers;
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
  // With an error estimate and a target (BakeOptions::errorEstimate): rounds of two walk replicates added,
  // their blocks evaluated into sums, until the walk's own figure is at most the target or a cap stops it.
  // finish then runs the ray stages and, while the finished figure (walk and stages) is above the target,
  // raises the part that dominates it (the stages' rays, or more rounds of paths into the same sums); the
  // report's estimatedError says what stopped it ("target" only at or below it). Deterministic for a seed
  // unless the time cap stops it.
  void refineToTarget(ExactVplSums& sums, const std::function<void(size_t next)>& afterBlock = {});
  // Backend counts of the blocks evaluated so far (report "gl"), for a partial to carry to the merge;
  // addBackendCounts adds a shard's.
  nlohmann::json backendCounts() const;
  void addBackendCounts(const nlohmann::json& counts);
  // Everything after the VPL blocks; sums must hold every block (moved in: freed once rounded). Call once.
  BakeResult finish(ExactVplSums sums);

 private:
  std::unique_ptr<BakeState> state_;
  // finish's part under a target: the ray stages and the figure, raised round by round until it is met.
  void stagesToTarget(ExactVplSums& sums, BakeResult& r);
};

struct OutputOptions {
  std::filesystem::path outDir;      // OUTDIR: lightmap_<page>.exr, scene.gltf
  std::filesystem::path reportPath;  // report JSON; empty = OUTDIR/report.json
  bool writeGltf = true;             // export scene.gltf (+ .bin, PNG maps) beside the EXR pages
  std::vector<std::filesystem::path> inputs;  // the bake's input files: never overwritten (Error(Usage))
  std::filesystem::path portablePath;  // also the portable GLB here (export/portable_export.h); empty: none
  PortableOptions portable;            // its exposure and texture limits
  // The command's output guard: every file goes through it (null: one that knows only `inputs`).
  const OutputGuard* guard = nullptr;
  std::vector<PendingFile> alsoWrite;  // more files of the same all-or-nothing set (--dump-config)
};

// Writes the EXR pages, the glTF (through exportGltf) and the report, each atomically. Returns the
// files written.
std::vector<std::filesystem::path> writeBakeOutputs(const BakeResult& result, const OutputOptions& options);

// Peak resident memory of this process so far (MiB, getrusage).
double peakMemoryMiB();

}  // namespace irbake
