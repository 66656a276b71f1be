#include "app/quality.h"

#include "pipeline/bake.h"

namespace irbake::app {

namespace {

// The command's light paths (--paths auto at --quality default). The library's WalkOptions::paths is the
// smaller default its own callers are tuned to; the command always sets the walk's paths from here.
constexpr int kDefaultPaths = 4096;

// The density rule's texels per metre at --quality default (AtlasOptions::autoTexelsPerUnit): a level's maps
// are at least this fine; a small scene or a detailed model gets more (docs/guide.md, "Texel density").
constexpr double kDefaultTexelsPerMetre = 16.0;

// value × num / den: a preset as a multiple of the default bake.
struct Scale {
  long long num = 1, den = 1;
  template <typename T>
  T of(T value) const { return static_cast<T>(static_cast<long long>(value) * num / den); }
};

// Where the final gather runs, three quarters of the paths: it reads their map averaged over each texel's
// hemisphere, so more paths barely lower the error there.
constexpr Scale kPathsUnderGather{3, 4};

// The default bake scaled: paths, every stage's rays and ray budgets, the shadow-edge sub-samples per axis and
// the automatic page edge. The rays, budgets, sub-samples and page edge start from each stage's option struct.
QualityPreset scaledDefault(const char* name, Scale paths, Scale rays, Scale edgeSamples, Scale page, double texelsPerMetre) {
  const BakeOptions base;
  const int p = paths.of(kDefaultPaths);
  return {name,
          p,
          kPathsUnderGather.of(p),
          rays.of(base.gather.rays),
          rays.of(base.gather.rayBudget),
          rays.of(base.compensation.rays),
          rays.of(base.compensation.refineRays),
          rays.of(base.compensation.rayBudget),
          rays.of(base.sky.raysPerSample),
          rays.of(base.sky.maxRays),
          edgeSamples.of(base.shadowEdges.subSamples),
          page.of(base.atlas.targetPageSize),
          texelsPerMetre};
}

}  // namespace

const std::vector<QualityPreset>& qualityPresets() {
  // preview: an eighth of the paths, a quarter of the rays, half the shadow-edge sub-samples per axis and a quarter
  // of the texels where the density is automatic (every per-texel stage costs that much less); high and
  // production: twice and four times the paths and rays (production also 1.5× the sub-samples per axis).
  // Texels per metre of the density rule (docs/guide.md "Texel density"): preview half the default's (a quarter
  // of the texels); high and production the default's (they spend their time on paths and rays).
  static const std::vector<QualityPreset> presets = {
      scaledDefault("preview", {1, 8}, {1, 4}, {1, 2}, {1, 2}, kDefaultTexelsPerMetre / 2),
      scaledDefault("default", {}, {}, {}, {}, kDefaultTexelsPerMetre),
      scaledDefault("high", {2, 1}, {2, 1}, {}, {}, kDefaultTexelsPerMetre),
      scaledDefault("production", {4, 1}, {4, 1}, {3, 2}, {}, kDefaultTexelsPerMetre),
  };
  return presets;
}

const QualityPreset* findQualityPreset(const std::string& name) {
  for (const QualityPreset& p : qualityPresets())
    if (name == p.name) return &p;
  return nullptr;
}

const QualityPreset& defaultQualityPreset() { return *findQualityPreset("default"); }

}  // namespace irbake::app
