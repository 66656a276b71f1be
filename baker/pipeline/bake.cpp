// The bake, stage by stage, with the report the benchmarks and users read.
#include "pipeline/bake.h"

#include <sys/resource.h>

#include <cmath>
#include <future>
#include <memory>

#include "backend/compensation/clamp_compensation.h"
#include "backend/embree/embree_backend.h"
#include "transport/geometry_term.h"
#include "backend/gl/gl_backend.h"
#include "backend/interleave/interleaved_sampling.h"
#include "glcontext/gl_context.h"
#include "backend/reference/reference_integrator.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "post/post.h"
#include "raytrace/ray_tracer.h"

namespace irbake {
namespace {

nlohmann::json rgb(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

// Above this many triangles, GL on llvmpipe is slower than Embree on the benches (Cornell box, 32: GL ≈ 10%
// faster; DamagedHelmet, 15k: Embree 1.8× faster; furnished room, 58k: Embree 4–17× faster).
constexpr size_t kSoftwareGlTriangleHint = 10000;

// The first see-through material (MASK cut-outs, BLEND, transmission) a primitive uses, as a phrase for the
// log; empty when there is none. The GL backend sends the texels they shade to rays (contact texels).
std::string seeThroughMaterials(const Scene& scene) {
  for (const Primitive& p : scene.primitives) {
    const Material& m = scene.materials[p.material];
    if (m.alphaMode == AlphaMode::Mask) return "material '" + m.name + "' is alpha MASK";
    if (m.alphaMode == AlphaMode::Blend) return "material '" + m.name + "' is alpha BLEND (see-through)";
    if (m.transmission > 0.0f) return "material '" + m.name + "' is transmissive";
  }
  return {};
}

// The backend stage. The GL engineer owns the GL line (options, stats); every backend returns one
// Lightmap per texel page. glContext: the bake's context (current on this thread) for the GL backend.
std::vector<Lightmap> runBackend(BackendKind backend, const BakeOptions& options, const BakeInputs& inputs,
                                 nlohmann::json& report, GlContext* glContext) {
  const int interleave =
      options.interleave > 0 ? options.interleave : chooseInterleave(inputs.texels, inputs.eval.clampBound);
  switch (backend) {
    case BackendKind::Gl: {
      // One context for every call (interleaved sampling makes n² + 1 of them).
      GlBakeStats total;
      VplBackend gl = [&](const BakeInputs& in) {
        GlBakeStats st;
        GlBackendOptions go = options.gl;
        go.stats = &st;
        go.context = glContext;
        std::vector<Lightmap> maps = bakeGl(in, go);
        total.add(st);
        return maps;
      };
      InterleaveStats is;
      std::vector<Lightmap> maps = bakeInterleaved(inputs, interleave, gl, &is);
      report["renderer"] = total.renderer;
      report["gl"] = {{"passes", total.passes},               {"facesRendered", total.facesRendered},
                      {"trianglesDrawn", total.trianglesDrawn}, {"cubeFaceSize", total.cubeFaceSize},
                      {"contactTexels", total.contactTexels},
                      {"contactFraction", total.texelsEvaluated ? double(total.contactTexels) / total.texelsEvaluated : 0.0}};
      report["timings"]["gl"] = {{"setupSeconds", total.setupSeconds},     {"shadowSeconds", total.shadowSeconds},
                                 {"accumulateSeconds", total.accumulateSeconds}, {"foldSeconds", total.foldSeconds},
                                 {"contactSeconds", total.contactSeconds}};
      report["interleave"] = {{"classes", is.classes}, {"backendCalls", is.backendCalls}};
      return maps;
    }
    case BackendKind::Embree: {
      InterleaveStats is;
      std::vector<Lightmap> maps =
          bakeInterleaved(inputs, interleave, [](const BakeInputs& in) { return bakeEmbree(in); }, &is);
      report["interleave"] = {{"classes", is.classes}, {"backendCalls", is.backendCalls}};
      return maps;
    }
    case BackendKind::Auto:
      break;  // resolved by bake() before this stage
    case BackendKind::Reference: {
      ReferenceOptions ref;
      ref.spp = options.referenceSpp;
      ref.seed = options.walk.seed;
      std::vector<Lightmap> standardError;
      std::vector<Lightmap> maps = bakeReference(inputs, ref, &standardError);
      // The mean standard error over valid texels says how converged the yardstick is.
      double se = 0.0, value = 0.0;
      for (size_t p = 0; p < maps.size() && p < standardError.size(); ++p)
        for (size_t i = 0; i < maps[p].size() && i < standardError[p].size(); ++i) {
          if (i < maps[p].valid.size() && !maps[p].valid[i]) continue;
          const glm::vec3 &e = standardError[p].texels[i], &v = maps[p].texels[i];
          se += (e.x + e.y + e.z) / 3.0;
          value += (v.x + v.y + v.z) / 3.0;
        }
      report["reference"] = {{"spp", ref.spp}, {"relativeStandardError", value > 0.0 ? se / value : 0.0}};
      return maps;
    }
  }
  throw Error(ErrorCode::Usage, "", "unknown backend");
}

}  // namespace

BackendKind parseBackend(const std::string& name) {
  if (name == "auto") return BackendKind::Auto;
  if (name == "gl") return BackendKind::Gl;
  if (name == "embree") return BackendKind::Embree;
  if (name == "reference") return BackendKind::Reference;
  throw Error(ErrorCode::Usage, "", "unknown backend '" + name + "' (auto, gl, embree or reference)");
}

const char* toString(BackendKind kind) {
  switch (kind) {
    case BackendKind::Auto: return "auto";
    case BackendKind::Gl: return "gl";
    case BackendKind::Embree: return "embree";
    case BackendKind::Reference: return "reference";
  }
  return "?";
}

Light sunLight(const glm::vec3& direction, float irradiance) {
  float len = glm::length(direction);
  if (!(len > 0.0f) || !std::isfinite(len))
    throw Error(ErrorCode::Usage, "", "--sun needs a non-zero direction");
  if (!(irradiance > 0.0f) || !std::isfinite(irradiance))
    throw Error(ErrorCode::Usage, "", "--sun needs a positive irradiance");
  Light sun;
  sun.name = "sun (command line)";
  sun.type = LightType::Directional;
  sun.direction = direction / len;
  sun.intensity = irradiance;
  return sun;
}

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: kilobytes
}

BakeResult bake(Scene scene, const BakeOptions& options) {
  BakeResult r;
  r.scene = std::move(scene);
  Scene& s = r.scene;
  if (s.triangleCount() == 0) throw Error(ErrorCode::EmptyScene, s.sourcePath, "no triangles to bake");
  nlohmann::json& report = r.report;
  nlohmann::json seconds;
  Stopwatch total, stage;
  auto withProgress = [&](ProgressCallback cb) { return cb ? cb : options.progress; };

  AtlasOptions atlasOptions = options.atlas;
  atlasOptions.progress = withProgress(atlasOptions.progress);
  r.atlas = buildAtlas(s, atlasOptions);
  seconds["atlas"] = stage.seconds();

  stage.reset();
  RayTracer rt(s);
  seconds["raytrace"] = stage.seconds();

  stage.reset();
  TexelSampleOptions texelOptions = options.texels;
  texelOptions.progress = withProgress(texelOptions.progress);
  std::vector<TexelSamples> texels = buildTexelSamples(s, rt, texelOptions);
  seconds["texels"] = stage.seconds();

  stage.reset();
  WalkOptions walk = options.walk;
  walk.progress = withProgress(walk.progress);
  r.vpls = generateVpls(s, rt, walk);
  seconds["vpls"] = stage.seconds();

  VplEvalOptions eval = options.eval;
  bool clampDerived = false;
  double clampK = 0.0;
  if (options.autoClamp && eval.clampBound == 0.0f) {
    clampK = options.clampVplsPerMean > 0.0 ? options.clampVplsPerMean
             : eval.biasCompensation     ? kCompensatedClampVplsPerMean
                                         : kClampVplsPerMean;
    eval.clampBound = deriveClampBound(s, r.vpls, clampK);
    clampDerived = true;
  }

  stage.reset();
  // --backend auto: GL where it is both right and fast, Embree otherwise (the choice and why in the report).
  std::unique_ptr<GlContext> glContext;
  BackendKind backend = options.backend;
  std::string backendReason = "asked for";
  if (backend == BackendKind::Auto) {
    backend = BackendKind::Embree;
    if (std::string why = seeThroughMaterials(s); !why.empty()) {
      backendReason = why + ": the GL backend would trace most texels it shades anyway (red pane test: 64%)";
    } else {
      try {
        glContext = std::make_unique<GlContext>();
        if (!glContext->softwareRenderer()) {
          backend = BackendKind::Gl;
          backendReason = "hardware GL renderer";
        } else if (s.triangleCount() <= kSoftwareGlTriangleHint) {
          backend = BackendKind::Gl;
          backendReason = "software GL renderer, " + std::to_string(s.triangleCount()) + " triangles (≤ " +
                          std::to_string(kSoftwareGlTriangleHint) + ": GL as fast as Embree)";
        } else {
          backendReason = "software GL renderer with " + std::to_string(s.triangleCount()) +
                          " triangles: its shadow pass draws them for every VPL cube (docs/performance.md)";
        }
      } catch (const Error& e) {
        backendReason = std::string("no GL context: ") + e.what();
      }
      if (backend != BackendKind::Gl) glContext.reset();
    }
    log::info(std::string("backend auto: ") + toString(backend) + " (" + backendReason + ")");
  }
  report["backendChoice"] = {{"asked", toString(options.backend)}, {"used", toString(backend)}, {"reason", backendReason}};

  // Bias compensation is its own stage after either VPL backend (backend/compensation), so the backends
  // evaluate the clamped sum only.
  const bool compensate = eval.biasCompensation && backend != BackendKind::Reference;
  VplEvalOptions backendEval = eval;
  if (compensate) backendEval.biasCompensation = false;
  BakeInputs inputs{s, rt, texels, r.vpls, backendEval, options.progress};
  ClampCompensationOptions co = options.compensation;
  co.seed = options.walk.seed;
  // The compensation's rays read the geometry only, so with the GL backend on a GPU they are traced on the
  // CPU while it bakes. Not on llvmpipe: the trace and the rasteriser threads share the same cores, and the
  // rasteriser waits for its slowest thread (Cornell box: bake 1.95 → 2.43 s). Embree uses every core itself.
  if (backend == BackendKind::Gl) {
    if (!glContext) glContext = std::make_unique<GlContext>();
    log::info("GL backend: " + glContext->description());
    // On a CPU rasteriser the shadow pass costs every triangle once per VPL cube face (docs/performance.md).
    if (glContext->softwareRenderer() && s.triangleCount() > kSoftwareGlTriangleHint && r.vpls.vpls.size() > 0)
      log::warn("GL backend on a software renderer with " + std::to_string(s.triangleCount()) +
                " triangles: its shadow pass draws them for every VPL cube (on the 2-core bench machine the Embree "
                "backend baked a 58k-triangle room 4-17x faster); consider --backend embree");
  }
  std::future<std::unique_ptr<ClampGather>> gather;
  const bool overlap = compensate && glContext &&
                       (options.overlapCompensation > 0 ||
                        (options.overlapCompensation < 0 && !glContext->softwareRenderer()));
  if (overlap)
    gather = std::async(std::launch::async, [&inputs, co] { return std::make_unique<ClampGather>(inputs, co); });
  report["compensationOverlapped"] = overlap;
  r.maps = runBackend(backend, options, inputs, report, glContext.get());
  if (r.maps.size() != texels.size())
    throw Error(ErrorCode::InvalidData, s.sourcePath, "the backend returned " + std::to_string(r.maps.size()) +
                                                          " pages for " + std::to_string(texels.size()));
  for (size_t p = 0; p < r.maps.size(); ++p) {
    r.maps[p].page = static_cast<int>(p);
    if (r.maps[p].valid.size() != r.maps[p].size()) r.maps[p].valid = texels[p].valid;
  }
  seconds["backend"] = stage.seconds();

  // The sky's direct light, traced (every VPL backend; the reference integrator finds the sky itself).
  // Before the compensation, whose gather reads the map as the light leaving each surface.
  if (s.environment.present() && backend != BackendKind::Reference) {
    stage.reset();
    SkyLightOptions so = options.sky;
    so.seed = options.walk.seed;
    SkyLightStats ss;
    addSkyLight(inputs, r.maps, so, &ss);
    seconds["sky"] = stage.seconds();
    report["sky"] = {{"rays", ss.rays}, {"raysPerSample", ss.raysPerSample},
                     {"uniform", s.environment.isUniform()}, {"source", s.environment.source()},
                     {"integral", rgb(s.environment.integral())}};
  }

  if (compensate) {
    stage.reset();
    ClampCompensationStats cs;
    if (options.progress) options.progress("compensate", 0.0);  // coarse: start and end of the stage
    std::unique_ptr<ClampGather> g = gather.valid() ? gather.get() : std::make_unique<ClampGather>(inputs, co);
    g->apply(r.maps, &cs);
    if (options.progress) options.progress("compensate", 1.0);
    seconds["compensation"] = stage.seconds();  // with the GL backend: the sweeps (and any trace not yet done)
    seconds["compensationTrace"] = g->traceSeconds();
    report["compensation"] = {{"rays", cs.raysTraced},
                              {"samplesRefined", cs.samplesRefined},
                              {"hitsKept", cs.hitsKept},
                              {"addedFraction", cs.addedFraction},
                              {"raysPerSample", cs.raysPerSample},
                              {"filterRadius", cs.filterRadius},
                              {"sweeps", cs.sweeps}};
  }

  stage.reset();
  PostOptions post;
  post.dilate = options.postDilate;
  post.stitchSeams = options.postSeams;
  if (options.progress) options.progress("post", 0.0);
  PostStats postStats = postProcess(s, r.maps, post);
  if (options.progress) options.progress("post", 1.0);
  seconds["post"] = stage.seconds();
  seconds["bake"] = total.seconds();

  // The report: what was baked, how, how long, and where the energy went.
  size_t texelCount = 0, covered = 0, valid = 0;
  for (const auto& t : texels) {
    texelCount += t.layerSize();
    for (auto c : t.covered) covered += c != 0;
    for (auto v : t.valid) valid += v != 0;
  }
  nlohmann::json pages = nlohmann::json::array();
  for (const auto& pg : r.atlas.pages) pages.push_back({{"width", pg.width}, {"height", pg.height}});
  nlohmann::json perBounce = nlohmann::json::array();
  glm::dvec3 vplPower(0.0);
  for (size_t b = 0; b < r.vpls.countPerBounce.size(); ++b) {
    glm::dvec3 pw = b < r.vpls.powerPerBounce.size() ? r.vpls.powerPerBounce[b] : glm::dvec3(0.0);
    vplPower += pw;
    perBounce.push_back({{"bounce", b}, {"count", r.vpls.countPerBounce[b]}, {"power", rgb(pw)}});
  }
  report["backend"] = toString(backend);
  report["scene"] = {{"source", s.sourcePath},
                     {"triangles", s.triangleCount()},
                     {"primitives", s.primitives.size()},
                     {"lights", s.lights.size()},
                     {"emitterPower", rgb(glm::dvec3(s.emitterPower()))}};
  report["atlas"] = {{"pages", pages},
                     {"charts", r.atlas.stats.charts},
                     {"texelsPerUnit", r.atlas.stats.texelsPerUnit},
                     {"centreUtilisation", r.atlas.stats.centreUtilisation},
                     {"warnings", r.atlas.stats.warnings}};
  report["texels"] = {{"total", texelCount}, {"covered", covered}, {"valid", valid},
                      {"supersample", std::max(1, options.texels.supersample)},
                      {"leakControl", options.texels.leakControl}};
  report["vpls"] = {{"paths", options.walk.paths},
                    {"count", r.vpls.vpls.size()},
                    {"bounces", r.vpls.bounces},
                    {"meanReflectivity", r.vpls.meanReflectivity},
                    {"emittedPower", rgb(r.vpls.emittedPower)},
                    {"totalPower", rgb(vplPower)},
                    {"perBounce", perBounce},
                    {"seed", options.walk.seed}};
  report["eval"] = {{"clampBound", eval.clampBound},
                    {"clampVplsPerMean", clampK},
                    {"clampDerived", clampDerived},
                    {"biasCompensation", eval.biasCompensation}};
  if (backend == BackendKind::Reference) report["eval"]["referenceSpp"] = options.referenceSpp;
  report["post"] = {{"texelsFilled", postStats.texelsFilled},
                    {"seamEdges", postStats.seamEdges},
                    {"seamMismatchBefore", postStats.seamMismatchBefore},
                    {"seamMismatchAfter", postStats.seamMismatchAfter}};
  // Everything that differs between two runs of the same bake lives in "timings" (wall clock per stage,
  // the GL stage split, peak memory); the rest of the report is the same bytes every time.
  report["timings"]["seconds"] = seconds;
  report["timings"]["memoryPeakMiB"] = peakMemoryMiB();
  return r;
}

}  // namespace irbake
