// --quality: named sets of the sampling knobs a user would otherwise tune one by one. `default` is the
// command's default bake: its rays, budgets, shadow-edge sub-samples and page edge are the stages' own option
// defaults, its light paths are set in quality.cpp, and the other presets scale it. Every knob a preset sets is
// still overridden by its own option when given. Figures for each (time, memory, error against Cycles):
// docs/validation.md.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace irbake::app {

struct QualityPreset {
  const char* name;
  int paths;                  // --paths auto: light paths of the walk
  int pathsUnderGather;       // --paths auto where the final gather runs (it reads their map averaged)
  int gatherRays;             // --gather-rays
  size_t gatherRayBudget;     // --gather-ray-budget
  int compensationRays;       // --comp-rays
  int compensationRefine;     // --comp-refine
  size_t compensationBudget;  // --comp-ray-budget
  int skyRays;                // --sky-rays
  int skyRayBudget;           // --sky-ray-budget
  int shadowEdgeSamples;      // --shadow-edge-samples
  int autoPageSize;           // --texels-per-unit auto: small scenes get at least one page of this edge
  double autoTexelsPerMetre;  // --texels-per-unit auto: the density rule's texels per metre
};

// preview, default, high, production (in that order).
const std::vector<QualityPreset>& qualityPresets();
// The preset of that name; nullptr when there is none.
const QualityPreset* findQualityPreset(const std::string& name);
// --quality default: the command's defaults (its help quotes them).
const QualityPreset& defaultQualityPreset();

}  // namespace irbake::app
