// Light-transport convergence and speed. Writes two CSVs:
//   convergence: series,n,relative_rmse   (square emitter over a black plane, exact form factor)
//     vpl_halton     Keller's quasi-random walk, N paths (= N VPLs on the emitter)
//     vpl_random     the same number of VPLs at independent uniform random points (the −0.5 baseline)
//     reference_spp  the path-traced reference, N paths per texel sample
//   timing: case,vpls,texels,pairs,median_seconds,pairs_per_second   (Embree backend, median of --runs;
//           case room_floor_occluded1: one rtcOccluded1 per pair, room_floor_occluded8: packets of 8)
// Plot: python3 bench/plot_convergence.py CSV docs/convergence.png
//   light_convergence_bench [--csv PATH] [--timing-csv PATH] [--runs N] [--timing-only 1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evaluators/embree/embree_backend.h"
#include "transport/geometry_term.h"
#include "evaluators/reference/reference_integrator.h"
#include "common/atomic_file.h"
#include "sampling/sampling.h"
#include "vpl/vpl.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

const float kHeight = 0.5f;

Scene quadOverPlane() {
  Scene s;
  int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, kHeight), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  return s;
}

double relativeRmse(const Lightmap& m, const TexelSamples& t) {
  std::vector<glm::dvec3> poly = {{-0.5, -0.5, kHeight}, {0.5, -0.5, kHeight}, {0.5, 0.5, kHeight}, {-0.5, 0.5, kHeight}};
  double se = 0.0, ref2 = 0.0;
  for (size_t i = 0; i < m.size(); ++i) {
    double exact = polygonFormFactor(glm::dvec3(glm::vec3(t.positionWeight[i])), glm::dvec3(0, 0, 1), poly);
    se += (m.texels[i].x - exact) * (m.texels[i].x - exact);
    ref2 += exact * exact;
  }
  return std::sqrt(se / ref2);
}

}  // namespace

int main(int argc, char** argv) {
  bool timingOnly = false;
  std::string csv = "bench/results/light_convergence.csv", timingCsv = "bench/results/light_timing.csv";
  int runs = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string a = argv[i];
    if (a == "--csv") csv = argv[i + 1];
    else if (a == "--timing-only") timingOnly = std::atoi(argv[i + 1]) != 0;
    else if (a == "--timing-csv") timingCsv = argv[i + 1];
    else if (a == "--runs") runs = std::max(1, std::atoi(argv[i + 1]));
    else { std::fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
  }

  if (!timingOnly) {
  Scene s = quadOverPlane();
  RayTracer rt(s);
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 16, 16)};
  std::string out = "series,n,relative_rmse\n";
  for (int n = 16; n <= 16384; n *= 2) {
    WalkOptions w;
    w.paths = n;
    VplSet halton = generateVpls(s, rt, w);
    BakeInputs in{s, rt, texels, halton, VplEvalOptions{}, {}};
    double eh = relativeRmse(bakeEmbree(in)[0], texels[0]);
    // Random baseline: uniform points on the emitter, averaged over 8 independent sets (RMS).
    double er2 = 0.0;
    for (int rep = 0; rep < 8; ++rep) {
      VplSet random;
      Rng rng(hashSeed(1234, n, rep));
      for (int i = 0; i < n; ++i) {
        glm::vec3 p(float(rng.uniform() - 0.5), float(rng.uniform() - 0.5), kHeight);
        random.vpls.push_back(Vpl{p, glm::vec3(0, 0, -1), glm::vec3(float(3.14159265358979323846 / n)), 0});
      }
      BakeInputs rin{s, rt, texels, random, VplEvalOptions{}, {}};
      double e = relativeRmse(bakeEmbree(rin)[0], texels[0]);
      er2 += e * e / 8.0;
    }
    out += "vpl_halton," + std::to_string(n) + "," + std::to_string(eh) + "\n";
    out += "vpl_random," + std::to_string(n) + "," + std::to_string(std::sqrt(er2)) + "\n";
    std::printf("N=%5d  halton %.3e  random %.3e\n", n, eh, std::sqrt(er2));
  }
  for (int spp = 4; spp <= 1024; spp *= 2) {
    VplSet none;
    BakeInputs in{s, rt, texels, none, VplEvalOptions{}, {}};
    ReferenceOptions ro;
    ro.spp = spp;
    ro.seed = 7;
    double e = relativeRmse(bakeReference(in, ro)[0], texels[0]);
    out += "reference_spp," + std::to_string(spp) + "," + std::to_string(e) + "\n";
    std::printf("spp=%4d reference %.3e\n", spp, e);
  }
  std::filesystem::create_directories(std::filesystem::path(csv).parent_path().empty() ? "." : std::filesystem::path(csv).parent_path());
  writeAtomically(csv, [&](const std::filesystem::path& p) { std::ofstream(p) << out; });
  }

  // Speed: a closed grey room (every pair of sample and VPL needs a shadow ray unless facing away).
  Scene room;
  addBox(room, addMaterial(room, glm::vec3(0.6f), glm::vec3(0.0f)), glm::vec3(0), glm::vec3(4, 3, 2.5f), true, 4);
  addQuad(room, addMaterial(room, glm::vec3(0.0f), glm::vec3(5.0f)), glm::vec3(1.5f, 1, 2.49f), glm::vec3(0, 1, 0),
          glm::vec3(1, 0, 0));
  RayTracer rrt(room);
  std::vector<TexelSamples> floor = {gridSamples(glm::vec3(0), glm::vec3(4, 0, 0), glm::vec3(0, 3, 0), 64, 48)};
  std::string tout = "case,vpls,texels,pairs,median_seconds,pairs_per_second\n";
  for (int n : {256, 1024, 4096}) {
    WalkOptions w;
    w.paths = n;
    VplSet v = generateVpls(room, rrt, w);
    VplEvalOptions eval;
    eval.clampBound = deriveClampBound(room, v);
    BakeInputs in{room, rrt, floor, v, eval, {}};
    size_t pairs = 0;  // sample–VPL pairs that need a shadow ray
    for (size_t t = 0; t < floor[0].slotCount(); ++t)
      for (const Vpl& p : v.vpls)
        pairs += vplGeometryTerm(glm::vec3(floor[0].positionWeight[t]), glm::vec3(floor[0].normal[t]), p.position, p.normal) > 0.0f;
    for (bool packets : {false, true}) {
      EmbreeOptions eo;
      eo.packets = packets;
      std::vector<double> times;
      for (int r = 0; r < runs; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        bakeEmbree(in, eo);
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      double m = median(times);
      const char* name = packets ? "room_floor_occluded8" : "room_floor_occluded1";
      tout += std::string(name) + "," + std::to_string(v.vpls.size()) + "," + std::to_string(floor[0].slotCount()) + "," +
              std::to_string(pairs) + "," + std::to_string(m) + "," + std::to_string(pairs / m) + "\n";
      std::printf("%s: %zu VPLs x %zu texels: median %.3f s, %.2f M pairs/s\n", name, v.vpls.size(),
                  floor[0].slotCount(), m, pairs / m * 1e-6);
    }
  }
  writeAtomically(timingCsv, [&](const std::filesystem::path& p) { std::ofstream(p) << tout; });
  return 0;
}
