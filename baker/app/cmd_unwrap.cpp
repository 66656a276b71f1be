// irbake unwrap IN.gltf -o OUT.gltf: the lightmap atlas alone. Writes TEXCOORD_1 and extras.lightmap
// (no maps) through the exporter, and optionally a JSON report of the atlas statistics.
#include <cstdio>
#include <fstream>
#include <string>

#include <memory>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "app/bake_option_table.h"
#include "app/commands.h"
#include "app/quality.h"
#include "atlas/atlas.h"
#include "atlas/atlas_from_bake.h"
#include "common/command_line.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_paths.h"
#include "common/output_guard.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "scene/gltf_loader.h"
#include "scene/scene_files.h"

namespace irbake::app {

namespace {

nlohmann::json reportJson(const std::string& input, const AtlasResult& r) {
  const AtlasStats& s = r.stats;
  nlohmann::json pages = nlohmann::json::array();
  for (const AtlasPage& p : r.pages) pages.push_back({{"width", p.width}, {"height", p.height}});
  return {
      {"input", input},
      {"charts", {{"total", s.charts}, {"planar", s.planarCharts}, {"lscm", s.lscmCharts}, {"split_by_checks", s.chartsSplit}}},
      {"pages", pages},
      {"texels_per_unit", s.texelsPerUnit},
      {"page_size", s.pageSize},
      {"centre_utilisation", s.centreUtilisation},
      {"area_stretch", {{"p5", s.areaStretchP5}, {"p50", s.areaStretchP50}, {"p95", s.areaStretchP95}}},
      {"l2_stretch", s.l2Stretch},
      {"overlapping_texels", s.overlappingTexels},
      {"flipped_triangles", s.flippedTriangles},
      {"uncovered_triangles", s.uncoveredTriangles},
      {"degenerate_faces", s.degenerateFaces},
      {"non_manifold_faces", s.nonManifoldFaces},
      {"seconds", {{"mesh", s.secondsMesh}, {"charts", s.secondsCharts}, {"parameterise", s.secondsParam},
                   {"pack", s.secondsPack}, {"output", s.secondsOutput}, {"stats", s.secondsStats},
                   {"total", s.secondsTotal}}},
      {"warnings", s.warnings},
  };
}

}  // namespace

int runUnwrap(const Args& args) {
  std::vector<std::string> inputs;
  std::string output, report;
  double tpu = 0.0;
  int threads = 0;
  AtlasOptions options;
  options.autoTexelsPerUnit = defaultQualityPreset().autoTexelsPerMetre;  // the bake's density rule
  auto app = cli::makeApp("irbake unwrap",
                              "Adds a lightmap UV set (TEXCOORD_1) and extras.lightmap {page, width, height} per "
                              "primitive.");
  app->add_option("IN", inputs, "the glTF/GLB scene to unwrap");
  app->add_option("-o,--output", output, "the unwrapped scene")->type_name("OUT.gltf|OUT.glb");
  // Shared with `irbake bake`: the density, the texel budget and the threads.
  addOption(*app, *findBakeOption("texels-per-unit"), &tpu)->group("Options");
  addOption(*app, *findBakeOption("max-texels"), &options.maxTexels)->group("Options");
  app->add_option("--padding", options.padding, "empty texels between charts (default 2)")
      ->transform(cli::integerIn(0, 256))->type_name("P");
  addOption(*app, *findBakeOption("page-size"), &options.maxPageSize)->group("Options");
  app->add_option("--target-page", options.targetPageSize, "the density rule: a small scene fills at least one page of this edge (default 1024)")
      ->transform(cli::integerIn(16, 16384))->type_name("S");
  app->add_flag("--keep-uv1", options.keepUv1, "keep an input TEXCOORD_1 and only repack its islands");
  app->add_option("--report", report, "write the atlas statistics")->type_name("R.json");
  addOption(*app, *findBakeOption("threads"), &threads);
  if (!cli::parse(*app, args)) return 0;
  std::unique_ptr<tbb::global_control> threadLimit;
  if (threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  if (inputs.size() != 1) throw Error(ErrorCode::Usage, "", "unwrap takes exactly one input scene");
  if (output.empty()) throw Error(ErrorCode::Usage, "", "unwrap needs -o OUT.gltf");
  const std::string input = inputs[0];
  options.texelsPerUnit = float(tpu);
  // Every output checked before any work: never onto the scene's files, a folder, or each other.
  if (!namesGltfFile(output))
    throw Error(ErrorCode::Usage, output, "unwrap writes one glTF: give -o a .gltf or .glb file name");
  const std::vector<std::filesystem::path> sceneFiles = sceneInputFiles(input);
  OutputGuard guard;
  guard.addInputs(sceneFiles);
  guard.addOutput(output, "the unwrapped glTF (-o)");
  if (hasExtension(output, ".gltf"))
    guard.addOutput(folderOf(output) / (std::filesystem::path(output).stem().string() + ".bin"), "the glTF's .bin output");
  if (!report.empty()) guard.addOutput(report, "--report");

  TerminalProgress bar;
  options.progress = bar.callback();
  Scene scene = loadScene(input);
  const AtlasResult result = buildAtlas(scene, options);
  bar.finish();

  ExportOptions exportOptions;
  exportOptions.output = output;
  exportOptions.writeExrPages = false;
  exportOptions.inputs = sceneFiles;
  exportOptions.guard = &guard;
  exportOptions.atlasRecord = atlasRecordJson(result);
  if (!report.empty()) {
    const std::string text = reportJson(input, result).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    exportOptions.alsoWrite.push_back({report, [text, report](const std::filesystem::path& tmp) {
                                         std::ofstream out(tmp, std::ios::binary);
                                         out << text;
                                         out.close();
                                         if (!out) throw Error(ErrorCode::Io, report, "cannot write the report");
                                       }});
  }
  exportGltf(scene, {}, exportOptions);
  const AtlasStats& s = result.stats;
  std::printf("%zu charts (%zu planar, %zu LSCM), %zu page(s)", s.charts, s.planarCharts, s.lscmCharts, result.pages.size());
  for (const AtlasPage& p : result.pages) std::printf(" %dx%d", p.width, p.height);
  std::printf(", %.1f texels/unit, centre-utilisation %.1f%%, area stretch p5/p50/p95 %.3f/%.3f/%.3f, overlaps %zu\n",
              s.texelsPerUnit, 100.0 * s.centreUtilisation, s.areaStretchP5, s.areaStretchP50, s.areaStretchP95, s.overlappingTexels);
  std::printf("wrote %s\n", output.c_str());
  return 0;
}

}  // namespace irbake::app
