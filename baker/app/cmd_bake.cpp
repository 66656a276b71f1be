// irbake bake SCENE -o OUTDIR [options]: the whole bake, outputs in OUTDIR.
#include <cstdio>
#include <string>

#include "app/commands.h"
#include "common/args.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "pipeline/bake.h"
#include "scene/gltf_loader.h"

namespace irbake::app {
namespace {
const char* kBakeHelp =
    "usage: irbake bake SCENE -o OUTDIR [options]\n"
    "  --backend auto|gl|embree|reference   evaluator (default auto: GL on a GPU or for small scenes, else embree)\n"
    "  --vpls N                 light paths of the quasi-random walk (default 1024)\n"
    "  --bounces N|auto         diffuse bounces (default auto: follow the energy left)\n"
    "  --texels-per-unit T      texels per metre (default: fit about one 1024 page)\n"
    "  --supersample S          S×S samples per texel (default 1)\n"
    "  --clamp B                geometry-term bound (1/m²); 0 = no clamp (default: derived from the scene)\n"
    "  --clamp-k K              derived clamp: no VPL adds more than 1/K of the mean (default 256 with\n"
    "                           bias compensation, 16 without)\n"
    "  --no-bias-compensation   keep the clamp's bias (default: recovered by a gather into the map,\n"
    "                           after Kollig & Keller 2004; --comp-rays N, --comp-refine N rays per sample)\n"
    "  --interleave N|auto      interleaved sampling: each texel of an N×N block sees 1/N² of the VPLs,\n"
    "                           then a filter on the surface mixes them (default auto: 1..4 from the texel\n"
    "                           size and the clamp radius; 1 = every VPL everywhere)\n"
    "  --sky R,G,B              a uniform sky of that radiance (W/(m² sr)): direct light traced, bounces as VPLs\n"
    "  --env FILE.exr|.hdr      an equirectangular environment (+Y up, centre towards −Z) instead;\n"
    "  --env-intensity S        scales it (default 1), --env-rotation DEG turns it about +Y\n"
    "  --cube-face N|auto       GL backend: VPL depth-cube face size in texels (default auto: a shadow\n"
    "                           texel's footprint held to the light-map texel spacing, 128..256)\n"
    "  --seed K                 walk seed (default 0)\n"
    "  --spp N                  reference backend: paths per texel sample (default 256)\n"
    "  --sun DX,DY,DZ,E         add a directional light travelling along D with irradiance E (W/m²)\n"
    "  --report R.json          report path (default OUTDIR/report.json)\n"
    "  --no-gltf                write only the EXR pages and the report\n"
    "  --no-leak-control --no-dilate --no-seams   switch post/texel stages off (diagnostics)\n"
    "  --quiet                  warnings and errors only\n"
    "writes OUTDIR/lightmap_<page>.exr (irradiance/pi, linear), OUTDIR/scene.gltf and the report\n";

int positiveInt(const ArgParser& a, const std::string& name, int fallback, int lo, int hi) {
  int v = a.intOr(name, fallback);
  if (v < lo || v > hi)
    throw Error(ErrorCode::Usage, "", "option " + name + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                          "], got " + std::to_string(v));
  return v;
}
}  // namespace

int runBake(const Args& args) {
  ArgParser a(args,
              {"-o", "--output", "--backend", "--vpls", "--bounces", "--texels-per-unit", "--supersample", "--clamp",
               "--seed", "--spp", "--report", "--sun", "--clamp-k", "--comp-rays", "--comp-refine", "--interleave",
               "--cube-face", "--sky", "--env", "--env-intensity", "--env-rotation"},
              {"--help", "-h", "--bias-compensation", "--no-bias-compensation", "--no-gltf", "--no-leak-control", "--no-dilate", "--no-seams",
               "--quiet"});
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(kBakeHelp, stdout);
    return 0;
  }
  if (a.positionals().size() != 1)
    throw Error(ErrorCode::Usage, "", "bake needs exactly one SCENE (got " + std::to_string(a.positionals().size()) +
                                          "); see 'irbake bake --help'");
  auto out = a.value("-o") ? a.value("-o") : a.value("--output");
  if (!out || out->empty()) throw Error(ErrorCode::Usage, "", "bake needs -o OUTDIR");
  if (a.flag("--quiet")) log::setLevel(log::Level::Warn);

  BakeOptions o;
  o.backend = parseBackend(a.valueOr("--backend", "auto"));
  o.walk.paths = positiveInt(a, "--vpls", o.walk.paths, 1, 1 << 26);
  std::string bounces = a.valueOr("--bounces", "auto");
  o.walk.maxBounces = bounces == "auto" ? -1 : positiveInt(a, "--bounces", 0, 0, 64);
  o.walk.seed = static_cast<uint32_t>(positiveInt(a, "--seed", 0, 0, 1 << 30));
  double tpu = a.doubleOr("--texels-per-unit", 0.0);
  if (tpu < 0.0 || tpu > 1e6) throw Error(ErrorCode::Usage, "", "option --texels-per-unit must be in [0, 1e6]");
  o.atlas.texelsPerUnit = static_cast<float>(tpu);
  o.texels.supersample = positiveInt(a, "--supersample", 1, 1, 8);
  o.texels.leakControl = !a.flag("--no-leak-control");
  if (a.value("--clamp")) {
    double clamp = a.doubleOr("--clamp", 0.0);
    if (clamp < 0.0) throw Error(ErrorCode::Usage, "", "option --clamp must be >= 0 (0 = no clamp)");
    o.eval.clampBound = static_cast<float>(clamp);
    o.autoClamp = false;
  }
  o.eval.biasCompensation = !a.flag("--no-bias-compensation");  // on by default; --bias-compensation kept
  o.clampVplsPerMean = a.doubleOr("--clamp-k", 0.0);
  if (o.clampVplsPerMean < 0.0 || o.clampVplsPerMean > 1e6)
    throw Error(ErrorCode::Usage, "", "option --clamp-k must be in [0, 1e6] (0 = automatic)");
  o.compensation.rays = positiveInt(a, "--comp-rays", o.compensation.rays, 1, 4096);
  o.compensation.refineRays = positiveInt(a, "--comp-refine", o.compensation.refineRays, 0, 65536);
  o.referenceSpp = positiveInt(a, "--spp", o.referenceSpp, 1, 1 << 20);
  o.interleave = a.valueOr("--interleave", "auto") == "auto" ? 0 : positiveInt(a, "--interleave", 0, 1, 8);
  o.gl.cubeFaceSize = a.valueOr("--cube-face", "auto") == "auto" ? 0 : positiveInt(a, "--cube-face", 0, 16, 2048);
  o.postDilate = !a.flag("--no-dilate");
  o.postSeams = !a.flag("--no-seams");

  const std::filesystem::path scenePath = a.positionals()[0];
  Stopwatch loadTime;
  Scene scene = loadScene(scenePath);
  if (auto sun = a.numberList("--sun", 4); !sun.empty())
    scene.lights.push_back(sunLight(glm::vec3(sun[0], sun[1], sun[2]), static_cast<float>(sun[3])));
  if (auto sky = a.numberList("--sky", 3); !sky.empty()) {
    for (double c : sky)
      if (!(c >= 0.0) || !std::isfinite(c)) throw Error(ErrorCode::Usage, "", "--sky needs three radiances ≥ 0 (R,G,B)");
    scene.environment = Environment::uniform(glm::vec3(sky[0], sky[1], sky[2]));
  }
  if (auto env = a.value("--env")) {
    if (a.value("--sky")) throw Error(ErrorCode::Usage, "", "--sky and --env exclude each other");
    scene.environment = loadEnvironment(*env, static_cast<float>(a.doubleOr("--env-intensity", 1.0)),
                                        static_cast<float>(a.doubleOr("--env-rotation", 0.0)));
  }
  requireLight(scene, scenePath);
  double loadSeconds = loadTime.seconds();

  TerminalProgress progress;
  o.progress = progress.callback();
  BakeResult result = bake(std::move(scene), o);
  progress.finish();
  result.report["seconds"]["load"] = loadSeconds;

  OutputOptions oo;
  oo.outDir = *out;
  oo.reportPath = a.valueOr("--report", "");
  oo.writeGltf = !a.flag("--no-gltf");
  Stopwatch writeTime;
  auto files = writeBakeOutputs(result, oo);
  log::info("baked " + std::to_string(result.maps.size()) + " page(s) with " + result.report["backend"].get<std::string>() + " in " +
            std::to_string(result.report["seconds"]["bake"].get<double>()) + " s (+ " + std::to_string(writeTime.seconds()) +
            " s writing)");
  for (const auto& f : files) std::printf("%s\n", f.string().c_str());
  return 0;
}

}  // namespace irbake::app
