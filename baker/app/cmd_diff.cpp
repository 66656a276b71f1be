// irbake diff A B: error figures of bake A against bake B (the reference) on the same atlas.
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "pipeline/diff.h"

namespace irbake::app {
int runDiff(const Args& args) {
  std::vector<std::string> bakes;
  bool json = false;
  auto app = cli::makeApp(
      "irbake diff",
      "Compares bake A with bake B (the reference) on the same atlas.\n"
      "A, B: bake folders (lightmap_<page>.exr, scene.gltf) or single EXR files. Texels are weighted by the\n"
      "surface area they stand for when a folder holds scene.gltf, else every texel counts once.\n"
      "relative RMSE = RMSE / RMS(B); bias = mean(A - B).");
  app->add_option("A B", bakes, "the bake to score and the reference");
  app->add_flag("--json", json, "print the figures as one JSON object");
  if (!cli::parse(*app, args)) return 0;
  if (bakes.size() != 2) throw Error(ErrorCode::Usage, "", "diff needs two bakes A B; see 'irbake diff --help'");
  BakeOnDisk bakeA = readBakeFromDisk(bakes[0]);
  BakeOnDisk bakeB = readBakeFromDisk(bakes[1]);
  const auto& areas = !bakeB.areas.empty() ? bakeB.areas : bakeA.areas;
  MapDifference d = compareMaps(bakeA.pages, bakeB.pages, areas);
  if (d.texels == 0) throw Error(ErrorCode::InvalidData, bakes[0], "no texel to compare");
  const bool areaWeighted = !areas.empty();
  if (json) {
    nlohmann::json j = {{"pages", d.pages},         {"texels", d.texels},
                        {"areaWeighted", areaWeighted}, {"weightSum", d.weightSum},
                        {"rmse", d.rmse},           {"relativeRmse", d.relativeRmse},
                        {"maxError", d.maxError},   {"meanBias", d.meanBias},
                        {"relativeBias", d.relativeBias}, {"meanA", d.meanA},
                        {"meanB", d.meanB}};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("pages %zu, texels compared %zu (%s)\n", d.pages, d.texels,
              areaWeighted ? "weighted by surface area" : "unweighted");
  std::printf("relative RMSE  %.6g  (RMSE %.6g, reference RMS-normalised)\n", d.relativeRmse, d.rmse);
  std::printf("max error      %.6g\n", d.maxError);
  std::printf("mean bias      %.6g  (%+.4g%% of the reference mean %.6g)\n", d.meanBias, 100.0 * d.relativeBias, d.meanB);
  return 0;
}

}  // namespace irbake::app
