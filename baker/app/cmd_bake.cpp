// irbake bake SCENE -o OUTDIR [options]: the whole bake, outputs in OUTDIR.
#include <cstdio>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "common/log.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "pipeline/bake.h"
#include "scene/gltf_loader.h"

namespace irbake::app {

int runBake(const Args& args) {
  BakeOptions o;
  // The command's default light paths: 4096. Against Blender Cycles in our own atlas (docs/accuracy.md) the
  // sample Cornell box is 4.0% at 1024 paths (3.9 s) and 2.0% at 4096 (7.3 s); the library's 1024 stays for
  // callers that choose their own budget.
  o.walk.paths = 4096;
  std::vector<std::string> scenes;
  std::string out, backend = "auto", sun, sky, env, report;
  double envIntensity = 1.0, envRotation = 0.0;
  long long seed = 0;
  double tpu = 0.0, clamp = 0.0;
  int threads = 0;
  bool quiet = false, noGltf = false, noLeakControl = false, noDilate = false, noSeams = false;
  bool noBiasCompensation = false, biasCompensation = false;

  auto app = cli::makeApp("irbake bake",
                          "Bakes light maps (EXR, irradiance/pi, linear) and exports glTF with MOZ_lightmap.\n"
                          "Writes OUTDIR/lightmap_<page>.exr, OUTDIR/scene.gltf and the report.");
  app->add_option("SCENE", scenes, "the glTF/GLB scene to bake");
  app->add_option("-o,--output", out, "output folder (OUTDIR), or OUT.glb / OUT.gltf: that glTF, the rest beside it")->type_name("OUTDIR");
  app->add_option("--backend", backend,
                  "evaluator (default auto: GL on a GPU or for scenes ≤ 10k triangles,\n"
                  "else embree; embree: ray-traced; reference: path traced)")
      ->check(CLI::IsMember({"auto", "gl", "embree", "reference"}));
  app->add_option("--vpls", o.walk.paths, "light paths of the quasi-random walk (default 4096)")
      ->transform(cli::integerIn(1, 1 << 26))->type_name("N");
  app->add_option("--bounces", o.walk.maxBounces, "diffuse bounces (default auto: follow the energy left)")
      ->transform(cli::integerOrAuto(0, 64, -1))->type_name("N|auto");
  app->add_option("--texels-per-unit", tpu, "texels per metre (default: fit about one 1024 page)")
      ->transform(cli::numberIn(0.0, 1e6))->type_name("T");
  app->add_option("--max-texels", o.atlas.maxTexels,
                  "texel budget of all pages together (default 16777216 = 16M);\n"
                  "a denser atlas fails at once, naming the density that fits;\n0 = no limit")
      ->transform(cli::integerIn(0, 1LL << 40))->type_name("N");
  app->add_option("--supersample", o.texels.supersample, "S×S samples per texel (default 1)")
      ->transform(cli::integerIn(1, 8))->type_name("S");
  auto* clampOption =
      app->add_option("--clamp", clamp, "geometry-term bound (1/m²); 0 = no clamp\n(default: derived from the scene)")
          ->transform(cli::numberIn(0.0, 1e30))
          ->type_name("B");
  app->add_option("--clamp-k", o.clampVplsPerMean,
                  "derived clamp: no VPL adds more than 1/K of the mean\n"
                  "(default 256 with bias compensation, 16 without; 0 = automatic)")
      ->transform(cli::numberIn(0.0, 1e6))->type_name("K");
  app->add_flag("--no-bias-compensation", noBiasCompensation,
               "keep the clamp's bias (default: recovered by a gather into\nthe map, after Kollig & Keller 2004)");
  app->add_flag("--bias-compensation", biasCompensation, "the default (kept for old scripts)");
  app->add_option("--comp-rays", o.compensation.rays, "bias compensation: rays per texel sample, first round (default 16)")
      ->transform(cli::integerIn(1, 4096))->type_name("N");
  app->add_option("--comp-refine", o.compensation.refineRays, "bias compensation: extra rays where needed (default 112)")
      ->transform(cli::integerIn(0, 65536))->type_name("N");
  app->add_option("--interleave", o.interleave,
                  "interleaved sampling: each texel of an N×N block sees 1/N²\n"
                  "of the VPLs, then a filter on the surface mixes them\n"
                  "(default auto: 1..4 from the texel size and the clamp radius;\n1 = every VPL everywhere)")
      ->transform(cli::integerOrAuto(1, 8, 0))->type_name("N|auto");
  app->add_option("--cube-face", o.gl.cubeFaceSize,
                  "GL backend: VPL depth-cube face size in texels\n"
                  "(default auto: a shadow texel's footprint held to the\nlight-map texel spacing, 128..256)")
      ->transform(cli::integerOrAuto(16, 2048, 0))->type_name("N|auto");
  app->add_option("--seed", seed, "walk seed (default 0)")->transform(cli::integerIn(0, 1 << 30))->type_name("K");
  app->add_option("--spp", o.referenceSpp, "reference backend: paths per texel sample (default 256)")
      ->transform(cli::integerIn(1, 1 << 20))->type_name("N");
  app->add_option("--sun", sun, "add a directional light travelling along D with irradiance E (W/m²)")
      ->transform(cli::numberList(4))->type_name("DX,DY,DZ,E");
  app->add_option("--sky", sky, "a uniform sky of that radiance (W/(m² sr)): direct light\ntraced, bounces as VPLs")
      ->transform(cli::numberList(3))->type_name("R,G,B");
  app->add_option("--env", env, "an equirectangular environment (.exr/.hdr, +Y up, centre\ntowards −Z) instead of --sky")
      ->type_name("FILE");
  app->add_option("--env-intensity", envIntensity, "scales --env (default 1)")->transform(cli::numberIn(0.0, 1e30))->type_name("S");
  app->add_option("--env-rotation", envRotation, "turns --env about +Y (degrees, default 0)")
      ->transform(cli::numberIn(-36000.0, 36000.0))->type_name("DEG");
  app->add_option("--report", report, "report path (default OUTDIR/report.json)")->type_name("R.json");
  app->add_flag("--no-gltf", noGltf, "write only the EXR pages and the report");
  app->add_flag("--no-leak-control", noLeakControl, "diagnostics: texel samples may sit behind walls");
  app->add_flag("--no-dilate", noDilate, "diagnostics: no dilation into the padding");
  app->add_flag("--no-seams", noSeams, "diagnostics: no seam stitching");
  app->add_option("--threads", threads, "worker threads (default 0: every core); the outputs are\nbyte-identical for any count")
      ->transform(cli::integerIn(0, 1024))->type_name("N");
  app->add_flag("--quiet", quiet, "warnings and errors only, no progress bars");
  if (!cli::parse(*app, args)) return 0;

  if (scenes.size() != 1)
    throw Error(ErrorCode::Usage, "", "bake needs exactly one SCENE (got " + std::to_string(scenes.size()) +
                                          "); see 'irbake bake --help'");
  if (out.empty()) throw Error(ErrorCode::Usage, "", "bake needs -o OUTDIR");
  if (quiet) log::setLevel(log::Level::Warn);
  std::unique_ptr<tbb::global_control> threadLimit;
  if (threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  o.backend = parseBackend(backend);
  o.walk.seed = static_cast<uint32_t>(seed);
  o.atlas.texelsPerUnit = static_cast<float>(tpu);
  o.texels.leakControl = !noLeakControl;
  if (clampOption->count() > 0) {
    o.eval.clampBound = static_cast<float>(clamp);
    o.autoClamp = false;
  }
  o.eval.biasCompensation = !noBiasCompensation;  // on by default; --bias-compensation kept
  o.postDilate = !noDilate;
  o.postSeams = !noSeams;

  const OutputFolderLock lock(outputFolderOf(out));  // before any work: a second bake into OUTDIR fails at once
  const std::filesystem::path scenePath = scenes[0];
  Stopwatch loadTime;
  Scene scene = loadScene(scenePath);
  if (!sun.empty()) {
    const std::vector<double> d = cli::parseNumberList(sun);
    scene.lights.push_back(sunLight(glm::vec3(d[0], d[1], d[2]), static_cast<float>(d[3])));
  }
  if (!sky.empty()) {
    const std::vector<double> L = cli::parseNumberList(sky);
    for (double v : L)
      if (!(v >= 0.0)) throw Error(ErrorCode::Usage, "", "--sky needs three radiances ≥ 0 (R,G,B)");
    scene.environment = Environment::uniform(glm::vec3(L[0], L[1], L[2]));
  }
  if (!env.empty()) {
    if (!sky.empty()) throw Error(ErrorCode::Usage, "", "--sky and --env exclude each other");
    scene.environment = loadEnvironment(env, static_cast<float>(envIntensity), static_cast<float>(envRotation));
  }
  requireLight(scene, scenePath);
  double loadSeconds = loadTime.seconds();

  TerminalProgress progress;
  o.progress = progress.callback();
  BakeResult result = bake(std::move(scene), o);
  result.report["timings"]["seconds"]["load"] = loadSeconds;

  OutputOptions oo;
  oo.outDir = out;
  oo.reportPath = report;
  oo.writeGltf = !noGltf;
  Stopwatch writeTime;
  o.progress("write", 0.0);  // coarse: EXR pages, glTF and report are written one after another
  auto files = writeBakeOutputs(result, oo);
  o.progress("write", 1.0);
  progress.finish();
  log::info("baked " + std::to_string(result.maps.size()) + " page(s) with " + result.report["backend"].get<std::string>() + " in " +
            std::to_string(result.report["timings"]["seconds"]["bake"].get<double>()) + " s (+ " + std::to_string(writeTime.seconds()) +
            " s writing)");
  for (const auto& f : files) std::printf("%s\n", f.string().c_str());
  return 0;
}

}  // namespace irbake::app
