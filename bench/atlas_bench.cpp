// Atlas benchmark on the shared scenes against xatlas's figures (docs/atlas.md; same protocol: padding 2,
// one page that grows to fit, single thread). Writes bench/results/atlas.csv; quotes medians of --runs.
//   atlas_bench [--scenes DIR] [--runs N] [--csv PATH] [--threads N]
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "atlas/atlas.h"
#include "common/atomic_file.h"
#include "common/log.h"
#include "scene/gltf_loader.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {

struct Case {
  std::string name, file;
  double texelsPerUnit, scale;
  double xatlasUtil, xatlasSeconds;
  int xatlasCharts;
  std::string target;
};

double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

}  // namespace

int main(int argc, char** argv) {
  fs::path scenes;
  if (const char* src = std::getenv("IRBAKE_SOURCE_DIR")) scenes = fs::path(src) / ".." / "shared" / "scenes";
  if (scenes.empty() || !fs::exists(scenes)) scenes = "/work/shared/scenes";
  int runs = 5, threads = 1;
  std::string only;  // run one case by name
  fs::path csvPath = fs::path(__FILE__).parent_path() / "results" / "atlas.csv";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--scenes") scenes = argv[i + 1];
    else if (a == "--runs") runs = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--csv") csvPath = argv[i + 1];
    else if (a == "--threads") threads = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--only") only = argv[i + 1];
  }
  if (!fs::exists(scenes)) {
    std::fprintf(stderr, "atlas_bench: no shared scenes at %s\n", scenes.string().c_str());
    return 2;
  }
  log::setLevel(log::Level::Error);
  tbb::global_control single(tbb::global_control::max_allowed_parallelism, size_t(threads));
  const std::vector<Case> cases = {
      {"gazebo", "gazebo/gazebo.glb", 60, 1.0, 0.686, 0.07, 332, "util>=68.6%"},
      {"bunny", "stanford_bunny/bunny.glb", 3500, 1.0, 0.565, 18.8, 588, "util>=60%; t<=2s; charts<=100"},
      {"bunny_x0.01", "stanford_bunny/bunny.glb", 3500 / 0.01, 0.01, 0.565, 18.8, 588, "same charts; util within 1%"},
      {"bunny_x100", "stanford_bunny/bunny.glb", 3500 / 100.0, 100.0, 0.565, 18.8, 588, "same charts; util within 1%"},
      {"helmet", "damaged_helmet/DamagedHelmet.gltf", 200, 1.0, 0.445, 0.29, 890, "util>=50%"},
      {"cornell", "cornell_box/cornell_box.glb", 170, 1.0, 0.783, 0.01, 18, "util>=78%"},
  };
  std::string csv =
      "scene,texels_per_unit,scale,triangles,charts,planar_charts,lscm_charts,pages,page_w,page_h,centre_util,"
      "stretch_p5,stretch_p50,stretch_p95,l2_stretch,overlapping_texels,flipped,uncovered,degenerate,"
      "median_s,min_s,max_s,median_cpu_s,runs,xatlas_charts,xatlas_util,xatlas_s,target\n";
  std::printf("%-12s %7s %6s %8s %7s %9s %6s %6s %8s %8s\n", "scene", "charts", "pages", "size", "util", "p5/p95", "ovl", "flip",
              "median_s", "xatlas");
  for (const Case& c : cases) {
    if (!only.empty() && c.name != only) continue;
    const fs::path path = scenes / c.file;
    if (!fs::exists(path)) {
      std::printf("%-12s missing (%s)\n", c.name.c_str(), path.string().c_str());
      continue;
    }
    LoadOptions lo;
    lo.decodeImages = false;
    const Scene loaded = loadScene(path, lo);
    std::vector<double> seconds, cpu;  // wall clock and process CPU time (the machine is shared)
    AtlasResult last;
    size_t triangles = 0;
    for (int r = 0; r < runs; ++r) {
      Scene scene = loaded;
      for (Primitive& p : scene.primitives)
        for (glm::vec3& v : p.positions) v *= float(c.scale);
      triangles = scene.triangleCount();
      AtlasOptions options;
      options.texelsPerUnit = float(c.texelsPerUnit);
      options.padding = 2;
      options.maxPageSize = 16384;  // "one page that grows to fit"
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpuSeconds();
      last = buildAtlas(scene, options);
      cpu.push_back(cpuSeconds() - c0);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    const AtlasStats& s = last.stats;
    const int pw = last.pages.empty() ? 0 : last.pages[0].width, ph = last.pages.empty() ? 0 : last.pages[0].height;
    char line[1024];
    std::snprintf(line, sizeof line, "%s,%g,%g,%zu,%zu,%zu,%zu,%zu,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%zu,%zu,%zu,%zu,%.4f,%.4f,%.4f,%.4f,%d,%d,%.3f,%.2f,%s\n",
                  c.name.c_str(), c.texelsPerUnit, c.scale, triangles, s.charts, s.planarCharts, s.lscmCharts, last.pages.size(), pw, ph,
                  s.centreUtilisation, s.areaStretchP5, s.areaStretchP50, s.areaStretchP95, s.l2Stretch, s.overlappingTexels,
                  s.flippedTriangles, s.uncoveredTriangles, s.degenerateFaces, median(seconds),
                  *std::min_element(seconds.begin(), seconds.end()), *std::max_element(seconds.begin(), seconds.end()), median(cpu), runs,
                  c.xatlasCharts, c.xatlasUtil, c.xatlasSeconds, c.target.c_str());
    csv += line;
    std::printf("%-12s %7zu %6zu %4dx%-4d %6.1f%% %4.2f/%4.2f %6zu %6zu %8.3f cpu %6.3f  %d ch %.1f%% %.2fs | mesh %.3f charts %.3f param %.3f pack %.3f out %.3f stats %.3f split %zu\n",
                c.name.c_str(), s.charts, last.pages.size(), pw, ph, 100 * s.centreUtilisation, s.areaStretchP5, s.areaStretchP95,
                s.overlappingTexels, s.flippedTriangles, median(seconds), median(cpu), c.xatlasCharts, 100 * c.xatlasUtil, c.xatlasSeconds,
                s.secondsMesh, s.secondsCharts, s.secondsParam, s.secondsPack, s.secondsOutput, s.secondsStats, s.chartsSplit);
    std::fflush(stdout);
  }
  fs::create_directories(csvPath.parent_path());
  writeAtomically(csvPath, [&](const fs::path& tmp) { std::ofstream(tmp) << csv; });
  std::printf("wrote %s\n", csvPath.string().c_str());
  return 0;
}
