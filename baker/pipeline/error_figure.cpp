// The error estimate's runs: the mixed halves, the estimate between rounds, the ray stages' own noise, the
// finished figure and its report; --target-error's raised rays.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <tbb/parallel_for.h>

#include "common/log.h"
#include "pipeline/bake_state.h"
#include "sampling/sampling.h"
#include "stages/interleave/interleaved_sampling.h"
#include "stages/sky/sky_light.h"

namespace irbake {
namespace {

// The halves through the final gather alone (no direct light, rays that escape bring nothing): the map's
// noise under the gather, since the gather is linear in the map it reads (emitters' Le cancels in the spread).
std::vector<std::vector<Lightmap>> gatheredHalves(const BakeState& s) {
  FinalGatherOptions g = s.plan.gather;
  g.missRadiance = glm::vec3(0.0f);
  std::vector<Lightmap> none = s.halves[0];
  for (Lightmap& m : none) std::fill(m.texels.begin(), m.texels.end(), glm::vec3(0.0f));
  std::vector<std::vector<Lightmap>> out = {s.halves[0], s.halves[1]};
  for (auto& half : out) finalGather(*s.wholeInputs, none, half, g);
  return out;
}

// A stage's own ray noise: the stage again with rays of another seed on the same input; one stage's
// variance per bin is half the two results' squared difference (twice replicateError's s²/2 of the pair).
// Recorded as `stage` on every valid texel's bins and on the interior ones.
void rayNoise(BakeState& s, const std::string& stage, const std::vector<Lightmap>& once, const std::vector<Lightmap>& twice) {
  const int bin = s.options.errorEstimate.bin;
  s.stageNoise[stage] = std::sqrt(2.0) * replicateError({once, twice}, nullptr, bin).noiseRms;
  s.stageNoiseInterior[stage] = std::sqrt(2.0) * replicateError({once, twice}, nullptr, bin, 1.0, BinTexels::Interior).noiseRms;
}

// maps += sign · s.skyShift (none without a sky).
void shiftSky(const BakeState& s, std::vector<Lightmap>& maps, float sign) {
  for (size_t p = 0; p < maps.size() && p < s.skyShift.size(); ++p)
    for (size_t t = 0; t < maps[p].size() && t < s.skyShift[p].size(); ++t) maps[p].texels[t] += sign * s.skyShift[p].texels[t];
}

// before: the compensation's input, replaced by its second run's output. The second run reads the second sky
// (its read of the sky's noise is its own figure's; the sky's pages themselves are skyRays'); under the final
// gather the second sky stays in for the gather's second run.
void compensationRayNoise(BakeState& s, std::vector<Lightmap>& before, const std::vector<Lightmap>& after) {
  ClampCompensationOptions o = s.plan.compensation;
  o.seed = static_cast<uint32_t>(hashSeed(s.options.walk.seed, 0x636f6d70ull));  // "comp"
  shiftSky(s, before, 1.0f);
  ClampGather(*s.wholeInputs, o).apply(before);
  if (s.plan.finalGather) return;
  shiftSky(s, before, -1.0f);
  rayNoise(s, "compensationRays", after, before);
}

// before: the gather's input, the second sky in it (compensationRayNoise, or here): the second run's figure holds
// the sky's noise as the gather reads it at its hits (a uniform sky that the gather counts itself: all of it
// but the gather's own misses, which the second seed re-draws).
void gatherRayNoise(BakeState& s, std::vector<Lightmap> before, const std::vector<Lightmap>& after) {
  FinalGatherOptions o = s.plan.gather;
  o.seed = static_cast<uint32_t>(hashSeed(s.options.walk.seed, 0x676174686572ull));  // "gather"
  finalGather(*s.wholeInputs, s.directMaps, before, o);
  rayNoise(s, s.plan.compensate ? "compensationAndGatherRays" : "finalGatherRays", after, before);
}

}  // namespace

// The sky traced again with another seed into blank pages. Where its pages reach the written map as they are
// (without the final gather, or in the gather's D) the two traces are compared on the sky's pages, not on two
// gathered maps: the D copy passes the gather unchanged. The copy in the map the ray stages read reaches the
// written map only through them (scaled by the albedo, averaged over their hits): their second runs read the
// second sky (s.skyShift), so that share is in their figure and no sky noise counts twice. A uniform sky that
// the final gather counts itself is read from the pages only at the gather's hits: no skyRays, the gather's
// second run holds all of it.
void skyRayNoise(BakeState& s, const std::vector<Lightmap>& sky) {
  SkyLightOptions o = s.plan.sky;
  o.seed = static_cast<uint32_t>(hashSeed(s.options.walk.seed, 0x736b79ull));  // "sky"
  std::vector<Lightmap> again = sky;
  for (Lightmap& m : again) std::fill(m.texels.begin(), m.texels.end(), glm::vec3(0.0f));
  addSkyLight(*s.wholeInputs, again, o);
  if (!s.plan.skyByGather) rayNoise(s, "skyRays", sky, again);
  for (size_t p = 0; p < again.size(); ++p)
    for (size_t t = 0; t < again[p].size(); ++t) again[p].texels[t] -= sky[p].texels[t];
  if (s.plan.compensate || s.plan.finalGather) s.skyShift = std::move(again);
  s.skyNoiseMeasured = true;
}

namespace {

// The walk's figure with the stages' own ray noise added (independent of the walk's: the variances add),
// each part relative to the same signal in `breakdown`.
BinnedError withStages(BinnedError e, const nlohmann::json& stages, nlohmann::json& breakdown) {
  breakdown = {{"vpls", e.relative}};
  double noise2 = e.noiseRms * e.noiseRms;
  for (const auto& [stage, rms] : stages.items()) {
    noise2 += rms.get<double>() * rms.get<double>();
    breakdown[stage] = e.signalRms > 0.0 ? rms.get<double>() / e.signalRms : 0.0;
  }
  e.noiseRms = std::sqrt(noise2);
  e.relative = e.signalRms > 0.0 ? e.noiseRms / e.signalRms : 0.0;
  return e;
}

// The finished bake's figure into s.figure.
void measureFigure(BakeState& s, const std::vector<Lightmap>& maps) {
  std::vector<std::vector<Lightmap>> reps = s.plan.finalGather ? gatheredHalves(s)
                                                             : std::vector<std::vector<Lightmap>>{s.halves[0], s.halves[1]};
  const int bin = s.options.errorEstimate.bin;
  s.figure = ErrorFigure{};
  s.figure.whole = withStages(replicateError(reps, &maps, bin), s.stageNoise, s.figure.breakdown);
  s.figure.interior = withStages(replicateError(reps, &maps, bin, 1.0, BinTexels::Interior), s.stageNoiseInterior,
                                 s.figure.interiorBreakdown);
  if (s.options.errorEstimate.errorMap) s.figure.errorPages = standardErrorPages(reps);
}

}  // namespace

// Both halves' VPL sums (even and odd replicates), each scaled to a whole estimate, mixed like the map.
std::array<std::vector<Lightmap>, 2> mixedHalves(const BakeState& s, const ExactVplSums& sums) {
  std::array<std::vector<Lightmap>, 2> out;
  const float scale = 2.0f / static_cast<float>(s.replicates.size());
  for (size_t p = 0; p < s.texels.size(); ++p) {
    for (auto& half : out) {
      half.push_back(blankLightmap(s.texels[p]));
      half.back().page = static_cast<int>(p);
      if (half.back().valid.size() != half.back().size()) half.back().valid = s.texels[p].valid;
    }
    std::vector<glm::vec3> a(s.texels[p].layerSize()), b(s.texels[p].layerSize());
    tbb::parallel_for(size_t(0), a.size(), [&](size_t t) {
      const glm::vec3 odd = s.halfB.value(p, t);
      a[t] = (sums.value(p, t) - odd) * scale;
      b[t] = odd * scale;
    });
    addMixedClasses(s.texels[p], s.plan.interleave, {&a, &b}, sums.pages[p].valid, {&out[0][p], &out[1][p]},
                    s.surfaceFilters.get());
  }
  return out;
}

// The estimate between rounds: the mixed halves' spread (under the final gather scaled by the gather's
// noise ratio, measured once) over their mean plus the punctual lights. The sky and the compensation are
// left out of the normaliser, so it is at least the finished bake's figure.
double roundEstimate(BakeState& s, const ExactVplSums& sums) {
  s.halves = mixedHalves(s, sums);
  if (s.cachedDirect.empty()) s.cachedDirect = directStage(s, nullptr);
  std::vector<Lightmap> value = replicateMean({s.halves[0], s.halves[1]});
  for (size_t p = 0; p < value.size() && p < s.cachedDirect.size(); ++p)
    for (size_t t = 0; t < value[p].size() && t < s.cachedDirect[p].size(); ++t) value[p].texels[t] += s.cachedDirect[p].texels[t];
  const int bin = s.options.errorEstimate.bin;
  const BinnedError e = replicateError({s.halves[0], s.halves[1]}, &value, bin);
  if (s.plan.finalGather && s.gatherNoiseRatio == 0.0)
    s.gatherNoiseRatio = e.noiseRms > 0.0 ? replicateError(gatheredHalves(s), nullptr, bin).noiseRms / e.noiseRms : 1.0;
  return e.relative * (s.plan.finalGather ? s.gatherNoiseRatio : 1.0);
}

// The last figure into the report and the log.
void reportFigure(const BakeState& s, nlohmann::json& report) {
  const BinnedError& e = s.figure.whole;
  nlohmann::json& j = report["estimatedError"] = e.toJson();
  j["replicates"] = s.replicates.size();
  j["breakdown"] = s.figure.breakdown;
  if (s.lightCutBound > 0.0) {  // the cut's bias, independent of the noise: the squares add
    j["breakdown"]["lightCut"] = s.lightCutBound;
    j["relative"] = std::hypot(j["relative"].get<double>(), s.lightCutBound);
  }
  if (s.lightTailNoise > 0.0) {  // the sampled-back tail's noise, independent of the VPLs': the squares add
    j["breakdown"]["lightTail"] = s.lightTailNoise;
    j["relative"] = std::hypot(j["relative"].get<double>(), s.lightTailNoise);
  }
  j["interior"] = s.figure.interior.toJson();
  j["interior"]["breakdown"] = s.figure.interiorBreakdown;
  j["interior"]["texels"] = "valid texels whose four neighbours are valid: the chart-border ring left out, as "
                            "bench/cycles/compare.py scores a map";
  j["binTexels"] = s.options.errorEstimate.bin;
  j["binsHold"] = "valid texels only (relative RMS over bins of binTexels² texels): the dilation's padding is in "
                  "none (compare two bakes' pages over their valid texels: --no-dilate; docs/units.md, \"Padding\")";
  j["covers"] = "the VPL sum's noise (two independent halves of the walk, mixed and gathered as the map), and the "
                "sky's, compensation's and final gather's own ray noise (each run again with another seed)";
  j["notCovered"] = "bias (the clamp after compensation, the final gather, the geometric tail)";
  if (s.lightCutBound > 0.0) j["covers"] = j["covers"].get<std::string>() + ", and the light cut's bound (lightCull.cutBound)";
  if (s.lightTailNoise > 0.0) j["covers"] = j["covers"].get<std::string>() + ", and the sampled-back light tail's noise (lightCull.tailNoise)";
  const double moved = report.contains("finalGather") ? report["finalGather"].value("outlierFraction", 0.0) : 0.0;
  if (moved > 0.0) {  // light moved, not lost: a bias in where it lands, not in the map's mean
    j["gatherOutliersMoved"] = moved;
    j["notCovered"] = j["notCovered"].get<std::string>() + ", the final gather's outlier spread (gatherOutliersMoved: the "
                      "share of the map's light moved by up to ~15 texels)";
  }
  j["rounds"] = s.rounds;
  if (s.options.errorEstimate.targetError > 0.0) {
    j["targetError"] = s.options.errorEstimate.targetError;
    j["stoppedBy"] = s.stoppedBy;
    j["stageRays"] = s.stageRays;
    report["stoppedBy"] = s.stoppedBy;
  }
  log::info("estimated error " + percent(e.relative) + " (relative RMS on " + std::to_string(s.options.errorEstimate.bin) +
            "x" + std::to_string(s.options.errorEstimate.bin) + "-texel bins, " + std::to_string(s.replicates.size()) +
            " replicates" + (s.stageRays > 1.0 ? ", the ray stages' rays x" + shortNumber(s.stageRays) : std::string()) +
            ")");
}

void rayStages(BakeState& s, BakeResult& r, nlohmann::json& report, bool estimate) {
  StageContext ctx = stageContext(s, report);
  L1Pages* l1 = s.plan.directional ? &r.directional : nullptr;
  std::vector<Lightmap> beforeStage = estimate && s.plan.compensate ? r.maps : std::vector<Lightmap>{};
  compensationStage(ctx, r.maps, l1, s.gather.valid() ? s.gather.get() : nullptr);
  // Under the final gather the map the gather reads is not written: the compensation's second run is
  // gathered again (with another gather seed), so both stages' ray noise is measured where it shows.
  if (!beforeStage.empty()) timed(s, "errorEstimate", [&] { compensationRayNoise(s, beforeStage, r.maps); });
  if (estimate && s.plan.finalGather && beforeStage.empty()) {
    beforeStage = r.maps;
    shiftSky(s, beforeStage, 1.0f);
  }
  finalGatherStage(ctx, s.directMaps, l1 ? &s.directL1 : nullptr, r.maps, l1);
  if (s.plan.finalGather && !beforeStage.empty()) timed(s, "errorEstimate", [&] { gatherRayNoise(s, std::move(beforeStage), r.maps); });
  if (estimate) timed(s, "errorEstimate", [&] { measureFigure(s, r.maps); });
}

// A round's entry in estimatedError.rounds, before its figures.
nlohmann::json roundEntry(const BakeState& s) {
  return {{"round", s.rounds.size() + 1}, {"replicates", s.replicates.size()}, {"vpls", s.vpls.vpls.size()},
          {"stageRays", s.stageRays}};
}

// The compensation's and the final gather's rays (per sample, and their budgets) `factor` times more.
void raiseStageRays(BakeState& s, double factor) {
  if (s.stageRays == 1.0) {
    s.planCompensation = s.plan.compensation;
    s.planGather = s.plan.gather;
  }
  s.stageRays *= factor;
  auto scaled = [&s](auto n) { return static_cast<decltype(n)>(std::llround(static_cast<double>(n) * s.stageRays)); };
  s.plan.compensation.rays = scaled(s.planCompensation.rays);
  s.plan.compensation.refineRays = scaled(s.planCompensation.refineRays);
  s.plan.compensation.rayBudget = scaled(s.planCompensation.rayBudget);  // 0 (no cap) stays 0
  s.plan.gather.rays = scaled(s.planGather.rays);
  s.plan.gather.preRays = scaled(s.planGather.preRays);  // 0 (no pre-pass) stays 0
  s.plan.gather.rayBudget = scaled(s.planGather.rayBudget);
}

std::string shortNumber(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

std::string percent(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f%%", 100.0 * x);
  return text;
}

}  // namespace irbake
