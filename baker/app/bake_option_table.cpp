#include "app/bake_option_table.h"

#include <sstream>
#include <type_traits>

#include "atlas/atlas_estimate.h"
#include "common/command_line.h"
#include "export/light_probes_export.h"
#include "pipeline/backend_choice.h"
#include "stages/compensation/clamp_compensation.h"
#include "stages/interleave/interleaved_sampling.h"
#include "transport/geometry_term.h"

namespace irbake::app {

namespace {

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

using Field = std::function<OptionField(BakeCommand&, BakeArguments&)>;

// Where a value goes: a field of the arguments, of the command, or of the pipeline's options.
template <typename T>
Field arg(T BakeArguments::*member) {
  return [member](BakeCommand&, BakeArguments& a) -> OptionField { return &(a.*member); };
}
template <typename T>
Field cmd(T BakeCommand::*member) {
  return [member](BakeCommand& c, BakeArguments&) -> OptionField { return &(c.*member); };
}
template <typename F>
Field opt(F fieldOf) {
  return [fieldOf](BakeCommand& c, BakeArguments&) -> OptionField { return fieldOf(c.options); };
}
template <typename T>
std::function<long long(const QualityPreset&)> knob(T QualityPreset::*member) {
  return [member](const QualityPreset& p) { return static_cast<long long>(p.*member); };
}

OptionDescriptor row(std::string names, OptionKind kind, std::string group, std::string typeName, std::string help,
                     Field field, unsigned traits = kNoTraits) {
  OptionDescriptor d;
  d.names = std::move(names);
  // The first long name ("--paths,--vpls": paths), or the positional's name.
  const size_t dashes = d.names.find("--");
  d.name = dashes == std::string::npos ? d.names : d.names.substr(dashes + 2, d.names.find(',', dashes) - dashes - 2);
  d.kind = kind;
  d.group = std::move(group);
  d.typeName = std::move(typeName);
  d.help = std::move(help);
  d.field = std::move(field);
  d.traits = traits;
  return d;
}

OptionDescriptor flag(std::string names, std::string group, std::string help, Field field, unsigned traits = kNoTraits) {
  return row(std::move(names), OptionKind::Flag, std::move(group), "", std::move(help), std::move(field), traits);
}

OptionDescriptor ranged(OptionKind kind, std::string names, double lo, double hi, std::string group,
                        std::string typeName, std::string help, Field field, unsigned traits = kNoTraits) {
  OptionDescriptor d = row(std::move(names), kind, std::move(group), std::move(typeName), std::move(help), std::move(field), traits);
  d.lo = lo;
  d.hi = hi;
  return d;
}
OptionDescriptor integer(std::string names, double lo, double hi, std::string group, std::string typeName,
                         std::string help, Field field, unsigned traits = kNoTraits) {
  return ranged(OptionKind::Integer, std::move(names), lo, hi, std::move(group), std::move(typeName), std::move(help),
                std::move(field), traits);
}
OptionDescriptor number(std::string names, double lo, double hi, std::string group, std::string typeName,
                        std::string help, Field field, unsigned traits = kNoTraits) {
  return ranged(OptionKind::Number, std::move(names), lo, hi, std::move(group), std::move(typeName), std::move(help),
                std::move(field), traits);
}
// "auto" or a value in [lo, hi]; auto is written as autoValue.
OptionDescriptor orAuto(OptionDescriptor d, double autoValue) {
  d.traits |= kAutomatic;
  d.autoValue = autoValue;
  return d;
}
OptionDescriptor preset(OptionDescriptor d, std::function<long long(const QualityPreset&)> k) {
  d.preset = std::move(k);
  return d;
}
OptionDescriptor choice(std::string names, std::vector<std::string> choices, std::string group, std::string typeName,
                        std::string help, Field field, unsigned traits = kNoTraits) {
  OptionDescriptor d = row(std::move(names), OptionKind::Choice, std::move(group), std::move(typeName), std::move(help),
                           std::move(field), traits);
  d.choices = std::move(choices);
  return d;
}
OptionDescriptor list(std::string names, size_t length, std::string group, std::string typeName, std::string help, Field field) {
  OptionDescriptor d = row(std::move(names), OptionKind::NumberList, std::move(group), std::move(typeName), std::move(help), std::move(field));
  d.listLength = length;
  return d;
}
OptionDescriptor text(std::string names, std::string group, std::string typeName, std::string help, Field field,
                      unsigned traits = kNoTraits) {
  return row(std::move(names), OptionKind::Text, std::move(group), std::move(typeName), std::move(help), std::move(field), traits);
}

// The groups of --help-all; "Options" is the short --help.
const char* const kCommon = "Options";
const char* const kPaths = "Light paths and VPLs";
const char* const kTexels = "Texels";
const char* const kClamp = "Clamp and its compensation";
const char* const kGather = "Final gather";
const char* const kLights = "Sky, environment and punctual lights";
const char* const kProbes = "Irradiance probes";
const char* const kBackends = "Backends";
const char* const kOutputs = "Outputs";
const char* const kDistributed = "Distributed and resumable bakes";
const char* const kError = "Estimated error";
const char* const kDiagnostics = "Diagnostics";

// The scene, the output, the backend, the walk and the texels.
void addWalkRows(std::vector<OptionDescriptor>& t) {
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  t.push_back(text("SCENE", kCommon, "", "the glTF/GLB scene to bake", arg(&BakeArguments::scenes), kPath | kNotResult));
  t.push_back(text("-o,--output", kCommon, "OUTDIR", "output folder (OUTDIR), or OUT.glb / OUT.gltf: that glTF, the rest beside it",
                   cmd(&BakeCommand::out), kPath | kNotResult));
  t.push_back(choice("--backend", {"auto", "gl", "embree", "reference"}, kBackends, "",
                     "evaluator (default auto: GL on a GPU or for scenes ≤ " + shown(kGlTriangleHint / 1000) + "k triangles,\n"
                     "else embree; embree: ray-traced; reference: path traced)",
                     arg(&BakeArguments::backend), kAutomatic | kReplayable));
  t.push_back(orAuto(integer("--paths,--vpls", 1, 1 << 26, kPaths, "N|auto",
                             "light paths of the quasi-random walk (default auto: by --quality;\n" + shown(q.pathsUnderGather) +
                                 " under the final gather, which reads their map averaged; without it\n" + shown(q.paths / 2) +
                                 " evaluated, from 8x as many walked, forked past bounce 1 and resampled;\n" +
                                 "or " + shown(q.paths) + " with --walk-split N and no final gather)",
                             arg(&BakeArguments::paths), kReplayable), 0));
  t.push_back(orAuto(integer("--bounces", 0, 64, kPaths, "N|auto", "diffuse bounces (default auto: follow the energy left)",
                             arg(&BakeArguments::bounces)), -1));
  t.push_back(orAuto(integer("--walk-split", 1, 64, kPaths, "N|auto",
                             "paths fork into N where they leave bounce 1, each child carrying 1/N\n"
                             "(default auto: 1/(share of that light meeting the scene again), at most " +
                                 shown(d.walk.maxAutoSplit) + ";\n"
                                 "1 in closed scenes, but at least 4 where the final gather does not run;\n"
                                 "1 = Keller's plain walk)",
                             arg(&BakeArguments::walkSplit)), 0));
  t.push_back(orAuto(number("--vpl-importance", 1.0, 64.0, kPaths, "F|auto",
                            "importance-driven VPLs: the walk places F times the VPLs and --vpl-keep of\n"
                            "the plain walk's count is kept, chosen by what they add to dim texels\n"
                            "(default auto: where the final gather runs and a pilot finds them uneven,\n"
                            "F up to " + shown(d.vplImportance.maxFactor) + " while probes × candidates ≤ " +
                                shown(d.vplImportance.pairBudget / 1e6) + "M; 1: the plain walk)",
                            arg(&BakeArguments::vplImportance), kReplayable), 0.0));
  t.push_back(integer("--vpl-probes", 16, 65536, kPaths, "N",
                      "importance-driven VPLs: texel samples the candidates are measured at (default " +
                          shown(d.vplImportance.probes) + ")",
                      opt([](BakeOptions& o) { return &o.vplImportance.probes; })));
  t.push_back(number("--vpl-keep", 0.05, 4.0, kPaths, "S",
                     "importance-driven VPLs: VPLs kept, as a share of the plain walk's count (default " +
                         shown(d.vplImportance.keepShare) + ")",
                     opt([](BakeOptions& o) { return &o.vplImportance.keepShare; })));
  t.push_back(number("--texels-per-unit", 0.0, 1e6, kCommon, "T",
                     "texels per metre (default: the density rule, " + shown(q.autoTexelsPerMetre) +
                         " per metre; a small scene ≥ one " + shown(q.autoPageSize) + "² page)",
                     arg(&BakeArguments::tpu), kReplayable));
  t.push_back(integer("--max-texels", 0, double(1LL << 40), kTexels, "N",
                      "texel budget of all pages together (default " + shown(d.atlas.maxTexels) + " = " +
                          shown(d.atlas.maxTexels >> 20) + "M);\n"
                          "the density rule is lowered to fit it, with a warning; a given\n"
                          "--texels-per-unit over it fails at once, naming the density that fits;\n0 = no limit",
                      opt([](BakeOptions& o) { return &o.atlas.maxTexels; })));
  t.push_back(integer("--page-size", 0, 16384, kTexels, "S",
                      "largest page edge in texels; more pages when one is full (default 0: the\n"
                          "smallest power of two from " + shown(kMinAutoPageSize) + " to " + shown(kMaxAutoPageSize) +
                          " that holds the atlas twice over, else " + shown(kMaxAutoPageSize) + ")",
                      opt([](BakeOptions& o) { return &o.atlas.maxPageSize; })));
  t.push_back(text("--atlas-from", kTexels, "BAKED.gltf",
                   "bake onto the atlas of an earlier bake of the same geometry (its\n"
                   "TEXCOORD_1 and pages, no unwrap): lighting scenarios that share the\n"
                   "light-map UVs (docs/guide.md, \"Scenarios\")",
                   opt([](BakeOptions& o) { return &o.atlasFrom; }), kPath));
  t.push_back(integer("--supersample", 1, 8, kTexels, "S", "S×S samples per texel (default " + shown(d.texels.supersample) + ")",
                      opt([](BakeOptions& o) { return &o.texels.supersample; })));
}

// The clamp and its compensation.
void addClampRows(std::vector<OptionDescriptor>& t) {
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  t.push_back(number("--clamp", 0.0, 1e30, kClamp, "B", "geometry-term bound (1/m²); 0 = no clamp\n(default: derived from the scene)",
                     arg(&BakeArguments::clamp), kPresence));
  t.push_back(number("--clamp-k", 0.0, 1e6, kClamp, "K",
                     "derived clamp: no VPL adds more than 1/K of the mean\n"
                     "(default with bias compensation: " + shown(kCompensatedClampVplsPerMean) + ", or " +
                         shown(kCompensatedClampVplsPerMeanNoEmitters) + " in a scene\nwithout small emissive surfaces (under half the surface); " +
                         shown(kClampVplsPerMean) + " without; 0 = automatic)",
                     opt([](BakeOptions& o) { return &o.clampVplsPerMean; }), kReplayable));
  t.push_back(flag("--no-bias-compensation", kClamp,
                   "keep the clamp's bias (default: recovered by a gather into\nthe map, after Kollig & Keller 2004)",
                   arg(&BakeArguments::noBiasCompensation)));
  t.push_back(flag("--bias-compensation", kClamp, "the default (kept for old scripts)", arg(&BakeArguments::biasCompensation)));
  t.push_back(preset(integer("--comp-rays", 1, 4096, kClamp, "N",
                             "bias compensation: rays per texel sample, first round (default " + shown(q.compensationRays) + ")",
                             opt([](BakeOptions& o) { return &o.compensation.rays; })),
                     knob(&QualityPreset::compensationRays)));
  t.push_back(preset(integer("--comp-refine", 0, 65536, kClamp, "N",
                             "bias compensation: extra rays where needed (default " + shown(q.compensationRefine) + ")",
                             opt([](BakeOptions& o) { return &o.compensation.refineRays; })),
                     knob(&QualityPreset::compensationRefine)));
  t.push_back(preset(integer("--comp-ray-budget", 0, double(1LL << 34), kClamp, "N",
                             "bias compensation: first-round rays over all samples (default " + shown(q.compensationBudget) +
                                 ";\na large page gets fewer per sample, never below " + shown(d.compensation.minRays) + "; 0 = no cap)",
                             opt([](BakeOptions& o) { return &o.compensation.rayBudget; })),
                     knob(&QualityPreset::compensationBudget)));
  t.push_back(orAuto(integer("--comp-filter", 0, 8, kClamp, "R|auto",
                             "bias compensation: the residual averaged over (2R+1)² texels on\n"
                             "the same surface (default auto: up to 4 where the rays per sample are\n"
                             "few and R texels stay within 1/20 of the clamp radius; 0 = none)",
                             arg(&BakeArguments::compFilter)), -1));
}

// The final gather, interleaving, the GL backend's cubes.
void addGatherRows(std::vector<OptionDescriptor>& t) {
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  t.push_back(choice("--final-gather", {"off", "on", "auto"}, kGather, "off|on|auto",
                     "bounced light gathered from the baked map one bounce away instead of\n"
                     "read from the VPLs that reach each texel (docs/units.md): on, off,\n"
                     "or auto (default: on in scenes without emissive or see-through surfaces)",
                     arg(&BakeArguments::finalGather), kAutomatic | kReplayable));
  t.push_back(preset(integer("--gather-rays", 1, 4096, kGather, "N",
                             "final gather: cosine rays per texel sample (default " + shown(q.gatherRays) + ")",
                             opt([](BakeOptions& o) { return &o.gather.rays; })),
                     knob(&QualityPreset::gatherRays)));
  t.push_back(integer("--gather-pre-rays", 0, 4096, kGather, "N",
                      "final gather: rays per sample of a first, cheaper gather whose map\nthe final rays read (default " +
                          shown(d.gather.preRays) + "; 0 = none)",
                      opt([](BakeOptions& o) { return &o.gather.preRays; })));
  t.push_back(preset(integer("--gather-ray-budget", 0, double(1LL << 34), kGather, "N",
                             "final gather: rays over all samples (default " + shown(q.gatherRayBudget) + "; a large\n"
                             "page gets fewer per sample, never below " + shown(d.gather.minRays) + "; 0 = no cap)",
                             opt([](BakeOptions& o) { return &o.gather.rayBudget; })),
                     knob(&QualityPreset::gatherRayBudget)));
  t.push_back(integer("--gather-filter", 0, 8, kGather, "R",
                      "final gather: the gathered light averaged over (2R+1)² texels on\nthe same surface (default " +
                          shown(d.gather.filterRadius) + "; 0 = none)",
                      opt([](BakeOptions& o) { return &o.gather.filterRadius; })));
  t.push_back(number("--gather-outliers", 0.0, 1e6, kGather, "K",
                     "final gather: a texel's gathered light above K × its filter window's mean\nis held there and the "
                     "excess spread ~4x wider (default " + shown(d.gather.outlierRatio) + "; 0 = off)",
                     opt([](BakeOptions& o) { return &o.gather.outlierRatio; })));
  t.push_back(orAuto(integer("--interleave", 1, 8, kTexels, "N|auto",
                             "interleaved sampling: each texel of an N×N block sees 1/N²\n"
                             "of the VPLs, then a filter on the surface mixes them\n"
                             "(default auto: 1.." + shown(kMaxAutoInterleave) + " from the texel size and the clamp radius;\n"
                             "1 = every VPL everywhere)",
                             arg(&BakeArguments::interleave), kReplayable), 0));
  t.push_back(orAuto(integer("--cube-face", 16, 2048, kBackends, "N|auto",
                             "GL backend: VPL depth-cube face size in texels\n"
                             "(default auto: a shadow texel's footprint held to the\nlight-map texel spacing, " +
                                 shown(d.gl.minCubeFaceSize) + ".." + shown(d.gl.maxCubeFaceSize) + ")",
                             arg(&BakeArguments::cubeFace), kReplayable), 0));
}

// The seed, the reference backend, light from the command line.
void addLightRows(std::vector<OptionDescriptor>& t) {
  const BakeOptions d;
  const QualityPreset& q = defaultQualityPreset();
  t.push_back(integer("--seed", 0, 1 << 30, kCommon, "K", "walk seed (default 0)", arg(&BakeArguments::seed)));
  t.push_back(integer("--spp", 1, 1 << 20, kBackends, "N", "reference backend: paths per texel sample (default " + shown(d.referenceSpp) + ")",
                      opt([](BakeOptions& o) { return &o.referenceSpp; })));
  t.push_back(list("--sun", 4, kCommon, "DX,DY,DZ,E", "add a directional light travelling along D with irradiance E (W/m²)",
                   arg(&BakeArguments::sun)));
  t.push_back(list("--sky", 3, kCommon, "R,G,B", "a uniform sky of that radiance (W/(m² sr))", arg(&BakeArguments::sky)));
  t.push_back(preset(integer("--sky-rays", 8, 4096, kLights, "N",
                             "sky and environment: rays per texel sample (default " + shown(q.skyRays) + ")",
                             opt([](BakeOptions& o) { return &o.sky.raysPerSample; })),
                     knob(&QualityPreset::skyRays)));
  t.push_back(preset(integer("--sky-ray-budget", 1, 1 << 30, kLights, "N",
                             "sky and environment: rays over all samples (default " + shown(q.skyRayBudget) + "; a large\n"
                             "page gets fewer per sample, never below " + shown(d.sky.minRays) + ", or 4 where the final\n"
                             "gather counts a uniform sky itself)",
                             opt([](BakeOptions& o) { return &o.sky.maxRays; })),
                     knob(&QualityPreset::skyRayBudget)));
  t.push_back(row("--light-mode", OptionKind::Repeated, kLights, "NAME=MODE",
                  "a punctual light's bake mode: baked (default), indirect (its bounces\n"
                  "only) or shadowmask (indirect plus its visibility in a mask page);\n"
                  "NAME: the glTF light's name, sun (--sun), #I (KHR light I) or *\n"
                  "(every punctual light); name:TEXT, index:I and option:sun never\n"
                  "mean another light; repeatable, beats extras.irbake.mode",
                  arg(&BakeArguments::lightModes)));
  t.push_back(row("--light-group", OptionKind::Repeated, kLights, "NAME=LIGHTS",
                  "bake these sources into a layer of their own (IRBAKE_lightmap_scenarios);\n"
                  "LIGHTS: comma-separated light names, sun, sky, emissive, emissive:NAME,\n"
                  "#I or * (every source no other group names); repeatable, beside\n"
                  "extras.irbake.group; the maps hold the sum (docs/guide.md)",
                  arg(&BakeArguments::lightGroups)));
  t.push_back(text("--only-group", kLights, "NAME",
                   "with --atlas-from BAKED.gltf, a grouped bake: bake light group NAME\n"
                   "alone, carry the bake's other layers over, write the whole set\n"
                   "(docs/guide.md, \"Scenarios and light groups\")",
                   opt([](BakeOptions& o) { return &o.onlyGroup; })));
  t.push_back(preset(integer("--shadow-edge-samples", 0, 16, kLights, "S",
                             "punctual lights: S×S shadow rays over each texel a shadow edge\ncrosses (default " +
                                 shown(q.shadowEdgeSamples) + "; 0 or 1: the centre alone)",
                             opt([](BakeOptions& o) { return &o.shadowEdges.subSamples; })),
                     knob(&QualityPreset::shadowEdgeSamples)));
  t.push_back(number("--light-cull", 0.0, 1.0, kLights, "F",
                     "each light's work only where it reaches: its range, or where its light\nfalls to F × the scene's "
                     "reference (default " + shown(LightCullOptions{}.fraction) + ", docs/units.md); 0: every light everywhere",
                     opt([](BakeOptions& o) { return &o.lightCull.fraction; })));
  t.push_back(integer("--light-tail", 0, 256, kLights, "N",
                      "shadow rays per texel (to lights resampled from a light tree) adding back\nwhat the cut left out of lights without "
                      "range (default " + shown(LightTailOptions{}.samples) + "; 0: left out)",
                      opt([](BakeOptions& o) { return &o.lightTail.samples; })));
  t.push_back(text("--env", kCommon, "FILE", "an equirectangular environment (.exr/.hdr, +Y up) instead of --sky",
                   arg(&BakeArguments::env), kPath));
  t.push_back(number("--env-intensity", 0.0, kLargestLight, kLights, "S",
                     "scales --env (default " + shown(LightAdditions{}.environmentIntensity) + ")", arg(&BakeArguments::envIntensity)));
  t.push_back(number("--env-rotation", -36000.0, 36000.0, kLights, "DEG",
                     "turns --env about +Y (degrees, default " + shown(LightAdditions{}.environmentRotation) + ")",
                     arg(&BakeArguments::envRotation)));
}

// The probes and what is written.
void addProbeAndOutputRows(std::vector<OptionDescriptor>& t) {
  const ProbeOptions p;
  const BakeCommand dc;
  t.push_back(text("--report", kCommon, "R.json", "report path (default OUTDIR/report.json)", cmd(&BakeCommand::report),
                   kPath | kNotResult));
  t.push_back(text("--probes", kCommon, "auto|off|M",
                   "irradiance probes for moving objects (IRBAKE_light_probes): auto (default: about\n"
                   "1024 probes over the scene, 2048 with a sun), off, or a spacing in metres",
                   arg(&BakeArguments::probes), kAutomatic));
  t.push_back(list("--probe-box", 6, kProbes, "X0,Y0,Z0,X1,Y1,Z1", "the probes fill this box instead of the scene's bounds",
                   arg(&BakeArguments::probeBox)));
  t.push_back(integer("--probe-budget", 1, double(p.maxProbes), kProbes, "N",
                      "at most N probes, or the bake is refused before any work (default " + shown(p.budget) +
                          ",\n8x the automatic grid with a sun; up to " + shown(p.maxProbes) + ")",
                      opt([](BakeOptions& o) { return &o.probes.budget; })));
  t.push_back(integer("--probe-rays", 16, 1 << 16, kProbes, "N", "rays per probe (default " + std::to_string(p.rays) + ")",
                      opt([](BakeOptions& o) { return &o.probes.rays; })));
  t.push_back(integer("--probe-light-fit", 0, 8, kProbes, "S",
                      "the punctual lights' visibility at the probes fitted over S×S×S points per probe\n"
                      "(default " + std::to_string(p.lightFitSamples) + "; 0: each probe's own shadow ray)",
                      opt([](BakeOptions& o) { return &o.probes.lightFitSamples; })));
  t.push_back(integer("--probe-volume-fit", 0, 8, kProbes, "S",
                      "the rest of the probes' light fitted over S×S×S points per probe, " +
                          std::to_string(p.volumeFitRays) + " rays each\n(default " +
                          std::to_string(p.volumeFitSamples) + "; 0: each probe's own rays)",
                      opt([](BakeOptions& o) { return &o.probes.volumeFitSamples; })));
  t.push_back(integer("--probe-volume-rays", 16, 1 << 16, kProbes, "N",
                      "lattice rays per point of the volume fit (default " + std::to_string(p.volumeFitRays) + ")",
                      opt([](BakeOptions& o) { return &o.probes.volumeFitRays; })));
  t.push_back(number("--probe-volume-clearance", 0.0, 8.0, kProbes, "C",
                     "the volume fit's points at least this many spacings from every surface (default " +
                         shown(p.volumeFitClearance) + ";\n0: every point the probes see)",
                     opt([](BakeOptions& o) { return &o.probes.volumeFitClearance; })));
  t.push_back(integer("--probe-exact-emitters", 0, kMaxExactEmitterTriangles, kProbes, "N",
                      "uniform planar or small emitters of at most N triangles in all (brightest first) left out of the\n"
                      "probes' SH for the clients' exact shading (default " + std::to_string(p.exactEmitterTriangles) +
                          "; 0: every emitter in the SH)",
                      opt([](BakeOptions& o) { return &o.probes.exactEmitterTriangles; })));
  t.push_back(flag("--directional", kCommon, "also bake directional (L1) maps (docs/export.md)",
                   opt([](BakeOptions& o) { return &o.directional; })));
  t.push_back(flag("--no-gltf", kOutputs, "write only the EXR pages and the report", cmd(&BakeCommand::noGltf), kNotResult));
  t.push_back(text("--portable", kCommon, "[GLB]",
                   "also an unlit GLB for viewers without MOZ_lightmap, in OUTDIR unless a folder is named (docs/export.md)",
                   cmd(&BakeCommand::portable), kPath | kNotResult));
  t.back().valueWhenBare = kPortableName;
  t.push_back(number("--portable-exposure", 1e-6, 1e6, kOutputs, "X",
                     "--portable: scale on the shown values before the range and the 8-bit sRGB encode\n"
                     "(default " + shown(dc.portableExposure) + ": the map as it is)",
                     cmd(&BakeCommand::portableExposure), kNotResult));
  t.push_back(integer("--portable-max-size", 64, 16384, kOutputs, "N",
                      "--portable: at most N texels a side per texture; a larger page is tiled\n"
                      "into several textures (default " + std::to_string(dc.portableMaxSize) + ")",
                      cmd(&BakeCommand::portableMaxSize), kNotResult));
}

// Diagnostics, threads and logging, distributed and resumable bakes, presets and config files.
void addRunRows(std::vector<OptionDescriptor>& t) {
  const BakeOptions d;
  const BakeCommand dc;
  t.push_back(flag("--no-leak-control", kDiagnostics, "diagnostics: texel samples may sit behind walls", arg(&BakeArguments::noLeakControl)));
  t.push_back(flag("--no-dilate", kDiagnostics, "diagnostics: no dilation into the padding", arg(&BakeArguments::noDilate)));
  t.push_back(flag("--no-seams", kDiagnostics, "diagnostics: no seam stitching", arg(&BakeArguments::noSeams)));
  t.push_back(flag("--gpu-timers", kDiagnostics,
                   "diagnostics: the GL passes' GPU time in the report (timings.gl.gpu*Seconds;\n"
                   "timer queries, which some drivers serialise)",
                   opt([](BakeOptions& o) { return &o.gl.gpuTimers; })));
  t.push_back(integer("--threads", 0, 1024, kCommon, "N", "worker threads (default 0: every core; same bytes for any count)",
                      cmd(&BakeCommand::threads), kNotResult));
  t.push_back(number("--max-memory", 0.0, 1e6, kCommon, "GB", "refuse a bake predicted to need more memory (irbake plan; 0: none)",
                     opt([](BakeOptions& o) { return &o.maxMemoryGB; }), kNotResult));
  t.push_back(flag("--quiet", kCommon, "warnings and errors only, no progress bars", cmd(&BakeCommand::quiet), kNotResult));
  t.push_back(flag("--verbose", kOutputs, "also the stages' debug lines (e.g. the compensation's sweeps)",
                   cmd(&BakeCommand::verbose), kNotResult));
  t.push_back(text("--shard", kDistributed, "K/N",
                   "evaluate share K of N of the VPL blocks and write the exact partial\n"
                   "sums to OUTDIR/partial_K_of_N.vplsum for 'irbake merge' (docs/distributed.md)",
                   arg(&BakeArguments::shard), kNotResult));
  t.push_back(flag("--resume", kDistributed,
                   "continue from OUTDIR's checkpoint (left by a bake that was killed);\n"
                   "the outputs are byte-identical to an uninterrupted bake",
                   cmd(&BakeCommand::resume), kNotResult));
  t.push_back(number("--checkpoint-seconds", 0.0, 1e9, kDistributed, "S",
                     "at most this long between checkpoints of the VPL sums (default " + shown(dc.checkpointSeconds) +
                         ";\n0: after every VPL block)",
                     cmd(&BakeCommand::checkpointSeconds), kNotResult));
  t.push_back(integer("--vpl-block", 1, 1 << 20, kPaths, "N",
                      "VPLs per block of the exact VPL sum, the unit of shards and\ncheckpoints (default " + shown(d.vplBlock) + ")",
                      opt([](BakeOptions& o) { return &o.vplBlock; })));
  std::vector<std::string> presets;
  for (const QualityPreset& p : qualityPresets()) presets.push_back(p.name);
  t.push_back(choice("--quality", presets, kCommon, "Q", "paths and rays together (default: default; docs/validation.md)",
                     arg(&BakeArguments::quality)));
  t.push_back(text("--config", kCommon, "FILE", "options from a TOML file (key = value); the command line wins",
                   arg(&BakeArguments::config), kNotResult | kNotInConfig));
  t.push_back(text("--dump-config", kOutputs, "FILE", "write every option of this bake as such a file",
                   arg(&BakeArguments::dumpConfig), kPath | kNotResult | kNotDumped));
  t.push_back(flag("--help-all", kCommon, "every option, grouped by stage", arg(&BakeArguments::helpAll), kNotResult | kNotInConfig));
}

// The bake's own error (stages/error_estimate) and the target that adds rounds until it is met.
void addErrorRows(std::vector<OptionDescriptor>& t) {
  const ErrorEstimateOptions d;
  t.push_back(flag("--estimate-error", kError,
                   "walk the paths as two independent halves (seeds of their own) and\n"
                   "report the bake's estimated error (report.json estimatedError:\n"
                   "relative RMS on 4x4-texel bins, as bench/cycles/compare.py scores)",
                   opt([](BakeOptions& o) { return &o.errorEstimate.enabled; })));
  t.push_back(number("--target-error", 1e-6, 1.0, kCommon, "E",
                     "add paths or stage rays until the estimated error is at most E (e.g. 0.02)",
                     opt([](BakeOptions& o) { return &o.errorEstimate.targetError; })));
  t.push_back(integer("--max-rounds", 1, 4096, kError, "N",
                      "--target-error: at most this many rounds, of paths or of rays\n(default " + shown(d.maxRounds) + ")",
                      opt([](BakeOptions& o) { return &o.errorEstimate.maxRounds; })));
  t.push_back(number("--max-time", 0.0, 1e9, kError, "SECONDS",
                     "--target-error: no round started that would end past this many\n"
                     "seconds of bake (default 0: no cap; the result then depends on the\nmachine)",
                     opt([](BakeOptions& o) { return &o.errorEstimate.maxSeconds; })));
  t.push_back(flag("--error-map", kError, "with the estimate: also each texel's standard error, OUTDIR/error_<page>.exr",
                   opt([](BakeOptions& o) { return &o.errorEstimate.errorMap; })));
}

}  // namespace

const std::vector<OptionDescriptor>& bakeOptionTable() {
  static const std::vector<OptionDescriptor> table = [] {
    std::vector<OptionDescriptor> t;
    addWalkRows(t);
    addClampRows(t);
    addGatherRows(t);
    addLightRows(t);
    addProbeAndOutputRows(t);
    addRunRows(t);
    addErrorRows(t);
    return t;
  }();
  return table;
}

const OptionDescriptor* findBakeOption(const std::string& name) {
  for (const OptionDescriptor& d : bakeOptionTable())
    if (d.name == name || d.configKey() == name) return &d;
  return nullptr;
}

CLI::Option* addOption(CLI::App& app, const OptionDescriptor& d, OptionField field) {
  CLI::Option* option = std::visit(
      [&](auto* target) -> CLI::Option* {
        using T = std::remove_pointer_t<decltype(target)>;
        if constexpr (std::is_same_v<T, bool>) {
          return app.add_flag(d.names, *target, d.help);
        } else {
          return app.add_option(d.names, *target, d.help);
        }
      },
      field);
  const bool automatic = d.has(kAutomatic);
  const auto lo = static_cast<long long>(d.lo), hi = static_cast<long long>(d.hi);
  switch (d.kind) {
    case OptionKind::Integer:
      option->transform(automatic ? cli::integerOrAuto(lo, hi, static_cast<long long>(d.autoValue)) : cli::integerIn(lo, hi));
      break;
    case OptionKind::Number:
      option->transform(automatic ? cli::numberOrAuto(d.lo, d.hi, d.autoValue) : cli::numberIn(d.lo, d.hi));
      break;
    case OptionKind::Choice: option->check(CLI::IsMember(d.choices)); break;
    case OptionKind::NumberList: option->transform(cli::numberList(d.listLength)); break;
    default: break;
  }
  if (!d.typeName.empty()) option->type_name(d.typeName);
  if (d.kind == OptionKind::Repeated) option->allow_extra_args(false);  // one value each time: never the SCENE after it
  if (!d.valueWhenBare.empty()) option->expected(0, 1)->default_str(d.valueWhenBare);
  option->group(d.group);
  return option;
}

std::string defaultText(const OptionDescriptor& d) {
  BakeCommand command;
  BakeArguments arguments;
  CLI::App app;
  return addOption(app, d, d.field(command, arguments))->capture_default_str()->get_default_str();
}

const CLI::Option* givenOption(const CLI::App& app, const OptionDescriptor& d) {
  return app.get_option(d.name == "SCENE" ? d.name : "--" + d.name);
}

std::string joinedResults(const CLI::Option& option) {
  std::string value;
  for (const std::string& r : option.results()) value += (value.empty() ? "" : ",") + r;
  return value;
}

std::unique_ptr<CLI::App> bakeApp(BakeCommand& command, BakeArguments& arguments) {
  auto app = cli::makeApp("irbake bake",
                          "Bakes light maps (EXR, irradiance/pi, linear) and exports glTF with MOZ_lightmap.\n"
                          "Writes OUTDIR/lightmap_<page>.exr, OUTDIR/scene.gltf and the report.");
  for (const OptionDescriptor& d : bakeOptionTable()) addOption(*app, d, d.field(command, arguments));
  arguments.shardOption = app->get_option("--shard");
  arguments.clampOption = app->get_option("--clamp");
  return app;
}

void applyQuality(const CLI::App& app, const QualityPreset& preset, BakeCommand& command, BakeArguments& arguments) {
  for (const OptionDescriptor& d : bakeOptionTable()) {
    if (!d.preset || app.get_option("--" + d.name)->count() > 0) continue;
    const long long value = d.preset(preset);
    std::visit(
        [value](auto* target) {
          using T = std::remove_pointer_t<decltype(target)>;
          if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) *target = static_cast<T>(value);
        },
        d.field(command, arguments));
  }
  command.options.atlas.targetPageSize = preset.autoPageSize;  // read only where --texels-per-unit is auto
  command.options.atlas.autoTexelsPerUnit = preset.autoTexelsPerMetre;
}

}  // namespace irbake::app
