// The bake, stage by stage, with the report the benchmarks and users read. StagedBake owns the record of
// what the stages produced (BakeState, pipeline/bake_state.h) and runs its stage runners in order.
#include "pipeline/bake.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <memory>

#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "pipeline/bake_report.h"
#include "pipeline/bake_stages.h"
#include "pipeline/bake_state.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/error_estimate/error_estimate.h"

namespace irbake {
namespace {

// The values an option holds when it is set must make sense: unset is "automatic", never a number.
void checkOptionRanges(const BakeOptions& o) {
  auto atLeast = [](const std::optional<int>& value, int lowest, const char* name) {
    if (value && *value < lowest)
      throw Error(ErrorCode::Usage, "", std::string(name) + " must be at least " + std::to_string(lowest) + " (got " +
                                            std::to_string(*value) + ")");
  };
  atLeast(o.interleave, 1, "interleave");
  atLeast(o.gl.cubeFaceSize, 1, "GL cube face size");
  atLeast(o.walk.maxBounces, 0, "bounce count");
  atLeast(o.compensation.filterRadius, 0, "compensation filter radius");
  if (o.directional && o.backend == BackendKind::Reference)  // the L1 pages come from the VPL backends' passes
    throw Error(ErrorCode::Usage, "", "--directional needs a VPL backend (gl, embree or auto), not reference");
  if (o.clamp == ClampMode::Fixed && !(o.clampBound > 0.0f))
    throw Error(ErrorCode::Usage, "", "a fixed clamp bound must be positive (got " + std::to_string(o.clampBound) +
                                          "; ClampMode::Off for no clamp)");
}

// extras.irbake.mode "off" (Primitive::mode): out of the scene every stage sees (no shadows, bounces, emission or
// texels), kept aside for the export, which writes them as they were.
std::vector<Primitive> takeObjectsOff(Scene& scene) {
  std::vector<Primitive> kept, off;
  for (Primitive& p : scene.primitives) (p.mode == ObjectMode::Off ? off : kept).push_back(std::move(p));
  scene.primitives = std::move(kept);
  for (Primitive& p : off) {
    p.uv1.clear();
    p.lightmap = LightmapRef{};
  }
  if (!off.empty() && scene.triangleCount() == 0)
    throw Error(ErrorCode::EmptyScene, scene.sourcePath, "every object's extras.irbake.mode is \"off\": nothing to bake");
  return off;
}

// Probe-lit objects need the probes: with --probes off the clients have none to light them with.
void warnProbeObjectsWithoutProbes(const BakeOptions& options, const Scene& scene) {
  if (options.probes.enabled) return;
  const auto probeLit = [](const Primitive& p) { return p.mode == ObjectMode::Probes; };
  const size_t count = size_t(std::count_if(scene.primitives.begin(), scene.primitives.end(), probeLit));
  if (count == 0) return;
  log::warn(scene.sourcePath + ": " + std::to_string(count) + " primitive(s) have extras.irbake.mode \"probes\" " +
            "but --probes is off: they get no light-map texels and no probes, so the clients draw them unlit");
}

}  // namespace

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: kilobytes
}

StagedBake::StagedBake(Scene scene, const BakeOptions& options) : state_(std::make_unique<BakeState>()) {
  BakeState& s = *state_;
  s.options = options;
  s.scene = std::move(scene);
  if (s.scene.triangleCount() == 0) throw Error(ErrorCode::EmptyScene, s.scene.sourcePath, "no triangles to bake");
  s.objectsOff = takeObjectsOff(s.scene);
  checkOptionRanges(options);
  warnProbeObjectsWithoutProbes(options, s.scene);
  checkLightModes(options, s.scene);  // a bad light name costs nothing
  prepare(s);
}

StagedBake::~StagedBake() = default;

size_t StagedBake::blockCount() const { return state_->blocks.size(); }
BackendKind StagedBake::backend() const { return state_->plan.backend; }

ExactVplSums StagedBake::emptySums() const {
  return zeroSums(*state_);
}

void StagedBake::evaluateBlocks(size_t begin, size_t end, ExactVplSums& sums,
                                const std::function<void(size_t next)>& afterBlock) {
  BakeState& s = *state_;
  end = std::min(end, s.blocks.size());
  if (s.plan.overlapCompensation && !s.gather.valid() && begin == 0 && end == s.blocks.size()) {
    const ClampCompensationOptions o = s.plan.compensation;
    // The gather reads the pages' texel samples and the geometry only: it runs while the GL backend bakes.
    s.gather = std::async(std::launch::async, [&s, o] { return std::make_unique<ClampGather>(*s.wholeInputs, o); });
  }
  timed(s, "backend", [&] {
    for (size_t b = begin; b < end; ++b) {
      ProgressCallback progress;
      if (s.options.progress) {
        const double count = static_cast<double>(std::max<size_t>(1, end - begin));
        progress = [&s, b, begin, count](const char* stage, double f) {
          s.options.progress(stage, (static_cast<double>(b - begin) + std::clamp(f, 0.0, 1.0)) / count);
        };
      }
      part(s, "evaluate", [&] { evaluateBlock(s, b, sums, progress); });
      if (afterBlock) afterBlock(b + 1);
    }
  });
}

void StagedBake::refineToTarget(ExactVplSums& sums, const std::function<void(size_t next)>& afterBlock) {
  BakeState& s = *state_;
  const ErrorEstimateOptions& o = s.options.errorEstimate;
  if (!targeting(s)) return;
  s.roundSeconds = s.seconds.value("backend", 0.0);  // the first round's: its blocks
  for (;;) {
    double estimate = 0.0;
    timed(s, "errorEstimate", [&] { estimate = roundEstimate(s, sums); });
    s.rounds.push_back(roundEntry(s));
    s.rounds.back()["walkError"] = estimate;
    log::info("round " + std::to_string(s.rounds.size()) + ": " + std::to_string(s.replicates.size()) + " replicates, " +
              std::to_string(s.vpls.vpls.size()) + " VPLs, the walk's estimated error " + percent(estimate));
    // The walk's figure is no lower than the finished one's walk part, and the ray stages add their own noise:
    // at most the target, the finished figure decides (finish).
    if (estimate <= o.targetError) return;
    if (static_cast<int>(s.rounds.size()) >= o.maxRounds) s.stoppedBy = "max-rounds";
    else if (o.maxSeconds > 0.0 && s.total.seconds() + s.roundSeconds > o.maxSeconds) s.stoppedBy = "max-time";
    if (!s.stoppedBy.empty()) return;
    Stopwatch watch;
    const size_t begin = s.blocks.size();
    addRound(s);
    evaluateBlocks(begin, s.blocks.size(), sums, afterBlock);
    s.roundSeconds = watch.seconds();
  }
}

namespace {
// --target-error aims a raised part at this fraction of the target (the next figure is itself an estimate,
// and aiming at the target itself would often miss it by a hair and cost another round).
constexpr double kTargetAim = 0.9;
// At most this many times the rays per round, and the ray stages' rays at most this many times the plan's.
constexpr double kMaxStageRaysPerRound = 16.0;
constexpr double kMaxStageRays = 1024.0;
}  // namespace

// After the walk's rounds: the ray stages and the finished figure; while it is above the target, another round
// of what dominates it, more of the compensation's and final gather's rays (the stages run again on the same
// input) or more paths (another two replicates, the map made again), until the figure is at most the target
// (stoppedBy "target") or a cap stops it.
void StagedBake::stagesToTarget(ExactVplSums& sums, BakeResult& r) {
  BakeState& s = *state_;
  const ErrorEstimateOptions& o = s.options.errorEstimate;
  if (s.rounds.empty()) s.rounds.push_back(roundEntry(s));
  for (;;) {
    std::vector<Lightmap> input = r.maps;  // the ray stages' input: more rays run them again on it
    L1Pages inputL1 = r.directional;
    Stopwatch watch;
    rayStages(s, r, r.report, true);
    const double stageSeconds = watch.seconds();
    const double total = s.figure.whole.relative, walk = s.figure.breakdown.value("vpls", 0.0);
    nlohmann::json& round = s.rounds.back();
    round["estimatedError"] = total;
    round["breakdown"] = s.figure.breakdown;
    if (total <= o.targetError) {
      s.stoppedBy = "target";
      return;
    }
    if (!s.stoppedBy.empty()) return;  // a cap stopped the walk's rounds
    const double aim2 = (kTargetAim * o.targetError) * (kTargetAim * o.targetError);
    // The sky's pages are traced once, before the rounds: neither raise lowers skyRays.
    const double sky = s.figure.breakdown.value("skyRays", 0.0);
    const double walk2 = walk * walk, stages2 = std::max(0.0, total * total - walk2 - sky * sky);
    // The larger part is raised: to what the other leaves of the aim, or to half the aim where the other
    // needs more than half (the other is raised next).
    const bool rays = stages2 > walk2;
    const double factor = !rays ? 1.0
                                : std::min({std::max(2.0, stages2 / (walk2 < aim2 / 2 ? aim2 - walk2 : aim2 / 2)),
                                            kMaxStageRaysPerRound, kMaxStageRays / s.stageRays});
    const double forecast = rays ? stageSeconds * factor : s.roundSeconds + stageSeconds;
    if (static_cast<int>(s.rounds.size()) >= o.maxRounds) s.stoppedBy = "max-rounds";
    else if (rays && factor <= 1.0) s.stoppedBy = "max-rays";
    else if (o.maxSeconds > 0.0 && s.total.seconds() + forecast > o.maxSeconds) s.stoppedBy = "max-time";
    if (!s.stoppedBy.empty()) return;
    round["raised"] = rays ? "stageRays" : "paths";
    log::info("round " + std::to_string(s.rounds.size()) + ": estimated error " + percent(total) + " (walk " +
              percent(walk) + ", ray stages " + percent(std::sqrt(stages2)) + "), above the target: " +
              (rays ? "the ray stages' rays x" + shortNumber(factor) : std::string("another round of paths")));
    if (rays) {
      raiseStageRays(s, factor);
      r.maps = std::move(input);
      r.directional = std::move(inputL1);
    } else {
      Stopwatch paths;
      const size_t begin = s.blocks.size();
      addRound(s);
      evaluateBlocks(begin, s.blocks.size(), sums);
      s.roundSeconds = paths.seconds();
      mapsFromSums(s, sums, r, r.report);  // a copy: the next round adds to them
    }
    s.rounds.push_back(roundEntry(s));
  }
}

nlohmann::json StagedBake::backendCounts() const {
  nlohmann::json counts = state_->evaluator->counts();
  counts["backendCalls"] = state_->interleaveStats.backendCalls;
  return counts;
}

void StagedBake::addBackendCounts(const nlohmann::json& counts) {
  state_->evaluator->addCounts(counts);
  state_->interleaveStats.backendCalls += counts.value("backendCalls", 0);
}

BakeResult StagedBake::finish(ExactVplSums sums) {
  BakeState& s = *state_;
  BakeResult r;
  nlohmann::json& report = r.report;
  s.classPages = {};
  s.pagesClass = -1;
  // With a target the sums are kept for more rounds (a copy made into the map); otherwise they are rounded
  // into the maps and freed page by page: not needed at the peak (compensation).
  const bool target = targeting(s);
  if (target) mapsFromSums(s, sums, r, report);
  else mapsFromSums(s, std::move(sums), r, report);
  const bool estimate = !s.halves[0].empty();
  if (target && estimate) stagesToTarget(sums, r);
  else rayStages(s, r, report, estimate);
  sums = {};
  timed(s, "lightCull", [&] { measureLightCut(s, r.maps, report); });
  if (estimate) timed(s, "errorEstimate", [&] {
    reportFigure(s, report);
    r.standardError = std::move(s.figure.errorPages);
  });
  s.halves = {};
  StageContext ctx = stageContext(s, report);
  leaveOutDirect(r.maps, s.leftOutDirect);
  s.leftOutDirect = {};
  r.shadowMask = shadowMaskStage(ctx);
  r.lightModes = s.plan.lightModes;
  r.maskChannels = s.plan.maskChannels;
  s.directMaps = {};
  s.directL1 = {};
  report["surfaceFilters"] = {{"plans", s.surfaceFilters->plansMade()}, {"fallbacks", s.surfaceFilters->fallbacks()}};
  if (s.plan.directional) directionalStage(ctx, r.directional);
  const PostStats post = postStage(ctx, r.maps);
  probeStage(ctx, r.maps, r.probes);
  if (!r.shadowMask.empty()) shadowMaskPostStage(ctx, r.shadowMask);
  s.seconds["bake"] = s.total.seconds();
  s.cpuSeconds["bake"] = s.total.cpuSeconds();
  describeBake(BakeFacts{s.scene, s.atlas, s.texels, s.vpls, s.options, s.plan, *s.evaluator, s.interleaveStats,
                         s.blocks.size(), s.importanceStats, post},
               report);
  // Everything that differs between two runs of the same bake lives in "timings" (wall clock per stage,
  // the GL stage split, peak memory); the rest of the report is the same bytes every time.
  report["timings"]["seconds"] = s.seconds;
  report["timings"]["cpuSeconds"] = s.cpuSeconds;
  report["timings"]["backendParts"] = s.backendParts;
  report["timings"]["memoryPeakMiB"] = peakMemoryMiB();
  report["prediction"] = s.prediction.cost.toJson();  // the preflight's, beside the measured timings
  r.atlas = std::move(s.atlas);
  r.vpls = std::move(s.vpls);
  s.gather = {};
  s.wholeInputs.reset();
  s.rayTracer.reset();  // it refers to the scene, which moves into the result
  r.scene = std::move(s.scene);
  for (Primitive& p : s.objectsOff) r.scene.primitives.push_back(std::move(p));
  return r;
}

BakeResult bake(Scene scene, const BakeOptions& options) {
  StagedBake staged(std::move(scene), options);
  ExactVplSums sums = staged.emptySums();
  staged.evaluateBlocks(0, staged.blockCount(), sums);
  staged.refineToTarget(sums);
  return staged.finish(std::move(sums));
}

}  // namespace irbake
