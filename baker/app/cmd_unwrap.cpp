// irbake unwrap IN.gltf -o OUT.gltf: the lightmap atlas alone. Writes TEXCOORD_1 and extras.lightmap
// (no maps) through the exporter, and optionally a JSON report of the atlas statistics.
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "atlas/atlas.h"
#include "common/args.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "scene/gltf_loader.h"

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
      {"centre_utilisation", s.centreUtilisation},
      {"area_stretch", {{"p5", s.areaStretchP5}, {"p50", s.areaStretchP50}, {"p95", s.areaStretchP95}}},
      {"l2_stretch", s.l2Stretch},
      {"overlapping_texels", s.overlappingTexels},
      {"flipped_triangles", s.flippedTriangles},
      {"uncovered_triangles", s.uncoveredTriangles},
      {"degenerate_faces", s.degenerateFaces},
      {"non_manifold_faces", s.nonManifoldFaces},
      {"seconds", {{"mesh", s.secondsMesh}, {"charts", s.secondsCharts}, {"parameterise", s.secondsParam},
                   {"pack", s.secondsPack}, {"output", s.secondsOutput}, {"stats", s.secondsStats}}},
      {"warnings", s.warnings},
  };
}

}  // namespace

int runUnwrap(const Args& args) {
  ArgParser parser(args, {"-o", "--texels-per-unit", "--padding", "--max-page", "--target-page", "--report"},
                   {"--help", "--keep-uv1"});
  if (parser.flag("--help")) {
    std::puts("usage: irbake unwrap IN.gltf -o OUT.gltf|OUT.glb [--texels-per-unit T] [--padding P] [--max-page S]\n"
              "                     [--target-page S] [--keep-uv1] [--report R.json]\n"
              "  adds a lightmap UV set (TEXCOORD_1) and extras.lightmap {page, width, height} per primitive\n"
              "  --texels-per-unit T  texel density per metre (default: fit the charts into about one target page)\n"
              "  --padding P          empty texels between charts (default 2)\n"
              "  --max-page S         largest page edge in texels (default 2048); more pages when full\n"
              "  --target-page S      page edge the automatic density aims at (default 1024)\n"
              "  --keep-uv1           keep an input TEXCOORD_1 and only repack its islands\n"
              "  --report R.json      write the atlas statistics");
    return 0;
  }
  if (parser.positionals().size() != 1) throw Error(ErrorCode::Usage, "", "unwrap takes exactly one input scene");
  const auto output = parser.value("-o");
  if (!output) throw Error(ErrorCode::Usage, "", "unwrap needs -o OUT.gltf");
  const std::string input = parser.positionals()[0];
  AtlasOptions options;
  options.texelsPerUnit = float(parser.doubleOr("--texels-per-unit", 0.0));
  options.padding = parser.intOr("--padding", 2);
  options.maxPageSize = parser.intOr("--max-page", 2048);
  options.targetPageSize = parser.intOr("--target-page", 1024);
  options.keepUv1 = parser.flag("--keep-uv1");
  if (options.texelsPerUnit < 0.0f) throw Error(ErrorCode::Usage, "", "--texels-per-unit must be > 0");
  if (options.padding < 0) throw Error(ErrorCode::Usage, "", "--padding must be ≥ 0");
  if (options.maxPageSize < 16 || options.maxPageSize > 16384) throw Error(ErrorCode::Usage, "", "--max-page must be in 16..16384");
  if (options.targetPageSize < 16) throw Error(ErrorCode::Usage, "", "--target-page must be ≥ 16");

  TerminalProgress bar;
  options.progress = bar.callback();
  Scene scene = loadScene(input);
  const AtlasResult result = buildAtlas(scene, options);
  bar.finish();

  ExportOptions exportOptions;
  exportOptions.output = *output;
  exportOptions.writeExrPages = false;
  exportGltf(scene, {}, exportOptions);
  if (const auto report = parser.value("--report")) {
    const std::string text = reportJson(input, result).dump(2) + "\n";
    writeAtomically(*report, [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp);
      out << text;
      if (!out) throw Error(ErrorCode::Io, report->c_str(), "cannot write the report");
    });
  }
  const AtlasStats& s = result.stats;
  std::printf("%zu charts (%zu planar, %zu LSCM), %zu page(s)", s.charts, s.planarCharts, s.lscmCharts, result.pages.size());
  for (const AtlasPage& p : result.pages) std::printf(" %dx%d", p.width, p.height);
  std::printf(", %.1f texels/unit, centre-utilisation %.1f%%, area stretch p5/p50/p95 %.3f/%.3f/%.3f, overlaps %zu\n",
              s.texelsPerUnit, 100.0 * s.centreUtilisation, s.areaStretchP5, s.areaStretchP50, s.areaStretchP95, s.overlappingTexels);
  std::printf("wrote %s\n", output->c_str());
  return 0;
}

}  // namespace irbake::app
