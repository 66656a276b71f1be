// Error figures between two bakes of the same atlas (irbake diff, the benchmarks, the tests).
#pragma once
#include <filesystem>
#include <vector>

#include "lightmap/lightmap.h"

namespace irbake {

// All figures over the compared texels (weight > 0), all channels, B taken as the reference.
struct MapDifference {
  size_t pages = 0;
  size_t texels = 0;            // texels compared
  double weightSum = 0.0;       // Σ w (m² when area-weighted)
  double rmse = 0.0;            // sqrt(Σ w ‖a−b‖²/3 / Σ w)
  double relativeRmse = 0.0;    // rmse / sqrt(Σ w ‖b‖²/3 / Σ w): RMSE over the reference's RMS
  double maxError = 0.0;        // max |a−b| over texels and channels
  double meanBias = 0.0;        // Σ w mean(a−b) / Σ w
  double relativeBias = 0.0;    // meanBias / (Σ w mean(b) / Σ w)
  double meanA = 0.0, meanB = 0.0;  // weighted means of the channel mean
};

// weights: per page, per texel (empty vector: weight = map valid flag of A·B, 1/0). Pages must
// match in count and size; throws Error(InvalidData) otherwise.
MapDifference compareMaps(const std::vector<Lightmap>& a, const std::vector<Lightmap>& b,
                          const std::vector<std::vector<float>>& weights = {});

// A bake on disk: a folder (its lightmap_<page>.exr pages, and its scene.gltf for texel areas when
// present) or one EXR file. areas is filled from the glTF's uv1 (empty when there is none).
struct BakeOnDisk {
  std::vector<Lightmap> pages;
  std::vector<std::vector<float>> areas;
  std::filesystem::path gltf;  // the glTF that gave the areas ("" if none)
};
BakeOnDisk readBakeFromDisk(const std::filesystem::path& path);

}  // namespace irbake
