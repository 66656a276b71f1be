#include "app/quality.h"

namespace irbake::app {

const std::vector<QualityPreset>& qualityPresets() {
  // default: the paths and rays that reach about 2% on the Cornell boxes against Cycles (docs/validation.md);
  // preview: an eighth of the paths, a quarter of the rays, and a quarter of the texels where the density is automatic
  // (every per-texel stage costs that much less); high and production: twice and four times the paths and rays.
  static const std::vector<QualityPreset> presets = {
      {"preview", 512, 384, 4, 12u << 20, 4, 28, 1u << 19, 16, 2 << 20, 4, 512},
      {"default", 4096, 3072, 16, 48u << 20, 16, 112, 1u << 21, 64, 8 << 20, 8, 1024},
      {"high", 8192, 6144, 32, 96u << 20, 32, 224, 1u << 22, 128, 16 << 20, 8, 1024},
      {"production", 16384, 12288, 64, 192u << 20, 64, 448, 1u << 23, 256, 32 << 20, 12, 1024},
  };
  return presets;
}

const QualityPreset* findQualityPreset(const std::string& name) {
  for (const QualityPreset& p : qualityPresets())
    if (name == p.name) return &p;
  return nullptr;
}

}  // namespace irbake::app
