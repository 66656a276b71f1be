// irbake bake SCENE -o OUTDIR [options]: the whole bake, outputs in OUTDIR; or one shard of it (--shard),
// or the rest of one that was killed (--resume).
#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <memory>
#include <string>
#include <type_traits>

#include <tbb/global_control.h>

#include "app/bake_command.h"
#include "app/bake_config.h"
#include "app/quality.h"
#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "common/excerpt.h"
#include "common/file_paths.h"
#include "common/log.h"
#include "common/output_guard.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "pipeline/backend_choice.h"
#include "pipeline/bake.h"
#include "pipeline/vpl_sum_file.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/interleave/interleaved_sampling.h"
#include "transport/geometry_term.h"
#include "common/atomic_file.h"
#include "scene/gltf_loader.h"
#include "scene/scene_files.h"
#include "scene/scene_limits.h"

namespace irbake::app {

namespace {

// What CLI11 writes that is not a BakeCommand field as such (turned into options by applyArguments).
struct BakeArguments {
  std::vector<std::string> scenes;
  std::string backend = "auto", shard, finalGather = "auto", quality = "default";
  std::string config, dumpConfig;  // --config FILE (read before parsing), --dump-config FILE
  std::string sun, sky, env;       // --sun, --sky, --env as given (BakeCommand::lights once checked)
  std::string probes = "auto", probeBox;  // --probes auto|off|SPACING, --probe-box as given
  std::vector<std::string> lightModes;  // --light-mode NAME=MODE as given
  std::string lightModeOrigin;          // "FILE: line N: key 'light-mode'" when the config file gave them
  double envIntensity = 1.0, envRotation = 0.0;
  bool helpAll = false;
  CLI::Option* shardOption = nullptr;
  long long seed = 0;
  double tpu = 0.0, clamp = 0.0, vplImportance = 0.0;  // 0: auto
  int bounces = -1, interleave = 0, cubeFace = 0, compFilter = -1, walkSplit = 0, paths = 0;  // "auto" as cli::integerOrAuto writes it (kept for the options hash)
  bool noLeakControl = false, noDilate = false, noSeams = false;
  bool noBiasCompensation = false, biasCompensation = false;
  CLI::Option* clampOption = nullptr;
  std::string clampText() const { return clampOption && !clampOption->results().empty() ? clampOption->results()[0] : ""; }
};

// The smallest --clamp bound: below it the bound is 0 in single precision.
constexpr double kSmallestClamp = 1e-30;
// Light from the command line: at most this much (W/m², W/(m² sr)), so sums over the bake stay finite in float.
constexpr double kLargestLight = 1e20;

// A default as the help quotes it, read from where the default is defined: integers in full, others as %g.
template <typename T>
std::string shown(T value) {
  if constexpr (std::is_integral_v<T>) {
    return std::to_string(value);
  } else {
    std::ostringstream s;
    s << value;
    return s.str();
  }
}

// --sun, --sky and --env as light a bake can use: a direction that is not zero (any length), amounts in
// [0, kLargestLight], not both a sky and a map. Throws Error(Usage) naming the option.
LightAdditions lightArguments(const BakeArguments& a) {
  LightAdditions lights;
  if (!a.sun.empty()) {
    const std::vector<double> d = cli::parseNumberList(a.sun);
    const double longest = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
    if (!(longest > 0.0)) throw Error(ErrorCode::Usage, "", "--sun needs a non-zero direction DX,DY,DZ (got '" + a.sun + "')");
    if (!(d[3] > 0.0) || d[3] > kLargestLight)
      throw Error(ErrorCode::Usage, "", "--sun needs an irradiance E in (0, 1e20] W/m² (got '" + a.sun + "')");
    const glm::dvec3 direction = glm::normalize(glm::dvec3(d[0], d[1], d[2]) / longest);
    lights.sun = directionalLight(glm::vec3(direction), static_cast<float>(d[3]));
  }
  if (!a.sky.empty()) {
    const std::vector<double> L = cli::parseNumberList(a.sky);
    for (double v : L)
      if (!(v >= 0.0) || v > kLargestLight)
        throw Error(ErrorCode::Usage, "", "--sky needs three radiances in [0, 1e20] W/(m² sr) (got '" + a.sky + "')");
    lights.sky = glm::vec3(L[0], L[1], L[2]);
  }
  if (!a.env.empty() && lights.sky) throw Error(ErrorCode::Usage, "", "--sky and --env exclude each other");
  lights.environment = a.env;
  lights.environmentIntensity = static_cast<float>(a.envIntensity);
  lights.environmentRotation = static_cast<float>(a.envRotation);
  return lights;
}

// --probes auto|off|SPACING and --probe-box into the probe stage's options. Throws Error(Usage) naming the option.
void probeArguments(const BakeArguments& a, ProbeOptions& o) {
  o.enabled = a.probes != "off";
  if (o.enabled && a.probes != "auto") {
    char* end = nullptr;
    const double spacing = std::strtod(a.probes.c_str(), &end);
    if (a.probes.empty() || *end != '\0' || !(static_cast<float>(spacing) >= kMinProbeSpacing) || !(spacing <= 1e6))
      throw Error(ErrorCode::Usage, "", "--probes needs auto, off or a spacing in metres from 0.01 to 1e6 (got '" + a.probes + "')");
    o.spacing = static_cast<float>(spacing);
  }
  if (!a.probeBox.empty()) {
    // Checked in double before the conversion to float: 1e300 would become Inf, and a box beyond the scene's
    // coordinates would start the probes' rays where Embree aborts.
    const std::vector<double> b = cli::parseNumberList(a.probeBox);
    for (double v : b)
      if (!(std::abs(v) <= kMaxSceneCoordinate))
        throw Error(ErrorCode::Usage, "", "--probe-box needs coordinates within the supported ±1e9 m (got '" + a.probeBox + "')");
    Bounds3 box;
    box.min = glm::vec3(b[0], b[1], b[2]);
    box.max = glm::vec3(b[3], b[4], b[5]);
    if (!(box.min.x <= box.max.x && box.min.y <= box.max.y && box.min.z <= box.max.z))
      throw Error(ErrorCode::Usage, "", "--probe-box needs X0,Y0,Z0,X1,Y1,Z1 with each minimum ≤ its maximum (got '" + a.probeBox + "')");
    if (!(box.min.x < box.max.x && box.min.y < box.max.y && box.min.z < box.max.z))
      throw Error(ErrorCode::Usage, "", "--probe-box needs a size on every axis (got '" + a.probeBox +
                                            "'): a size below the spacing gives one layer of probes there");
    o.box = box;
  }
}

// The options a user sets, shown by --help; the rest by --help-all, in groups by stage.
const std::vector<std::string> kCommonOptions = {"SCENE", "output", "quality", "config", "sun", "sky", "env",
                                                 "texels-per-unit", "directional", "probes", "seed", "target-error",
                                                 "threads", "report",
                                                 "quiet", "portable", "help", "help-all"};
const std::vector<std::pair<std::string, std::vector<std::string>>> kOptionGroups = {
    {"Light paths and VPLs", {"paths", "bounces", "walk-split", "vpl-importance", "vpl-probes", "vpl-keep", "vpl-block"}},
    {"Texels", {"max-texels", "supersample", "interleave"}},
    {"Clamp and its compensation", {"clamp", "clamp-k", "no-bias-compensation", "bias-compensation", "comp-rays",
                                    "comp-refine", "comp-ray-budget", "comp-filter"}},
    {"Final gather", {"final-gather", "gather-rays", "gather-pre-rays", "gather-ray-budget", "gather-filter"}},
    {"Sky, environment and punctual lights", {"sky-rays", "sky-ray-budget", "env-intensity", "env-rotation",
                                              "shadow-edge-samples", "light-mode"}},
    {"Irradiance probes", {"probe-box", "probe-budget", "probe-rays", "probe-light-fit", "probe-volume-fit", "probe-volume-rays",
                           "probe-volume-clearance", "probe-exact-emitters"}},
    {"Backends", {"backend", "cube-face", "spp"}},
    {"Outputs", {"no-gltf", "portable-exposure", "dump-config", "verbose"}},
    {"Distributed and resumable bakes", {"shard", "resume", "checkpoint-seconds"}},
    {"Estimated error", {"estimate-error", "max-time", "max-rounds", "error-map"}},
    {"Diagnostics", {"no-leak-control", "no-dilate", "no-seams", "gpu-timers"}},
};

void groupOptions(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string name = option->get_single_name();
    if (std::find(kCommonOptions.begin(), kCommonOptions.end(), name) != kCommonOptions.end()) {
      option->group("Options");
      continue;
    }
    for (const auto& [group, names] : kOptionGroups)
      if (std::find(names.begin(), names.end(), name) != names.end()) option->group(group);
  }
}

// The scene, the output, the backend, the walk and the texels.
void addWalkOptions(CLI::App* app, BakeCommand& command, BakeArguments& a) {
  BakeOptions& o = command.options;
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  app->add_option("SCENE", a.scenes, "the glTF/GLB scene to bake");
  app->add_option("-o,--output", command.out, "output folder (OUTDIR), or OUT.glb / OUT.gltf: that glTF, the rest beside it")->type_name("OUTDIR");
  app->add_option("--backend", a.backend,
                  "evaluator (default auto: GL on a GPU or for scenes ≤ " + shown(kGlTriangleHint / 1000) + "k triangles,\n"
                  "else embree; embree: ray-traced; reference: path traced)")
      ->check(CLI::IsMember({"auto", "gl", "embree", "reference"}));
  app->add_option("--paths,--vpls", a.paths,
                  "light paths of the quasi-random walk (default auto: by --quality;\n" + shown(q.pathsUnderGather) +
                      " under the final gather, which reads their map averaged; without it\n" + shown(q.paths / 2) +
                      " evaluated, from 8x as many walked, forked past bounce 1 and resampled;\n" +
                      "or " + shown(q.paths) + " with --walk-split N and no final gather)")
      ->transform(cli::integerOrAuto(1, 1 << 26, 0))->type_name("N|auto");
  app->add_option("--bounces", a.bounces, "diffuse bounces (default auto: follow the energy left)")
      ->transform(cli::integerOrAuto(0, 64, -1))->type_name("N|auto");
  app->add_option("--walk-split", a.walkSplit,
                  "paths fork into N where they leave bounce 1, each child carrying 1/N\n"
                  "(default auto: 1/(share of that light meeting the scene again), at most " +
                      shown(d.walk.maxAutoSplit) + ";\n"
                  "1 in closed scenes, but at least 4 where the final gather does not run;\n"
                  "1 = Keller's plain walk)")
      ->transform(cli::integerOrAuto(1, 64, 0))->type_name("N|auto");
  app->add_option("--vpl-importance", a.vplImportance,
                  "importance-driven VPLs: the walk places F times the VPLs and --vpl-keep of\n"
                  "the plain walk's count is kept, chosen by what they add to dim texels\n"
                  "(default auto: where the final gather runs and a pilot finds them uneven,\n"
                  "F up to " + shown(d.vplImportance.maxFactor) + " while probes × candidates ≤ " +
                      shown(d.vplImportance.pairBudget / 1e6) + "M; 1: the plain walk)")
      ->transform(cli::numberOrAuto(1.0, 64.0, 0.0))->type_name("F|auto");
  app->add_option("--vpl-probes", o.vplImportance.probes,
                  "importance-driven VPLs: texel samples the candidates are measured at (default " +
                      shown(d.vplImportance.probes) + ")")
      ->transform(cli::integerIn(16, 65536))->type_name("N");
  app->add_option("--vpl-keep", o.vplImportance.keepShare,
                  "importance-driven VPLs: VPLs kept, as a share of the plain walk's count (default " +
                      shown(d.vplImportance.keepShare) + ")")
      ->transform(cli::numberIn(0.05, 4.0))->type_name("S");
  app->add_option("--texels-per-unit", a.tpu, "texels per metre (default: about one " + shown(q.autoPageSize) + "² page, ≥ " +
                                                   shown(d.atlas.texelsPerTriangle) + " per triangle)")
      ->transform(cli::numberIn(0.0, 1e6))->type_name("T");
  app->add_option("--max-texels", o.atlas.maxTexels,
                  "texel budget of all pages together (default " + shown(d.atlas.maxTexels) + " = " +
                      shown(d.atlas.maxTexels >> 20) + "M);\n"
                  "a denser atlas fails at once, naming the density that fits;\n0 = no limit")
      ->transform(cli::integerIn(0, 1LL << 40))->type_name("N");
  app->add_option("--supersample", o.texels.supersample, "S×S samples per texel (default " + shown(d.texels.supersample) + ")")
      ->transform(cli::integerIn(1, 8))->type_name("S");
}

// The clamp and its compensation, the final gather, interleaving, the GL backend's cubes.
void addStageOptions(CLI::App* app, BakeCommand& command, BakeArguments& a) {
  BakeOptions& o = command.options;
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  a.clampOption =
      app->add_option("--clamp", a.clamp, "geometry-term bound (1/m²); 0 = no clamp\n(default: derived from the scene)")
          ->transform(cli::numberIn(0.0, 1e30))
          ->type_name("B");
  app->add_option("--clamp-k", o.clampVplsPerMean,
                  "derived clamp: no VPL adds more than 1/K of the mean\n"
                  "(default with bias compensation: " + shown(kCompensatedClampVplsPerMean) + ", or " +
                      shown(kCompensatedClampVplsPerMeanNoEmitters) + " in a scene\nwithout small emissive surfaces (under half the surface); " +
                      shown(kClampVplsPerMean) + " without; 0 = automatic)")
      ->transform(cli::numberIn(0.0, 1e6))->type_name("K");
  app->add_flag("--no-bias-compensation", a.noBiasCompensation,
               "keep the clamp's bias (default: recovered by a gather into\nthe map, after Kollig & Keller 2004)");
  app->add_flag("--bias-compensation", a.biasCompensation, "the default (kept for old scripts)");
  app->add_option("--comp-rays", o.compensation.rays,
                  "bias compensation: rays per texel sample, first round (default " + shown(q.compensationRays) + ")")
      ->transform(cli::integerIn(1, 4096))->type_name("N");
  app->add_option("--comp-refine", o.compensation.refineRays,
                  "bias compensation: extra rays where needed (default " + shown(q.compensationRefine) + ")")
      ->transform(cli::integerIn(0, 65536))->type_name("N");
  app->add_option("--comp-ray-budget", o.compensation.rayBudget,
                  "bias compensation: first-round rays over all samples (default " + shown(q.compensationBudget) +
                      ";\na large page gets fewer per sample, never below " + shown(d.compensation.minRays) + "; 0 = no cap)")
      ->transform(cli::integerIn(0, 1LL << 34))->type_name("N");
  app->add_option("--comp-filter", a.compFilter,
                  "bias compensation: the residual averaged over (2R+1)² texels on\n"
                  "the same surface (default auto: up to 4 where the rays per sample are\n"
                  "few and R texels stay within 1/20 of the clamp radius; 0 = none)")
      ->transform(cli::integerOrAuto(0, 8, -1))->type_name("R|auto");
  app->add_option("--final-gather", a.finalGather,
                  "bounced light gathered from the baked map one bounce away instead of\n"
                  "read from the VPLs that reach each texel (docs/units.md): on, off,\n"
                  "or auto (default: on in scenes without emissive or see-through surfaces)")
      ->check(CLI::IsMember({"off", "on", "auto"}))->type_name("off|on|auto");
  app->add_option("--gather-rays", o.gather.rays, "final gather: cosine rays per texel sample (default " + shown(q.gatherRays) + ")")
      ->transform(cli::integerIn(1, 4096))->type_name("N");
  app->add_option("--gather-pre-rays", o.gather.preRays,
                  "final gather: rays per sample of a first, cheaper gather whose map\nthe final rays read (default " +
                      shown(d.gather.preRays) + "; 0 = none)")
      ->transform(cli::integerIn(0, 4096))->type_name("N");
  app->add_option("--gather-ray-budget", o.gather.rayBudget,
                  "final gather: rays over all samples (default " + shown(q.gatherRayBudget) + "; a large\n"
                  "page gets fewer per sample, never below " + shown(d.gather.minRays) + "; 0 = no cap)")
      ->transform(cli::integerIn(0, 1LL << 34))->type_name("N");
  app->add_option("--gather-filter", o.gather.filterRadius,
                  "final gather: the gathered light averaged over (2R+1)² texels on\nthe same surface (default " +
                      shown(d.gather.filterRadius) + "; 0 = none)")
      ->transform(cli::integerIn(0, 8))->type_name("R");
  app->add_option("--interleave", a.interleave,
                  "interleaved sampling: each texel of an N×N block sees 1/N²\n"
                  "of the VPLs, then a filter on the surface mixes them\n"
                  "(default auto: 1.." + shown(kMaxAutoInterleave) + " from the texel size and the clamp radius;\n"
                  "1 = every VPL everywhere)")
      ->transform(cli::integerOrAuto(1, 8, 0))->type_name("N|auto");
  app->add_option("--cube-face", a.cubeFace,
                  "GL backend: VPL depth-cube face size in texels\n"
                  "(default auto: a shadow texel's footprint held to the\nlight-map texel spacing, " +
                      shown(d.gl.minCubeFaceSize) + ".." + shown(d.gl.maxCubeFaceSize) + ")")
      ->transform(cli::integerOrAuto(16, 2048, 0))->type_name("N|auto");
}

// The seed, light from the command line, and what is written.
void addLightAndOutputOptions(CLI::App* app, BakeCommand& command, BakeArguments& a) {
  BakeOptions& o = command.options;
  const BakeOptions d;
  const BakeCommand dc;
  const QualityPreset& q = defaultQualityPreset();
  app->add_option("--seed", a.seed, "walk seed (default 0)")->transform(cli::integerIn(0, 1 << 30))->type_name("K");
  app->add_option("--spp", o.referenceSpp, "reference backend: paths per texel sample (default " + shown(d.referenceSpp) + ")")
      ->transform(cli::integerIn(1, 1 << 20))->type_name("N");
  app->add_option("--sun", a.sun, "add a directional light travelling along D with irradiance E (W/m²)")
      ->transform(cli::numberList(4))->type_name("DX,DY,DZ,E");
  app->add_option("--sky", a.sky, "a uniform sky of that radiance (W/(m² sr))")
      ->transform(cli::numberList(3))->type_name("R,G,B");
  app->add_option("--sky-rays", o.sky.raysPerSample, "sky and environment: rays per texel sample (default " + shown(q.skyRays) + ")")
      ->transform(cli::integerIn(8, 4096))->type_name("N");
  app->add_option("--sky-ray-budget", o.sky.maxRays,
                  "sky and environment: rays over all samples (default " + shown(q.skyRayBudget) + "; a large\n"
                  "page gets fewer per sample, never below " + shown(d.sky.minRays) + ", or 4 where the final\n"
                  "gather counts a uniform sky itself)")
      ->transform(cli::integerIn(1, 1 << 30))->type_name("N");
  app->add_option("--light-mode", a.lightModes,
                  "a punctual light's bake mode: baked (default), indirect (its bounces\n"
                  "only) or shadowmask (indirect plus its visibility in a mask page);\n"
                  "NAME: the glTF light's name, sun (--sun), #I (KHR light I) or *\n"
                  "(every punctual light); name:TEXT, index:I and option:sun never\n"
                  "mean another light; repeatable, beats extras.irbake.mode")
      ->type_name("NAME=MODE")
      ->allow_extra_args(false);  // one NAME=MODE per --light-mode: never the SCENE after it
  app->add_option("--shadow-edge-samples", o.shadowEdges.subSamples,
                  "punctual lights: S×S shadow rays over each texel a shadow edge\ncrosses (default " +
                      shown(q.shadowEdgeSamples) + "; 0 or 1: the centre alone)")
      ->transform(cli::integerIn(0, 16))->type_name("S");
  app->add_option("--env", a.env, "an equirectangular environment (.exr/.hdr, +Y up) instead of --sky")
      ->type_name("FILE");
  app->add_option("--env-intensity", a.envIntensity, "scales --env (default " + shown(LightAdditions{}.environmentIntensity) + ")")->transform(cli::numberIn(0.0, kLargestLight))->type_name("S");
  app->add_option("--env-rotation", a.envRotation, "turns --env about +Y (degrees, default " + shown(LightAdditions{}.environmentRotation) + ")")
      ->transform(cli::numberIn(-36000.0, 36000.0))->type_name("DEG");
  app->add_option("--report", command.report, "report path (default OUTDIR/report.json)")->type_name("R.json");
  app->add_option("--probes", a.probes,
                  "irradiance probes for moving objects (IRBAKE_light_probes): auto (default: about\n"
                  "1024 probes over the scene, 2048 with a sun), off, or a spacing in metres")
      ->type_name("auto|off|M");
  app->add_option("--probe-box", a.probeBox, "the probes fill this box instead of the scene's bounds")
      ->transform(cli::numberList(6))->type_name("X0,Y0,Z0,X1,Y1,Z1");
  app->add_option("--probe-budget", o.probes.budget,
                  "at most N probes, or the bake is refused before any work (default " + shown(ProbeOptions{}.budget) +
                      ",\n8x the automatic grid with a sun; up to " + shown(ProbeOptions{}.maxProbes) + ")")
      ->transform(cli::integerIn(1, static_cast<int>(ProbeOptions{}.maxProbes)))->type_name("N");
  app->add_option("--probe-rays", o.probes.rays, "rays per probe (default " + std::to_string(ProbeOptions{}.rays) + ")")
      ->transform(cli::integerIn(16, 1 << 16))->type_name("N");
  app->add_option("--probe-light-fit", o.probes.lightFitSamples,
                  "the punctual lights' visibility at the probes fitted over S×S×S points per probe\n"
                  "(default " + std::to_string(ProbeOptions{}.lightFitSamples) + "; 0: each probe's own shadow ray)")
      ->transform(cli::integerIn(0, 8))->type_name("S");
  app->add_option("--probe-volume-fit", o.probes.volumeFitSamples,
                  "the rest of the probes' light fitted over S×S×S points per probe, " +
                      std::to_string(ProbeOptions{}.volumeFitRays) + " rays each\n(default " +
                      std::to_string(ProbeOptions{}.volumeFitSamples) + "; 0: each probe's own rays)")
      ->transform(cli::integerIn(0, 8))->type_name("S");
  app->add_option("--probe-volume-rays", o.probes.volumeFitRays,
                  "lattice rays per point of the volume fit (default " + std::to_string(ProbeOptions{}.volumeFitRays) + ")")
      ->transform(cli::integerIn(16, 1 << 16))->type_name("N");
  app->add_option("--probe-volume-clearance", o.probes.volumeFitClearance,
                  "the volume fit's points at least this many spacings from every surface (default " +
                      shown(ProbeOptions{}.volumeFitClearance) + ";\n0: every point the probes see)")
      ->transform(cli::numberIn(0.0, 8.0))->type_name("C");
  app->add_option("--probe-exact-emitters", o.probes.exactEmitterTriangles,
                  "uniform planar or small emitters of at most N triangles in all (brightest first) left out of the\n"
                  "probes' SH for the clients' exact shading (default " + std::to_string(ProbeOptions{}.exactEmitterTriangles) +
                      "; 0: every emitter in the SH)")
      ->transform(cli::integerIn(0, kMaxExactEmitterTriangles))->type_name("N");
  app->add_flag("--directional", o.directional,
                "also bake directional (L1) maps (docs/export.md)");
  app->add_flag("--no-gltf", command.noGltf, "write only the EXR pages and the report");
  app->add_option("--portable", command.portable,
                  "also write FILE.glb for viewers without MOZ_lightmap: base colour × light\n"
                  "map + emission baked into unlit textures (KHR_materials_unlit; docs/export.md)")
      ->type_name("FILE.glb");
  app->add_option("--portable-exposure", command.portableExposure,
                  "--portable: scale on the shown values before the 8-bit sRGB encode\n"
                  "(default " + shown(dc.portableExposure) + ": the map as it is; values above 1 clip)")
      ->transform(cli::numberIn(1e-6, 1e6))->type_name("X");
}

// Diagnostics, threads and logging, distributed and resumable bakes, presets and config files.
void addRunOptions(CLI::App* app, BakeCommand& command, BakeArguments& a) {
  BakeOptions& o = command.options;
  const BakeOptions d;
  const BakeCommand dc;
  app->add_flag("--no-leak-control", a.noLeakControl, "diagnostics: texel samples may sit behind walls");
  app->add_flag("--no-dilate", a.noDilate, "diagnostics: no dilation into the padding");
  app->add_flag("--no-seams", a.noSeams, "diagnostics: no seam stitching");
  app->add_flag("--gpu-timers", o.gl.gpuTimers,
                "diagnostics: the GL passes' GPU time in the report (timings.gl.gpu*Seconds;\n"
                "timer queries, which some drivers serialise)");
  app->add_option("--threads", command.threads, "worker threads (default 0: every core; same bytes for any count)")
      ->transform(cli::integerIn(0, 1024))->type_name("N");
  app->add_flag("--quiet", command.quiet, "warnings and errors only, no progress bars");
  app->add_flag("--verbose", command.verbose, "also the stages' debug lines (e.g. the compensation's sweeps)");
  a.shardOption = app->add_option("--shard", a.shard,
                  "evaluate share K of N of the VPL blocks and write the exact partial\n"
                  "sums to OUTDIR/partial_K_of_N.vplsum for 'irbake merge' (docs/distributed.md)")
      ->type_name("K/N");
  app->add_flag("--resume", command.resume,
                "continue from OUTDIR's checkpoint (left by a bake that was killed);\n"
                "the outputs are byte-identical to an uninterrupted bake");
  app->add_option("--checkpoint-seconds", command.checkpointSeconds,
                  "at most this long between checkpoints of the VPL sums (default " + shown(dc.checkpointSeconds) +
                      ";\n0: after every VPL block)")
      ->transform(cli::numberIn(0.0, 1e9))->type_name("S");
  app->add_option("--vpl-block", o.vplBlock,
                  "VPLs per block of the exact VPL sum, the unit of shards and\ncheckpoints (default " + shown(d.vplBlock) + ")")
      ->transform(cli::integerIn(1, 1 << 20))->type_name("N");
  app->add_option("--quality", a.quality,
                  "paths and rays together (default: default; docs/validation.md)")
      ->check(CLI::IsMember({"preview", "default", "high", "production"}))->type_name("Q");
  app->add_option("--config", a.config, "options from a TOML file (key = value); the command line wins")
      ->type_name("FILE");
  app->add_option("--dump-config", a.dumpConfig, "write every option of this bake as such a file")->type_name("FILE");
  app->add_flag("--help-all", a.helpAll, "every option, grouped by stage");
}

// The bake's own error (stages/error_estimate) and the target that adds rounds until it is met.
void addErrorOptions(CLI::App* app, BakeCommand& command) {
  ErrorEstimateOptions& e = command.options.errorEstimate;
  const ErrorEstimateOptions d;
  app->add_flag("--estimate-error", e.enabled,
                "walk the paths as two independent halves (seeds of their own) and\n"
                "report the bake's estimated error (report.json estimatedError:\n"
                "relative RMS on 4x4-texel bins, as bench/cycles/compare.py scores)");
  app->add_option("--target-error", e.targetError,
                  "add paths or stage rays until the estimated error is at most E (e.g. 0.02)")
      ->transform(cli::numberIn(1e-6, 1.0))->type_name("E");
  app->add_option("--max-rounds", e.maxRounds,
                  "--target-error: at most this many rounds, of paths or of rays\n(default " + shown(d.maxRounds) + ")")
      ->transform(cli::integerIn(1, 4096))->type_name("N");
  app->add_option("--max-time", e.maxSeconds,
                  "--target-error: no round started that would end past this many\n"
                  "seconds of bake (default 0: no cap; the result then depends on the\nmachine)")
      ->transform(cli::numberIn(0.0, 1e9))->type_name("SECONDS");
  app->add_flag("--error-map", e.errorMap,
                "with the estimate: also each texel's standard error, OUTDIR/error_<page>.exr");
}

// Every option of `irbake bake`, with its range and help.
std::unique_ptr<CLI::App> bakeApp(BakeCommand& command, BakeArguments& a) {
  auto app = cli::makeApp("irbake bake",
                          "Bakes light maps (EXR, irradiance/pi, linear) and exports glTF with MOZ_lightmap.\n"
                          "Writes OUTDIR/lightmap_<page>.exr, OUTDIR/scene.gltf and the report.");
  addWalkOptions(app.get(), command, a);
  addStageOptions(app.get(), command, a);
  addLightAndOutputOptions(app.get(), command, a);
  addRunOptions(app.get(), command, a);
  addErrorOptions(app.get(), command);
  groupOptions(*app);
  return app;
}

// Options that only say where and how fast to write: not part of the result.
const std::vector<std::string> kNotResult = {"SCENE", "output", "report", "threads", "quiet", "verbose", "no-gltf",
                                             "portable", "portable-exposure", "shard", "resume", "checkpoint-seconds",
                                             "help", "help-all", "config", "dump-config"};
// Options whose presence changes the result even at the default value (--clamp 0: no clamp; none: derived).
const std::vector<std::string> kPresenceMatters = {"clamp"};

bool sameValue(const std::string& a, const std::string& b) {
  if (a == b) return true;
  char* endA = nullptr;
  char* endB = nullptr;
  const double x = std::strtod(a.c_str(), &endA), y = std::strtod(b.c_str(), &endB);
  return !a.empty() && !b.empty() && *endA == 0 && *endB == 0 && x == y;
}

// The options that change the result, as name -> value: what CLI11 parsed (the validators write numbers
// canonically), less any option given at its default, so "--seed 0" or "--vpls auto" is the bake without
// it. Partials and checkpoints carry it and its hash; a refused resume names the options that differ.
nlohmann::json resultOptions(const CLI::App& app) {
  BakeCommand freshCommand;
  BakeArguments freshArguments;
  const std::unique_ptr<CLI::App> defaults = bakeApp(freshCommand, freshArguments);
  nlohmann::json options = nlohmann::json::object();
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = option->get_single_name();
    if (option->count() == 0 || std::find(kNotResult.begin(), kNotResult.end(), name) != kNotResult.end()) continue;
    std::string value;
    if (option->get_expected_min() == 0) {
      value = "true";  // a flag
    } else {
      for (const std::string& r : option->results()) value += (value.empty() ? "" : ",") + r;
    }
    const CLI::Option* plain = defaults->get_option_no_throw(option->get_name());
    const std::string fallback = plain ? const_cast<CLI::Option*>(plain)->capture_default_str()->get_default_str() : "";
    const bool presence = std::find(kPresenceMatters.begin(), kPresenceMatters.end(), name) != kPresenceMatters.end();
    if (!presence && option->get_expected_min() != 0 && sameValue(value, fallback)) continue;
    options[name] = value;
  }
  return options;
}

// The checks of single option values that CLI11 cannot make (--shard, --clamp, --sun, --sky, --probes,
// --probe-box, --light-mode), their results into the command. Throws Error(Usage) naming the option; a config
// file's entry is checked with them on its own, so that its refusal names the file, the line and the key.
void checkOptionValues(BakeCommand& command, const BakeArguments& a) {
  BakeOptions& o = command.options;
  if (a.shardOption->count() > 0) {
    long long k = 0, n = 0;
    const size_t slash = a.shard.find('/');
    const bool parsed = slash != std::string::npos && cli::parseWholeNumber(a.shard.substr(0, slash), k) &&
                        cli::parseWholeNumber(a.shard.substr(slash + 1), n);
    if (!parsed || n < 1 || n > 1000000 || k < 1 || k > n)
      throw Error(ErrorCode::Usage, "", "--shard needs K/N with 1 ≤ K ≤ N ≤ 1000000 (got '" + a.shard + "')");
    command.shardIndex = static_cast<int>(k);
    command.shardCount = static_cast<int>(n);
  }
  if (a.clampOption->count() > 0 && a.clamp > 0.0 && a.clamp < kSmallestClamp)
    throw Error(ErrorCode::Usage, "", "--clamp needs 0 (no clamp) or a bound in [1e-30, 1e30] 1/m² (got " + a.clampText() + ")");
  command.lights = lightArguments(a);
  probeArguments(a, o.probes);
  for (const std::string& entry : a.lightModes) {
    const size_t eq = entry.rfind('=');
    LightModeRequest request;
    if (eq == std::string::npos || eq == 0 || !parseLightMode(entry.substr(eq + 1), request.mode))
      throw Error(ErrorCode::Usage, "", "--light-mode needs NAME=MODE with MODE baked, indirect or shadowmask (got " +
                                            quotedExcerpt(entry) + ")");
    request.light = entry.substr(0, eq);
    request.origin = a.lightModeOrigin;
    o.lightModes.push_back(request);
  }
}

// The parsed arguments as options; throws Error(Usage) for values and combinations CLI11 cannot check.
void applyArguments(BakeCommand& command, const BakeArguments& a) {
  BakeOptions& o = command.options;
  checkOptionValues(command, a);
  if (command.noGltf) o.probes.enabled = false;  // the probes live in the glTF: none to write them to
  if (a.scenes.size() != 1)
    throw Error(ErrorCode::Usage, "", "bake needs exactly one SCENE (got " + std::to_string(a.scenes.size()) +
                                          "); see 'irbake bake --help'");
  if (command.out.empty()) throw Error(ErrorCode::Usage, "", "bake needs -o OUTDIR");
  command.scene = a.scenes[0];
  o.backend = parseBackend(a.backend);
  o.finalGather = a.finalGather == "on"     ? FinalGatherMode::On
                  : a.finalGather == "auto" ? FinalGatherMode::Auto
                                            : FinalGatherMode::Off;
  o.walk.seed = static_cast<uint32_t>(a.seed);
  o.atlas.texelsPerUnit = a.tpu;
  o.texels.leakControl = !a.noLeakControl;
  if (a.bounces >= 0) o.walk.maxBounces = a.bounces;
  if (a.walkSplit > 0) o.walk.split = a.walkSplit;
  if (a.vplImportance >= 1.0) o.vplImportance.candidateFactor = a.vplImportance;
  else o.vplImportance.candidateFactor.reset();  // auto
  if (a.interleave > 0) o.interleave = a.interleave;
  if (a.compFilter >= 0) o.compensation.filterRadius = a.compFilter;
  if (a.cubeFace > 0) o.gl.cubeFaceSize = a.cubeFace;
  // Where the final gather runs, the preset's pathsUnderGather (app/quality.cpp).
  const QualityPreset& preset = *findQualityPreset(a.quality);
  o.walk.paths = a.paths > 0 ? a.paths : preset.paths;
  if (a.paths == 0) o.finalGatherPaths = preset.pathsUnderGather;
  if (a.clampOption->count() > 0) {  // --clamp 0: no clamp; none given: derived
    o.clamp = a.clamp > 0.0 ? ClampMode::Fixed : ClampMode::Off;
    o.clampBound = static_cast<float>(a.clamp);
  }
  o.eval.biasCompensation = !a.noBiasCompensation;  // on by default; --bias-compensation kept
  o.postDilate = !a.noDilate;
  o.postSeams = !a.noSeams;
  if (command.shardIndex > 0 && !command.portable.empty())
    throw Error(ErrorCode::Usage, "", "--shard writes only a partial: give --portable to 'irbake merge'");
  if (command.shardIndex > 0 && namesGltfFile(command.out))
    throw Error(ErrorCode::Usage, "", "--shard writes a partial into a folder: give -o OUTDIR, not a glTF name");
  if (o.directional && o.backend == BackendKind::Reference)
    throw Error(ErrorCode::Usage, "", "--directional needs a VPL backend (gl, embree or auto), not reference");
  if (command.shardIndex > 0 && o.backend == BackendKind::Reference)
    throw Error(ErrorCode::Usage, "", "--shard splits the VPLs: the reference backend has none (use gl, embree or auto)");
  if (o.errorEstimate.targetError > 0.0 || o.errorEstimate.errorMap) o.errorEstimate.enabled = true;
  if (o.errorEstimate.enabled && (command.shardIndex > 0 || command.resume))
    throw Error(ErrorCode::Usage, "", "--estimate-error and --target-error need the whole bake in one process "
                                      "(the halves' sums are not in partials or checkpoints): drop --shard / --resume");
}

}  // namespace

namespace {

// "--name value" or "--name=value" in args: the value ("" when absent).
std::string argumentValue(const Args& args, const std::string& name) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == name && i + 1 < args.size()) return args[i + 1];
    if (args[i].rfind(name + "=", 0) == 0) return args[i].substr(name.size() + 1);
  }
  return {};
}

// The knobs a --quality preset sets, where their own option is not given.
void applyQuality(const CLI::App& app, const BakeArguments& a, BakeOptions& o) {
  const QualityPreset& p = *findQualityPreset(a.quality);
  auto unset = [&](const char* name) { return app.get_option(name)->count() == 0; };
  if (unset("--gather-rays")) o.gather.rays = p.gatherRays;
  if (unset("--gather-ray-budget")) o.gather.rayBudget = p.gatherRayBudget;
  if (unset("--comp-rays")) o.compensation.rays = p.compensationRays;
  if (unset("--comp-refine")) o.compensation.refineRays = p.compensationRefine;
  if (unset("--comp-ray-budget")) o.compensation.rayBudget = p.compensationBudget;
  if (unset("--sky-rays")) o.sky.raysPerSample = p.skyRays;
  if (unset("--sky-ray-budget")) o.sky.maxRays = p.skyRayBudget;
  if (unset("--shadow-edge-samples")) o.shadowEdges.subSamples = p.shadowEdgeSamples;
  o.atlas.targetPageSize = p.autoPageSize;  // read only where --texels-per-unit is auto
}

// Options a config file may give as an array of strings, one --name=item per item.
const std::vector<std::string> kRepeatableOptions = {"light-mode"};

// A message about a config value, the value in it shown as a short escaped excerpt.
std::string withExcerpt(std::string message, const std::string& value) {
  const std::string shown = quotedExcerpt(value);
  if (!value.empty() && shown != "'" + value + "'")
    for (size_t at = message.find(value); at != std::string::npos; at = message.find(value, at)) {
      size_t begin = at, end = at + value.size();
      if (begin > 0 && message[begin - 1] == '\'' && end < message.size() && message[end] == '\'') --begin, ++end;
      message.replace(begin, end - begin, shown);
      at = begin + shown.size();
    }
  return printableExcerpt(message, 400);
}

// Arguments for a config file's entries, each checked alone against the options and irbake's own checks of
// their values (unknown keys, wrong types, out-of-range and refused values name the file, the line and the
// key); entries the command line also sets are left out (the command line wins). lightModeOrigin: where the
// file's light-mode entry is, when it is used.
Args configArguments(const std::filesystem::path& file, const Args& commandLine, std::string& lightModeOrigin) {
  const std::vector<ConfigEntry> entries = readConfigFile(file);
  BakeCommand probeCommand;
  BakeArguments probeArguments;
  std::unique_ptr<CLI::App> given = bakeApp(probeCommand, probeArguments);
  cli::parse(*given, commandLine);
  const std::filesystem::path folder = file.parent_path();
  Args out;
  for (const ConfigEntry& e : entries) {
    const std::string line = "line " + std::to_string(e.line) + ": key " + quotedExcerpt(e.key);
    auto fail = [&](const std::string& what) { throw Error(ErrorCode::Usage, file.string(), line + ": " + what); };
    const bool positional = e.key == "scene";
    const std::string name = positional ? "SCENE" : "--" + e.key;
    const CLI::Option* option = given->get_option_no_throw(name);
    if (!option || e.key == "config" || e.key == "help" || e.key == "help-all")
      fail("not an option of 'irbake bake' (see 'irbake bake --help-all')");
    if (option->count() > 0) continue;
    const bool repeatable = std::find(kRepeatableOptions.begin(), kRepeatableOptions.end(), e.key) != kRepeatableOptions.end();
    if (e.array && !repeatable) fail("takes one value, not an array (only light-mode is repeated)");
    Args words;
    for (std::string value : e.array ? e.items : std::vector<std::string>{e.value}) {
      if (positional || e.key == "output" || e.key == "report" || e.key == "env" || e.key == "dump-config" ||
          e.key == "portable")
        if (!value.empty() && std::filesystem::path(value).is_relative()) value = (folder / value).lexically_normal().string();
      if (option->get_expected_min() == 0) {  // a flag
        if (value != "true" && value != "false") fail("a flag takes true or false, got " + quotedExcerpt(value));
        if (value == "true") words.push_back(name);
      } else {
        words.push_back(positional ? value : name + "=" + value);  // one word: a value may start with '-'
      }
    }
    BakeCommand checkCommand;
    BakeArguments checkArguments;
    std::unique_ptr<CLI::App> check = bakeApp(checkCommand, checkArguments);
    try {
      cli::parse(*check, words);
      checkOptionValues(checkCommand, checkArguments);
    } catch (const Error& error) {
      std::string message = error.what();
      for (const std::string& value : e.array ? e.items : std::vector<std::string>{e.value}) message = withExcerpt(message, value);
      fail(message);
    }
    if (e.key == "light-mode") lightModeOrigin = file.string() + ": " + line;
    out.insert(out.end(), words.begin(), words.end());
  }
  return out;
}

// Every option of the parsed bake as config entries: the given ones as entries (paths absolute), the rest
// as comments with the value the bake uses ("auto" where it decides, the --quality preset's knobs), so the
// file reads back to the same bake and still shows every knob.
std::vector<ConfigEntry> effectiveOptions(const CLI::App& app, const BakeArguments& a, const BakeOptions& o) {
  BakeCommand freshCommand;
  BakeArguments freshArguments;
  const std::unique_ptr<CLI::App> defaults = bakeApp(freshCommand, freshArguments);
  const QualityPreset& preset = *findQualityPreset(a.quality);
  const std::vector<std::pair<std::string, std::string>> fromPreset = {
      {"gather-rays", std::to_string(o.gather.rays)},          {"gather-ray-budget", std::to_string(o.gather.rayBudget)},
      {"comp-rays", std::to_string(o.compensation.rays)},     {"comp-refine", std::to_string(o.compensation.refineRays)},
      {"comp-ray-budget", std::to_string(o.compensation.rayBudget)}, {"sky-rays", std::to_string(o.sky.raysPerSample)},
      {"sky-ray-budget", std::to_string(o.sky.maxRays)},     {"shadow-edge-samples", std::to_string(o.shadowEdges.subSamples)}};
  std::vector<ConfigEntry> entries;
  for (const CLI::Option* option : app.get_options()) {
    std::string name = option->get_single_name();
    if (name == "help" || name == "help-all" || name == "config" || name == "dump-config") continue;
    const bool flag = option->get_expected_min() == 0;
    std::string value;
    if (option->count() > 0) {
      if (std::find(kRepeatableOptions.begin(), kRepeatableOptions.end(), name) != kRepeatableOptions.end()) {
        ConfigEntry repeated{name, "", 0, true, option->results()};  // one item per time it was given
        entries.push_back(repeated);
        continue;
      }
      if (flag) value = "true";
      else
        for (const std::string& r : option->results()) value += (value.empty() ? "" : ",") + r;
      if (name == "SCENE" || name == "output" || name == "report" || name == "env" || name == "portable")
        value = std::filesystem::absolute(value).lexically_normal().string();
      entries.push_back({name == "SCENE" ? "scene" : name, value, 0, false, {}});
      continue;
    }
    CLI::Option* plain = defaults->get_option_no_throw(option->get_name());
    value = plain ? plain->capture_default_str()->get_default_str() : "";
    if (flag) value = "false";
    if (option->get_type_name().find("auto") != std::string::npos) value = "auto";
    if (name == "paths") value = "auto (" + std::to_string(preset.paths) + ", or " + std::to_string(preset.pathsUnderGather) +
                                 " under the final gather, or " + std::to_string(preset.paths / 2) +
                                 " evaluated of 8x as many walked without it)";
    if (name == "clamp") value = "derived from the scene (0: no clamp)";
    for (const auto& [knob, v] : fromPreset)
      if (knob == name) value = v + " (--quality " + preset.name + ")";
    if (value.empty()) value = "none";
    entries.push_back({"# " + name, value, 0, false, {}});
  }
  return entries;
}

}  // namespace

PendingFile dumpedConfigFile(const std::string& file, const std::string& text) {
  return {file, [file, text](const std::filesystem::path& temp) {
            std::ofstream out(temp, std::ios::binary);
            out << text;
            out.close();
            if (!out) throw Error(ErrorCode::Io, file, "cannot write the config");
          }};
}

std::string automaticChoices(const nlohmann::json& report) {
  // Options whose chosen value, given explicitly, makes the same bake; the other automatic choices (the walk's
  // depth and split, the compensation's per-page filter) follow the scene and stay auto, with what they chose.
  static const std::vector<std::string> kReplayable = {"backend",    "final-gather",   "paths",          "interleave",
                                                       "cube-face",  "clamp-k",        "vpl-importance", "texels-per-unit"};
  std::vector<ConfigEntry> entries, comments;
  const nlohmann::json plan = report.value("plan", nlohmann::json::object());
  for (auto it = plan.begin(); it != plan.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& choice = it.value();
    if (!choice.value("automatic", false)) continue;
    const nlohmann::json& v = choice["value"];
    const std::string value = v.is_string() ? v.get<std::string>() : v.is_number_float() ? cli::canonicalNumber(v.get<double>()) : v.dump();
    if (std::find(kReplayable.begin(), kReplayable.end(), key) != kReplayable.end())
      entries.push_back({key, value, 0, false, {}});
    else
      comments.push_back({"# " + key, "auto (chose " + value + ": " + choice.value("reason", "") + ")", 0, false, {}});
  }
  std::string text = "# what this bake chose where its options said auto (the same scene and options choose the same):\n";
  const std::string body = configText(entries, "") + configText(comments, "");
  std::istringstream lines(body);
  for (std::string line; std::getline(lines, line);)
    if (line != "# " && line != "[bake]") text += line + "\n";
  return text;
}

std::optional<BakeCommand> parseBakeCommand(const Args& givenArgs) {
  Args args = givenArgs;
  // --help shows the common options; --help-all every one, grouped by stage.
  const bool helpAll = std::find(args.begin(), args.end(), "--help-all") != args.end();
  const bool help = helpAll || std::find(args.begin(), args.end(), "--help") != args.end() ||
                    std::find(args.begin(), args.end(), "-h") != args.end();
  const std::string config = argumentValue(args, "--config");
  std::string lightModeOrigin;
  if (!config.empty() && !help) {
    Args fromFile = configArguments(config, args, lightModeOrigin);
    fromFile.insert(fromFile.end(), args.begin(), args.end());
    args = fromFile;
  }
  BakeCommand command;
  BakeArguments arguments;
  const std::unique_ptr<CLI::App> app = bakeApp(command, arguments);
  if (help) {
    if (!helpAll)
      for (CLI::Option* option : app->get_options())
        if (option->get_group() != "Options") option->group("");
    std::fputs(app->help().c_str(), stdout);
    if (!helpAll) std::fputs("every option, grouped by stage: irbake bake --help-all\n", stdout);
    return std::nullopt;
  }
  if (!cli::parse(*app, args)) return std::nullopt;
  command.resultOptions = resultOptions(*app);
  command.optionsHash = hashText(command.resultOptions.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  // What a merge or resume re-parses: the config's entries are in `args` already, so the file is not needed.
  for (size_t i = 0; i < args.size(); ++i) {
    if ((args[i] == "--config" || args[i] == "--dump-config") && i + 1 < args.size()) {
      ++i;
      continue;
    }
    if (args[i].rfind("--config=", 0) == 0 || args[i].rfind("--dump-config=", 0) == 0) continue;
    command.arguments.push_back(args[i]);
  }
  arguments.lightModeOrigin = lightModeOrigin;
  applyArguments(command, arguments);
  applyQuality(*app, arguments, command.options);
  if (!arguments.dumpConfig.empty()) {
    command.dumpConfig = arguments.dumpConfig;
    command.dumpText = configText(effectiveOptions(*app, arguments, command.options),
                                  "irbake bake options (read back with --config FILE)");
  }
  return command;
}

Scene loadBakeScene(const BakeCommand& command) {
  const std::filesystem::path scenePath = command.scene;
  Scene scene = loadScene(scenePath);
  addLights(scene, command.lights);
  requireLight(scene, scenePath);
  return scene;
}

namespace {

namespace fs = std::filesystem;

// The checkpoint of a bake under way (removed when it finishes) and a shard's share, inside OUTDIR.
constexpr const char* kCheckpointName = ".irbake.checkpoint";
std::string partialName(int k, int n) {
  return "partial_" + std::to_string(k) + "_of_" + std::to_string(n) + ".vplsum";
}

// The scene's identity: its files, and the environment map's when --env names one.
std::string sceneIdentity(const BakeCommand& c) {
  std::string hash = hashSceneFiles(c.scene);
  if (!c.lights.environment.empty()) hash = hashText(hash + hashSceneFiles(c.lights.environment));
  return hash;
}

// The checkpoint goes when the bake is done: when the folder's manifest proves irbake wrote it, or when it
// is an irbake VPL sum file whose checksum holds (a copied shard's partial resumed from); else it stays.
void removeCheckpoint(const fs::path& checkpoint, const OutputGuard& guard) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(checkpoint, ec)) || guard.removeIfOurs(checkpoint)) return;
  try {
    if (!fs::is_regular_file(fs::symlink_status(checkpoint, ec))) throw Error(ErrorCode::Io, "", "not a file");
    readVplSumFile(checkpoint);
  } catch (const Error&) {
    log::warn("left " + checkpoint.string() + " as it is: irbake did not write it");
    return;
  }
  fs::remove(checkpoint, ec);
}

}  // namespace

std::string bakeSceneIdentity(const BakeCommand& c) { return sceneIdentity(c); }

namespace {

// lightmap_<page>.exr/.png and the directional lightmap_<page>_l1x|y|z.exr: names a bake writes.
bool isPageName(const std::string& name) {
  const std::string prefix = "lightmap_";
  if (name.rfind(prefix, 0) != 0) return false;
  size_t at = prefix.size(), digits = 0;
  while (at < name.size() && std::isdigit(static_cast<unsigned char>(name[at]))) ++at, ++digits;
  if (digits == 0) return false;
  const std::string rest = name.substr(at);
  return rest == ".exr" || rest == ".png" || rest == "_l1x.exr" || rest == "_l1y.exr" || rest == "_l1z.exr" ||
         rest == "_l1x.png" || rest == "_l1y.png" || rest == "_l1z.png" || rest == "_shadowmask.exr" ||
         rest == "_shadowmask.png";
}

// error_<page>.exr (--error-map) is a page too.
bool isPageOrErrorName(const std::string& name) {
  if (isPageName(name)) return true;
  const std::string prefix = "error_";
  if (name.rfind(prefix, 0) != 0 || name.size() <= prefix.size() + 4) return false;
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 4);
  return name.substr(name.size() - 4) == ".exr" &&
         digits.find_first_not_of("0123456789") == std::string::npos;
}

// The files a bake keeps in OUTDIR while it runs: its lock, its checkpoint and a shard's partial.
bool isBakeStateName(const std::string& name) {
  return name == OutputFolderLock::kFileName || name == ".irbake.checkpoint" ||
         (name.rfind("partial_", 0) == 0 && name.size() > 15 && name.substr(name.size() - 7) == ".vplsum");
}

}  // namespace

std::shared_ptr<OutputGuard> bakeOutputGuard(BakeCommand& c, const std::vector<fs::path>& moreInputs) {
  auto guard = std::make_shared<OutputGuard>();
  const fs::path outDir = outputFolderOf(c.out);
  const bool gltfNamed = namesGltfFile(c.out);
  const fs::path gltf = gltfNamed ? fs::path(c.out) : outDir / "scene.gltf";
  if (!c.portable.empty() && !hasExtension(c.portable, ".glb"))
    throw Error(ErrorCode::Usage, c.portable, "--portable writes one GLB: give a .glb file name");
  // Inputs first: the scene and its files, --env's map, and what the command reads besides (merge's partials).
  std::vector<fs::path> inputs = sceneInputFiles(c.scene);
  if (!c.lights.environment.empty()) inputs.push_back(c.lights.environment);
  inputs.insert(inputs.end(), moreInputs.begin(), moreInputs.end());
  guard->addInputs(inputs);
  // The names the bake picks in OUTDIR (pages, its lock, checkpoint and partials), then each named output.
  guard->keepManifest(outDir);
  guard->addOutputNames(outDir, isPageOrErrorName, "a light-map page of this bake");
  guard->addOutputNames(outDir, isBakeStateName, "the bake's own state (lock, checkpoint, partials)");
  if (!c.noGltf) {
    guard->addOutput(gltf, "the glTF output");
    if (!hasExtension(gltf, ".glb")) guard->addOutput(outDir / (gltf.stem().string() + ".bin"), "the glTF's .bin output");
  }
  guard->addOutput(c.report.empty() ? outDir / "report.json" : fs::path(c.report), c.report.empty() ? "the report" : "--report");
  if (!c.portable.empty()) guard->addOutput(c.portable, "--portable");
  if (!c.dumpConfig.empty()) guard->addOutput(c.dumpConfig, "--dump-config");
  c.inputs = inputs;
  return guard;
}

std::unique_ptr<OutputFolderLock> lockReportFolder(const BakeCommand& c) {
  if (c.report.empty()) return nullptr;
  const fs::path folder = folderOf(c.report);
  if (sameFile(folder, outputFolderOf(c.out))) return nullptr;
  return std::make_unique<OutputFolderLock>(folder);
}

int runBake(const Args& args) {
  std::optional<BakeCommand> parsed = parseBakeCommand(args);
  if (!parsed) return 0;
  BakeCommand& c = *parsed;
  if (c.quiet) log::setLevel(log::Level::Warn);
  else if (c.verbose) log::setLevel(log::Level::Debug);
  std::unique_ptr<tbb::global_control> threadLimit;
  if (c.threads > 0)
    threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, c.threads);

  const fs::path outDir = outputFolderOf(c.out);
  const std::shared_ptr<OutputGuard> guard = bakeOutputGuard(c, {});
  const OutputFolderLock lock(outDir);  // before any work: a second bake into OUTDIR fails at once
  const std::unique_ptr<OutputFolderLock> reportLock = lockReportFolder(c);
  removeStaleTemps(outDir);
  Stopwatch loadTime;
  Scene scene = loadBakeScene(c);
  const double loadSeconds = loadTime.seconds();

  TerminalProgress progress;
  c.options.progress = progress.callback();
  StagedBake staged(std::move(scene), c.options);

  // The blocks this process adds: all, or share K of N.
  const size_t blocks = staged.blockCount();
  const size_t begin = c.shardIndex ? blocks * (c.shardIndex - 1) / c.shardCount : 0;
  const size_t end = c.shardIndex ? blocks * c.shardIndex / c.shardCount : blocks;
  VplSumHeader header;
  header.sceneHash = sceneIdentity(c);
  header.optionsHash = c.optionsHash;
  header.options = c.resultOptions;
  header.seed = c.options.walk.seed;
  header.backend = toString(staged.backend());
  header.blockCount = blocks;
  header.firstBlock = begin;
  header.shardIndex = c.shardIndex;
  header.shardCount = c.shardCount;
  header.command = {{"scene", fs::absolute(c.scene).string()},
                    {"env", c.lights.environment.empty() ? std::string() : fs::absolute(c.lights.environment).string()},
                    {"args", c.arguments}};

  ExactVplSums sums = staged.emptySums();
  size_t next = begin;
  const fs::path checkpoint = outDir / kCheckpointName;
  if (fs::exists(checkpoint)) {
    if (c.resume) {
      VplSumFile saved = readVplSumFile(checkpoint);
      std::string differs = header.mismatch(saved.header);
      if (differs.empty() && (saved.header.firstBlock != begin || saved.header.endBlock > end))
        differs = "share of the VPL blocks";
      if (differs.empty() && saved.sums.coefficients != sums.coefficients)  // a version-1 --directional checkpoint
        differs = "coefficients per texel: " + std::to_string(saved.sums.coefficients) + " saved, " +
                  std::to_string(sums.coefficients) + " needed";
      if (differs.empty() && !saved.sums.sameLayout(sums)) differs = "page layout";
      if (!differs.empty())
        throw Error(ErrorCode::Usage, checkpoint.string(),
                    "this checkpoint belongs to another bake (different " + differs +
                        "): delete it, or bake without --resume");
      sums = std::move(saved.sums);
      next = saved.header.endBlock;
      staged.addBackendCounts(saved.header.backendCounts);
      log::info("resuming at VPL block " + std::to_string(next) + " of " + std::to_string(end) + " (" +
                checkpoint.string() + ")");
    } else {
      log::warn("ignoring the checkpoint " + checkpoint.string() + " of an earlier bake (--resume would continue it)");
    }
  } else if (c.resume) {
    log::info("no checkpoint in " + outDir.string() + ": baking from the start");
  }

  Stopwatch sinceCheckpoint;
  const bool checkpoints = !c.options.errorEstimate.enabled;  // the halves' sums are not in a checkpoint
  staged.evaluateBlocks(next, end, sums, [&](size_t done) {
    if (!checkpoints || done >= end || sinceCheckpoint.seconds() < c.checkpointSeconds) return;
    VplSumHeader h = header;
    h.kind = "checkpoint";
    h.endBlock = done;
    h.backendCounts = staged.backendCounts();
    writeVplSumFile(checkpoint, h, sums, guard.get());
    sinceCheckpoint.reset();
  });

  std::error_code ec;
  if (c.shardIndex > 0) {
    header.kind = "partial";
    header.endBlock = end;
    header.backendCounts = staged.backendCounts();
    const fs::path partial = outDir / partialName(c.shardIndex, c.shardCount);
    if (c.dumpConfig.empty()) writeVplSumFile(partial, header, sums, guard.get());
    else  // the partial and the config it was baked with, together or not at all
      guard->write({PendingFile{partial, [&](const fs::path& temp) { writeVplSumFile(temp, header, sums); }},
                    dumpedConfigFile(c.dumpConfig, c.dumpText)});
    removeCheckpoint(checkpoint, *guard);
    progress.finish();
    log::info("shard " + std::to_string(c.shardIndex) + "/" + std::to_string(c.shardCount) + ": VPL blocks " +
              std::to_string(begin) + ".." + std::to_string(end) + " of " + std::to_string(blocks));
    std::printf("%s\n", partial.string().c_str());
    return 0;
  }

  staged.refineToTarget(sums);
  BakeResult result = staged.finish(std::move(sums));
  result.report["timings"]["seconds"]["load"] = loadSeconds;
  result.report["options"] = c.resultOptions;
  writeFinishedBake(c, result, progress, *guard);
  removeCheckpoint(checkpoint, *guard);
  return 0;
}

namespace {
// "2.00%"
std::string percentText(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f%%", 100.0 * x);
  return text;
}
}  // namespace

// ", estimated error 2.10%" (and what stopped --target-error: the target, or a cap above it) for the final
// log line; "" without an estimate.
std::string estimatedErrorText(const nlohmann::json& report) {
  if (!report.contains("estimatedError")) return "";
  const nlohmann::json& e = report["estimatedError"];
  char text[96];
  std::snprintf(text, sizeof text, ", estimated error %.2f%%", 100.0 * e.value("relative", 0.0));
  std::string line = text;
  if (!e.contains("stoppedBy")) return line;
  const std::string stoppedBy = e["stoppedBy"].get<std::string>();
  if (stoppedBy == "target") return line + " (target " + percentText(e.value("targetError", 0.0)) + " reached)";
  return line + " (stopped by " + stoppedBy + ", above the target " + percentText(e.value("targetError", 0.0)) + ")";
}

void writeFinishedBake(const BakeCommand& c, const BakeResult& result, TerminalProgress& progress, const OutputGuard& guard) {
  OutputOptions outputOptions;
  outputOptions.guard = &guard;
  // --dump-config: the options, then what the bake chose where they said auto; written with the outputs.
  if (!c.dumpConfig.empty()) outputOptions.alsoWrite.push_back(dumpedConfigFile(c.dumpConfig, c.dumpText + automaticChoices(result.report)));
  outputOptions.outDir = c.out;
  outputOptions.reportPath = c.report;
  outputOptions.writeGltf = !c.noGltf;
  outputOptions.portablePath = c.portable;
  outputOptions.portable.exposure = c.portableExposure;
  outputOptions.inputs = c.inputs;
  Stopwatch writeTime;
  c.options.progress("write", 0.0);  // coarse: EXR pages, glTF and report are written one after another
  auto files = writeBakeOutputs(result, outputOptions);
  c.options.progress("write", 1.0);
  progress.finish();
  log::info("baked " + std::to_string(result.maps.size()) + " page(s) with " + result.report["backend"].get<std::string>() +
            " in " + std::to_string(result.report["timings"]["seconds"]["bake"].get<double>()) + " s (+ " +
            std::to_string(writeTime.seconds()) + " s writing)" + estimatedErrorText(result.report));
  for (const auto& f : files) std::printf("%s\n", f.string().c_str());
}
}  // namespace irbake::app
