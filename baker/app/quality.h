// --quality: named sets of the sampling knobs a user would otherwise tune one by one. `default` is the
// command's default bake; every knob it sets is still overridden by its own option when given.
// Figures for each (time, memory, error against Cycles): docs/validation.md.
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
  int autoPageSize;           // --texels-per-unit auto: the density fills about one page of this edge
};

// preview, default, high, production (in that order).
const std::vector<QualityPreset>& qualityPresets();
// The preset of that name; nullptr when there is none.
const QualityPreset* findQualityPreset(const std::string& name);

}  // namespace irbake::app
