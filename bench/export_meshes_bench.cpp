// glTF export time against the number of separate meshes: a generated source glTF with N unit quads,
// each its own mesh and node, is loaded, given TEXCOORD_1 cells on one light-map page, and exported
// with that page (.gltf + .bin + PNG + EXR). Three cases per count: the source document written back
// with one shared material or one material per mesh ("source"), and the scene written by our own
// writer ("generated", one material per mesh). Only exportGltf is timed; medians of --runs (of --runs-many
// for counts above --many). Writes bench/results/export_meshes.csv; --keep leaves the exports in --dir.
//   export_meshes_bench [--meshes 1000,10000,100000] [--runs 5] [--many 50000] [--runs-many 3] [--csv PATH] [--dir FOLDER] [--keep 1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/log.h"
#include "export/gltf_export.h"
#include "export/gltf_writer.h"
#include "scene/gltf_loader.h"

namespace fs = std::filesystem;
using namespace irbake;
using json = nlohmann::json;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

// "<cpu model>, <n> cores" from /proc/cpuinfo (commas dropped: it is one CSV field).
std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown cpu";
  int cores = 0;
  while (std::getline(in, line)) {
    if (line.rfind("processor", 0) == 0) ++cores;
    if (line.rfind("model name", 0) == 0 && model == "unknown cpu") model = line.substr(line.find(':') + 2);
  }
  std::string out = model + " " + std::to_string(cores) + " cores";
  std::replace(out.begin(), out.end(), ',', ' ');
  return out;
}

// N unit quads on a grid in y = 0, each its own mesh (POSITION, NORMAL, indices) and node; one shared
// material or one per mesh.
void writeSource(size_t n, bool materialPerMesh, const fs::path& path) {
  GltfDocument doc;
  for (size_t i = 0; i < (materialPerMesh ? n : 1); ++i) {
    const double grey = 0.25 + 0.5 * double(i % 101) / 100.0;
    doc.append("materials", {{"name", "grey" + std::to_string(i)}, {"pbrMetallicRoughness", {{"baseColorFactor", {grey, grey, grey, 1.0}}}}});
  }
  const std::vector<glm::vec3> normals(4, glm::vec3(0, 1, 0));
  const std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  const size_t side = static_cast<size_t>(std::ceil(std::sqrt(double(n))));
  json roots = json::array();
  for (size_t i = 0; i < n; ++i) {
    const float x = 2.0f * float(i % side), z = -2.0f * float(i / side);
    const std::vector<glm::vec3> pos = {{x, 0, z}, {x + 1, 0, z}, {x + 1, 0, z - 1}, {x, 0, z - 1}};
    json attributes = {{"POSITION", doc.addPositions(pos)}, {"NORMAL", doc.addVec3(normals)}};
    json prim = {{"attributes", attributes}, {"indices", doc.addIndices(indices)}, {"material", materialPerMesh ? i : 0}};
    const int mesh = doc.append("meshes", {{"name", "quad" + std::to_string(i)}, {"primitives", json::array({prim})}});
    roots.push_back(doc.append("nodes", {{"mesh", mesh}}));
  }
  doc.root["scenes"] = json::array({{{"nodes", roots}}});
  doc.root["scene"] = 0;
  writeAllAtomically(doc.files(path));
}

// Each primitive's TEXCOORD_1 is its own cell of a side × side grid on page 0.
void assignCells(Scene& scene, int pageSize) {
  const size_t side = static_cast<size_t>(std::ceil(std::sqrt(double(scene.primitives.size()))));
  const float cell = 1.0f / float(side);
  for (size_t i = 0; i < scene.primitives.size(); ++i) {
    Primitive& p = scene.primitives[i];
    const float u = cell * float(i % side), v = cell * float(i / side);
    p.uv1.assign(p.positions.size(), glm::vec2(u, v));
    for (size_t k = 0; k < p.positions.size(); ++k)
      p.uv1[k] += cell * glm::vec2(p.positions[k].x - p.positions[0].x, p.positions[0].z - p.positions[k].z) * 0.8f + 0.1f * cell;
    p.lightmap = {0, pageSize, pageSize};
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<size_t> counts = {1000, 10000, 100000};
  int runs = 5;
  size_t many = 50000;  // counts above this run --runs-many times
  int runsMany = 3;
  bool keep = false;
  fs::path csvPath = fs::path(IRBAKE_BENCH_RESULTS) / "export_meshes.csv";
  fs::path dir = fs::temp_directory_path() / "irbake_export_meshes_bench";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--meshes") {
      counts.clear();
      std::stringstream list(argv[i + 1]);
      for (std::string item; std::getline(list, item, ',');) counts.push_back(std::stoul(item));
    } else if (a == "--runs") runs = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--many") many = std::stoul(argv[i + 1]);
    else if (a == "--runs-many") runsMany = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--csv") csvPath = argv[i + 1];
    else if (a == "--dir") dir = argv[i + 1];
    else if (a == "--keep") keep = std::atoi(argv[i + 1]) != 0;
  }
  log::setLevel(log::Level::Error);
  const std::string where = machine();
  std::string csv = "meshes,input,materials,seconds_median,seconds_min,seconds_max,runs,machine\n";
  const int pageSize = 256;
  Lightmap map;
  map.page = 0;
  map.width = map.height = pageSize;
  for (int i = 0; i < pageSize * pageSize; ++i) map.texels.push_back(glm::vec3(float(i % pageSize) / pageSize, 0.5f, 0.25f));
  map.valid.assign(map.texels.size(), 1);
  struct Case {
    const char* input;  // "source": the source document written back; "generated": our writer
    bool materialPerMesh;
  };
  const Case cases[] = {{"source", false}, {"source", true}, {"generated", true}};
  for (size_t n : counts)
    for (const Case& c : cases) {
      const std::string name = std::to_string(n) + "_" + c.input + (c.materialPerMesh ? "_per_mesh" : "_shared");
      const fs::path caseDir = dir / name;
      fs::remove_all(caseDir);
      fs::create_directories(caseDir / "in");
      writeSource(n, c.materialPerMesh, caseDir / "in" / "source.gltf");
      LoadOptions lo;
      lo.decodeImages = false;
      Scene scene = loadScene(caseDir / "in" / "source.gltf", lo);
      if (std::string(c.input) == "generated") scene.sourcePath.clear();
      assignCells(scene, pageSize);
      const int caseRuns = n > many ? runsMany : runs;
      std::vector<double> seconds;
      for (int r = 0; r < caseRuns; ++r) {
        ExportOptions o;
        o.output = caseDir / "out" / "baked.gltf";
        fs::remove_all(caseDir / "out");
        const auto t0 = std::chrono::steady_clock::now();
        exportGltf(scene, {map}, o);
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      char line[512];
      std::snprintf(line, sizeof line, "%zu,%s,%s,%.4f,%.4f,%.4f,%d,%s\n", n, c.input, c.materialPerMesh ? "per_mesh" : "shared",
                    median(seconds), *std::min_element(seconds.begin(), seconds.end()), *std::max_element(seconds.begin(), seconds.end()),
                    caseRuns, where.c_str());
      csv += line;
      std::printf("%s", line);
      std::fflush(stdout);
      if (!keep) fs::remove_all(caseDir);
    }
  fs::create_directories(csvPath.parent_path());
  writeAtomically(csvPath, [&](const fs::path& tmp) { std::ofstream(tmp) << csv; });
  std::printf("wrote %s\n", csvPath.string().c_str());
  return 0;
}
