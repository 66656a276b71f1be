// The bake, stage by stage, with the report the benchmarks and users read.
#include "pipeline/bake.h"

#include <sys/resource.h>

#include <cmath>
#include <future>
#include <memory>

#include <tbb/parallel_for.h>

#include "stages/compensation/clamp_compensation.h"
#include "stages/gather/final_gather.h"
#include "transport/geometry_term.h"
#include "transport/vpl_importance.h"
#include "evaluators/gl/gl_backend.h"
#include "stages/interleave/interleaved_sampling.h"
#include "glcontext/gl_context.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "evaluators/gl/shadow_views.h"
#include "common/maths.h"
#include "pipeline/evaluator_factory.h"
#include "post/post.h"
#include "raytrace/ray_tracer.h"

namespace irbake {
namespace {

nlohmann::json rgb(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

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

// The values an option holds when it is set must make sense: unset is "automatic", never a number.
void checkOptionRanges(const BakeOptions& o) {
  auto atLeast = [](const std::optional<int>& value, int lowest, const char* name) {
    if (value && *value < lowest)
      throw Error(ErrorCode::Usage, "", std::string(name) + " must be at least " + std::to_string(lowest) + " (got " +
                                            std::to_string(*value) + ")");
  };
  atLeast(o.interleave, 1, "interleave");
  atLeast(o.gl.cubeFaceSize, 1, "GL cube face size");
  atLeast(o.walk.maxBounces, 0, "bounce count");
  atLeast(o.compensation.filterRadius, 0, "compensation filter radius");
  if (o.directional && o.backend == BackendKind::Reference)  // the L1 pages come from the VPL backends' passes
    throw Error(ErrorCode::Usage, "", "--directional needs a VPL backend (gl, embree or auto), not reference");
  if (o.clamp == ClampMode::Fixed && !(o.clampBound > 0.0f))
    throw Error(ErrorCode::Usage, "", "a fixed clamp bound must be positive (got " + std::to_string(o.clampBound) +
                                          "; ClampMode::Off for no clamp)");
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

namespace {

// The evaluation flags each backend call gets, decided here once: VPL blocks evaluate the clamped VPL sum
// only, the direct call the punctual lights only, and no backend compensates the clamp (that is its own
// stage, stages/compensation, after either backend).
VplEvalOptions vplBlockEval(const VplEvalOptions& eval) {
  VplEvalOptions e = eval;
  e.includeDirect = false;
  e.biasCompensation = false;
  return e;
}
VplEvalOptions directEval(const VplEvalOptions& eval) {
  VplEvalOptions e = eval;
  e.includeVpls = false;
  e.biasCompensation = false;
  return e;
}

// A contiguous range of one interleave class's VPLs.
struct VplBlock {
  int vplClass = 0;
  size_t begin = 0, end = 0;
};

}  // namespace

struct StagedBake::State {
  BakeOptions options;
  Scene scene;
  AtlasResult atlas;
  std::unique_ptr<RayTracer> rayTracer;
  std::vector<TexelSamples> texels;
  VplSet vpls;
  VplEvalOptions eval;        // with the derived clamp
  double clampK = 0.0;
  bool clampDerived = false;
  double importanceFactor = 1.0;       // candidates per kept VPL of the importance selection (1: plain walk)
  VplImportanceStats importanceStats;
  BackendKind backend = BackendKind::Auto;
  std::string backendReason = "asked for";
  std::unique_ptr<GlContext> glContext;
  GlBackendOptions gl;        // with the cube face size fixed for every block
  int interleave = 1;
  std::vector<VplSet> classVpls;                    // per interleave class
  int pagesClass = -1;                     // the class classPages holds (blocks run class by class, so one
  std::vector<TexelSamples> classPages;    // class's texel copy at a time: 1/n² of the samples' memory)
  std::vector<VplBlock> blocks;
  GlBakeStats glStats;        // the GL evaluator adds every call's figures here (and a merge its shards' counts)
  std::unique_ptr<Evaluator> contactEvaluator;  // Embree: where the GL evaluator sends its contact texels
  std::unique_ptr<Evaluator> vplEvaluator;      // GL or Embree, made on the first call (after planBlocks)
  InterleaveStats interleaveStats;
  std::unique_ptr<FootprintAlbedo> footprintAlbedo;  // hit albedo for the compensation and the gather (one for both)
  std::unique_ptr<BakeInputs> wholeInputs;          // every page and VPL: the sky and the gather read them
  std::unique_ptr<SurfaceFilterCache> surfaceFilters;  // each page's neighbour tests, made once for all filters
  std::future<std::unique_ptr<ClampGather>> gather;  // traced while the GL backend bakes (GPU only)
  bool compensate = false, overlap = false;
  bool finalGatherOn = false;                       // decided with the backend (FinalGatherMode)
  std::vector<Lightmap> directMaps;                 // the final gather's D: punctual lights and sky, exact
  L1Pages directL1;                                 // with --directional: D's L1 pages
  nlohmann::json seconds = nlohmann::json::object();
  Stopwatch total;

  ProgressCallback withProgress(ProgressCallback cb) const { return cb ? cb : options.progress; }
  BakeInputs inputs(const std::vector<TexelSamples>& pages, const VplSet& set, const VplEvalOptions& e,
                    ProgressCallback progress = {}) const {
    return BakeInputs{scene, *rayTracer, pages, set, e, std::move(progress)};
  }

  // Each stage records its wall time under its name.
  template <class Stage>
  void timed(const char* name, Stage&& stage) {
    Stopwatch watch;
    stage();
    seconds[name] = seconds.value(name, 0.0) + watch.seconds();
  }

  void prepare() {
    timed("atlas", [&] {
      AtlasOptions o = options.atlas;
      o.progress = withProgress(o.progress);
      atlas = buildAtlas(scene, o);
    });
    timed("raytrace", [&] { rayTracer = std::make_unique<RayTracer>(scene); });
    timed("texels", [&] {
      TexelSampleOptions o = options.texels;
      o.progress = withProgress(o.progress);
      texels = buildTexelSamples(scene, *rayTracer, o);
    });
    // The backend first (the GL context is made here: its time counts to the backend, as it did): the
    // reference backend reads no VPLs, so it needs no VPL selection.
    timed("backend", [&] { chooseBackend(); });
    timed("vpls", [&] {
      WalkOptions o = walkOptions();
      o.progress = withProgress(o.progress);
      vpls = generateVpls(scene, *rayTracer, o);
      // Importance-driven selection: where the plain walk's VPLs matter unevenly (its pilot), the walk again
      // with f times the paths, then about the plain walk's count kept where they matter
      // (transport/vpl_importance.h).
      if (backend != BackendKind::Reference && options.eval.includeVpls && !vpls.vpls.empty()) {
        double evenness = 0.0;
        // auto: only under the final gather. Without it the selection thins the VPLs that light bright texels,
        // which costs a plain bake's close-ups more than it gives; under the final gather the close-ups hold
        // and the gallery's seed-to-seed swing goes (docs/units.md, "Importance-driven VPL selection").
        const bool pilot = !options.vplImportance.candidateFactor;  // auto; a fixed factor needs none
        if (!pilot || finalGatherOn) {
          if (pilot) {
            deriveClamp();
            evenness = vplImportanceEvenness(scene, *rayTracer, texels, vpls.vpls, options.vplImportance,
                                             eval.clampBound, options.walk.seed);
          }
          importanceFactor = chooseCandidateFactor(options.vplImportance, vpls.vpls.size(), evenness);
        }
        importanceStats.evenness = evenness;
      }
      if (importanceFactor > 1.0) {
        o.paths = static_cast<int>(std::min(double(1 << 26), std::round(o.paths * importanceFactor)));
        vpls = generateVpls(scene, *rayTracer, o);
      }
    });
    if (importanceFactor > 1.0)
      timed("vplImportance", [&] {
        deriveClamp();  // the candidates' bound: the kept set's is about 1/f of it (B ∝ VPL count)
        VplSelection selection;
        selection.keepFraction = options.vplImportance.keepShare / importanceFactor;
        selection.clampBound =
            clampDerived ? static_cast<float>(eval.clampBound * selection.keepFraction) : eval.clampBound;
        selection.seed = options.walk.seed;
        importanceStats.factor = importanceFactor;
        selectVplsByImportance(scene, *rayTracer, texels, vpls, options.vplImportance, selection, &importanceStats);
      });
    deriveClamp();
    // The gather keeps a reference to its inputs, so they live as long as the bake.
    wholeInputs = std::make_unique<BakeInputs>(inputs(texels, vpls, eval));
    surfaceFilters = std::make_unique<SurfaceFilterCache>(texels);
    wholeInputs->surfaceFilters = surfaceFilters.get();
    if (compensate || finalGatherOn) {
      footprintAlbedo = std::make_unique<FootprintAlbedo>(scene);
      wholeInputs->footprintAlbedo = footprintAlbedo.get();
    }
    timed("backend", [&] { planBlocks(); });
  }

  // The walk as this bake runs it: finalGatherPaths where the final gather runs (decided with the backend).
  WalkOptions walkOptions() const {
    WalkOptions o = options.walk;
    if (finalGatherOn && options.finalGatherPaths) o.paths = *options.finalGatherPaths;
    return o;
  }

  void deriveClamp() {
    eval = options.eval;
    if (options.clamp != ClampMode::Derived) {
      eval.clampBound = options.clamp == ClampMode::Fixed ? options.clampBound : 0.0f;
      return;
    }
    clampK = options.clampVplsPerMean > 0.0 ? options.clampVplsPerMean
             : !eval.biasCompensation     ? kClampVplsPerMean
             : scene.hasEmissiveSurface() ? kCompensatedClampVplsPerMean
                                          : kCompensatedClampVplsPerMeanNoEmitters;
    eval.clampBound = deriveClampBound(scene, vpls, clampK);
    clampDerived = true;
  }

  // --backend auto: GL where it is both right and fast, Embree otherwise (the choice and why in the report).
  void chooseBackend() {
    backend = options.backend;
    if (backend == BackendKind::Auto) {
      const AutoBackendChoice choice =
          chooseAutoBackend(scene.triangleCount(), seeThroughMaterials(scene), [&] {
            GlProbe probe;
            try {
              glContext = std::make_unique<GlContext>();
              probe.softwareRenderer = glContext->softwareRenderer();
            } catch (const Error& e) {
              probe.error = e.what();
            }
            return probe;
          });
      backend = choice.backend;
      backendReason = choice.reason;
      if (backend != BackendKind::Gl) glContext.reset();
      log::info(std::string("backend auto: ") + toString(backend) + " (" + backendReason + ")");
    }
    compensate = options.eval.biasCompensation && backend != BackendKind::Reference;
    finalGatherOn = backend != BackendKind::Reference && options.eval.includeVpls &&
                    (options.finalGather == FinalGatherMode::On ||
                     (options.finalGather == FinalGatherMode::Auto && !scene.hasEmissiveSurface() &&
                      seeThroughMaterials(scene).empty()));
    if (options.finalGather != FinalGatherMode::Off)
      log::info(std::string("final gather: ") + (finalGatherOn ? "on" : "off"));
    if (backend != BackendKind::Gl) return;
    if (!glContext) glContext = std::make_unique<GlContext>();
    log::info("GL backend: " + glContext->description());
    // On a CPU rasteriser the shadow pass costs every triangle once per VPL cube face (docs/validation.md).
    if (glContext->softwareRenderer() && scene.triangleCount() > kGlTriangleHint && options.eval.includeVpls)
      log::warn("GL backend on a software renderer with " + std::to_string(scene.triangleCount()) +
                " triangles: its shadow pass draws them for every VPL cube (on the 2-core bench machine the Embree "
                "backend baked a 58k-triangle room 4-17x faster); consider --backend embree");
    // The compensation's rays read the geometry only, so with the GL backend on a GPU they are traced on the
    // CPU while it bakes. Not on llvmpipe: the trace and the rasteriser threads share the same cores, and
    // the rasteriser waits for its slowest thread.
    overlap = compensate && (options.overlapCompensation == OverlapCompensation::Always ||
                             (options.overlapCompensation == OverlapCompensation::Auto &&
                              !glContext->softwareRenderer()));
  }

  // Interleave classes and the fixed blocks of each class's VPLs: the units shards and checkpoints split.
  void planBlocks() {
    if (backend == BackendKind::Reference || !eval.includeVpls || vpls.vpls.empty()) return;
    interleave = options.interleave ? *options.interleave : chooseInterleave(texels, eval.clampBound, surfaceFilters.get());
    classVpls = classVplSubsets(vpls, interleave);
    const size_t blockSize = static_cast<size_t>(std::max(1, options.vplBlock));
    for (size_t c = 0; c < classVpls.size(); ++c)
      for (size_t b0 = 0; b0 < classVpls[c].vpls.size(); b0 += blockSize)
        blocks.push_back({static_cast<int>(c), b0, std::min(classVpls[c].vpls.size(), b0 + blockSize)});
    gl = options.gl;
    if (backend == BackendKind::Gl && !gl.cubeFaceSize)  // once for every block, from the first class
      gl.cubeFaceSize = chooseCubeFaceSize(vpls.vpls, pagesOf(0), eval.clampBound, gl.cubeFootprintPerTexel,
                                           gl.minCubeFaceSize, gl.maxCubeFaceSize)
                            .size;
    interleaveStats.classes = static_cast<int>(classVpls.size());
  }

  // The texel samples of an interleave class as pages of their own (interleave 1: the pages themselves).
  const std::vector<TexelSamples>& pagesOf(int vplClass) {
    if (interleave <= 1) return texels;
    if (pagesClass != vplClass) {
      classPages = interleaveClass(texels, interleave, vplClass % interleave, vplClass / interleave);
      pagesClass = vplClass;
    }
    return classPages;
  }

  // One call of the GL or Embree evaluator; with l1, the same pass also gives the L1 pages (--directional).
  std::vector<Lightmap> runVplBackend(const BakeInputs& in, L1Pages* l1 = nullptr) {
    if (!vplEvaluator) {
      EvaluatorSettings settings;
      settings.gl = gl;
      settings.gl.context = glContext.get();
      settings.gl.stats = &glStats;
      if (backend == BackendKind::Gl) contactEvaluator = makeEvaluator(BackendKind::Embree);
      vplEvaluator = makeEvaluator(backend, settings, contactEvaluator.get());
    }
    EvaluationRequest request;
    request.directional = l1;
    std::vector<Lightmap> maps = vplEvaluator->evaluate(in, request);
    ++interleaveStats.backendCalls;
    return maps;
  }

  // RGB triples per texel in the exact sums: the map, and the three L1 pages with --directional.
  int coefficients() const { return options.directional ? 1 + 3 : 1; }

  void evaluateBlock(size_t index, ExactVplSums& sums, ProgressCallback progress) {
    const VplBlock& block = blocks[index];
    const VplSet& classSet = classVpls[static_cast<size_t>(block.vplClass)];
    VplSet set;
    set.meanReflectivity = classSet.meanReflectivity;
    set.bounces = classSet.bounces;
    set.emittedPower = classSet.emittedPower;
    set.vpls.assign(classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.begin),
                    classSet.vpls.begin() + static_cast<std::ptrdiff_t>(block.end));
    const std::vector<TexelSamples>& pages = pagesOf(block.vplClass);
    L1Pages l1;
    const std::vector<Lightmap> maps =
        runVplBackend(inputs(pages, set, vplBlockEval(eval), std::move(progress)), options.directional ? &l1 : nullptr);
    const int n = interleave, cx = block.vplClass % n, cy = block.vplClass / n;
    for (size_t p = 0; p < maps.size() && p < texels.size(); ++p) {
      const Lightmap& m = maps[p];
      const int fullWidth = texels[p].width;
      for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
          const size_t ct = static_cast<size_t>(y) * m.width + x;
          if (ct >= m.valid.size() || !m.valid[ct]) continue;
          const size_t t = static_cast<size_t>(n * y + cy) * fullWidth + (n * x + cx);
          glm::vec3 value[ExactVplSums::kMaxCoefficients] = {m.texels[ct]};  // L0, then L1x, L1y, L1z
          if (options.directional)
            for (int k = 0; k < 3; ++k) value[1 + k] = l1[k][p].texels[ct];
          if (!sums.add(p, t, value))
            throw Error(ErrorCode::NumericError, scene.sourcePath,
                        "VPL block " + std::to_string(index) + " gave a non-finite or absurd value (≥ 2^40) at page " +
                            std::to_string(p) + " texel " + std::to_string(t % fullWidth) + "," +
                            std::to_string(t / fullWidth));
        }
    }
  }

  // Punctual lights on every texel, exact and unfiltered (blank valid pages when there are none); with l1,
  // their L1 pages too.
  std::vector<Lightmap> directStage(L1Pages* l1) {
    if (eval.includeDirect && !scene.lights.empty()) {
      const VplSet none;
      return runVplBackend(inputs(texels, none, directEval(eval)), l1);
    }
    std::vector<Lightmap> maps;
    for (const TexelSamples& ts : texels) {
      maps.push_back(blankLightmap(ts));
      maps.back().valid = ts.valid;
    }
    if (l1)
      for (auto& axis : *l1) axis = maps;
    return maps;
  }

  std::vector<Lightmap> referenceStage(nlohmann::json& report) {
    EvaluatorSettings settings;
    settings.reference.spp = options.referenceSpp;
    settings.reference.seed = options.walk.seed;
    const std::unique_ptr<Evaluator> reference = makeEvaluator(BackendKind::Reference, settings);
    std::vector<Lightmap> maps = reference->evaluate(inputs(texels, vpls, eval));
    report["reference"] = reference->stats();  // its paths per sample and how converged it is
    return maps;
  }

  // The backend stage's result: punctual lights plus the VPL sums, classes mixed (or the reference). With
  // l1 (--directional) the L1 pages alike, each coefficient mixed on its own. Each page's sums are freed
  // once rounded: with four coefficients they are the largest thing alive here.
  std::vector<Lightmap> backendMaps(ExactVplSums& sums, nlohmann::json& report, L1Pages* l1) {
    if (backend == BackendKind::Reference) return referenceStage(report);
    std::vector<Lightmap> maps = directStage(l1);
    if (maps.size() != texels.size() || (l1 && (*l1)[0].size() != texels.size()))
      throw Error(ErrorCode::InvalidData, scene.sourcePath, "the backend returned " + std::to_string(maps.size()) +
                                                                " pages for " + std::to_string(texels.size()));
    if (eval.includeDirect && !scene.lights.empty() && options.shadowEdges.subSamples > 1) {
      // On the punctual lights alone, before D is kept for the final gather: its sources see the same edges.
      // The L1 pages keep the centre's direction, scaled with the value per channel so that |L1| stays within
      // what L0 allows (a refined texel's light comes from the same lights; where the centre was dark, L1 is 0).
      std::vector<Lightmap> before;
      if (l1) before = maps;
      const ShadowEdgeStats st = refineShadowEdges(*wholeInputs, maps, options.shadowEdges);
      for (size_t p = 0; l1 && p < maps.size(); ++p)
        for (size_t t = 0; t < maps[p].size(); ++t) {
          const glm::vec3 &was = before[p].texels[t], &now = maps[p].texels[t];
          if (was == now) continue;
          const glm::vec3 scale(was.x > 0.0f ? now.x / was.x : 0.0f, was.y > 0.0f ? now.y / was.y : 0.0f,
                                was.z > 0.0f ? now.z / was.z : 0.0f);
          for (int k = 0; k < 3; ++k) (*l1)[k][p].texels[t] *= scale;
        }
      seconds["shadowEdges"] = st.seconds;
      report["shadowEdges"] = {{"subSamples", options.shadowEdges.subSamples}, {"edgeTexels", st.edgeTexels},
                               {"subPoints", st.subPoints}, {"droppedInside", st.droppedInside}};
    }
    if (finalGatherOn) {
      directMaps = maps;
      for (size_t p = 0; p < directMaps.size(); ++p)
        if (directMaps[p].valid.size() != directMaps[p].size()) directMaps[p].valid = texels[p].valid;
      if (l1) directL1 = *l1;
    }
    const int coefficients = l1 ? sums.coefficients : 1;
    for (size_t p = 0; p < maps.size(); ++p) {
      std::vector<Lightmap*> pages;  // this page's map, then its L1 pages
      for (int c = 0; c < coefficients; ++c) {
        Lightmap& map = c == 0 ? maps[p] : (*l1)[c - 1][p];
        map.page = static_cast<int>(p);
        if (map.valid.size() != map.size()) map.valid = texels[p].valid;
        pages.push_back(&map);
      }
      if (blocks.empty()) continue;
      std::vector<std::vector<glm::vec3>> vplParts(coefficients, std::vector<glm::vec3>(texels[p].layerSize()));
      std::vector<const std::vector<glm::vec3>*> parts;
      for (int c = 0; c < coefficients; ++c) {
        tbb::parallel_for(size_t(0), vplParts[c].size(), [&](size_t t) { vplParts[c][t] = sums.value(p, t, c); });
        parts.push_back(&vplParts[c]);
      }
      std::vector<uint8_t> vplValid = std::move(sums.pages[p].valid);
      sums.pages[p] = {};
      addMixedClasses(texels[p], interleave, parts, vplValid, pages, surfaceFilters.get());
    }
    return maps;
  }

  // The clamp compensation's options as this bake runs it. With the final gather its refinement is off: the
  // extra rays sharpen the residual at the texel itself, which the final gather replaces; only the map it
  // reads one bounce away needs the residual (Sponza views 2 / 3: 1.92 / 4.55% without, 1.92 / 4.56% with).
  // For the same reason a large page's samples may get 2 first rays instead of 4: the gather reads the
  // residual averaged over its rays and its window (Sponza: 6.0 -> 4.2 s, peak 850 -> 758 MiB; views 2 / 3
  // 1.56 / 2.73% -> 1.55 / 2.71%; 1 ray: 1.60 / 2.98%).
  ClampCompensationOptions compensationOptions() const {
    ClampCompensationOptions o = options.compensation;
    o.seed = options.walk.seed;
    o.directional = options.directional && !finalGatherOn;  // the gather writes the bounced light's L1 itself
    if (finalGatherOn) {
      o.refineRays = 0;
      o.minRays = std::min(o.minRays, 2);
      o.filterEachSweep = false;
    }
    return o;
  }

  SkyLightOptions skyOptions() const {
    SkyLightOptions o = options.sky;
    o.seed = options.walk.seed;
    // The gather counts a uniform sky at every texel itself; this stage's light is then read only at its hits,
    // averaged over a hemisphere of them, so half the rays do (Sponza: sky 2.6 -> 1.4 s, views unchanged).
    if (skyByGather()) o.minRays = std::min(o.minRays, 4);
    return o;
  }
  PostOptions postOptions() const {
    PostOptions o;
    o.dilate = options.postDilate;
    o.stitchSeams = options.postSeams;
    return o;
  }

  // The sky's direct light, traced (every VPL backend; the reference integrator finds the sky itself).
  // Before the compensation, whose gather reads the map as the light leaving each surface.
  void skyStage(std::vector<Lightmap>& maps, nlohmann::json& report) {
    if (!scene.environment.present() || backend == BackendKind::Reference) return;
    timed("sky", [&] {
      SkyLightStats stats;
      if (finalGatherOn && directMaps.size() == maps.size() && !skyByGather()) {
        // An environment map's light goes into D as well (its importance sampling beats the gather's cosine
        // rays): traced once into blank pages, added to both. A uniform sky stays out of D: the final
        // gather's rays that leave the scene count it (finalGatherStage).
        std::vector<Lightmap> sky = maps;
        for (Lightmap& m : sky) std::fill(m.texels.begin(), m.texels.end(), glm::vec3(0.0f));
        addSkyLight(*wholeInputs, sky, skyOptions(), &stats);
        for (size_t p = 0; p < maps.size(); ++p)
          for (size_t t = 0; t < maps[p].size(); ++t) {
            maps[p].texels[t] += sky[p].texels[t];
            directMaps[p].texels[t] += sky[p].texels[t];
          }
      } else {
        addSkyLight(*wholeInputs, maps, skyOptions(), &stats);
      }
      report["sky"] = stats.toJson();
      report["sky"]["uniform"] = scene.environment.isUniform();
      report["sky"]["source"] = scene.environment.source();
      report["sky"]["integral"] = rgb(scene.environment.integral());
    });
  }

  // Bias compensation: the clamp's lost near-field light gathered back from the baked map.
  // With l1 (--directional) the residual's irradiance vector goes into the L1 pages too.
  void compensationStage(std::vector<Lightmap>& maps, L1Pages* l1, nlohmann::json& report) {
    if (!compensate) return;
    timed("compensation", [&] {  // with an overlapped trace: the sweeps (and any trace not yet done)
      const ClampCompensationOptions o = compensationOptions();
      ClampCompensationStats stats;
      if (options.progress) options.progress("compensate", 0.0);  // coarse: start and end of the stage
      std::unique_ptr<ClampGather> g = gather.valid() ? gather.get() : std::make_unique<ClampGather>(*wholeInputs, o);
      g->apply(maps, &stats);
      if (l1 && !finalGatherOn) g->applyDirectional(maps, *l1);
      if (options.progress) options.progress("compensate", 1.0);
      seconds["compensationTrace"] = g->traceSeconds();
      report["compensation"] = stats.toJson();
    });
  }

  // Directional maps after the backend stage, whose passes accumulated the L1 pages of the punctual lights
  // and VPLs beside the map (and the exact sums mixed them per coefficient): the sky's part traced again
  // (addSkyLightDirectional), then post per axis. The clamp compensation added its own share before
  // (ClampGather::applyDirectional).
  void directionalStage(L1Pages& axes, nlohmann::json& report) {
    if (!options.directional) return;
    timed("directional", [&] {
      if (scene.environment.present()) addSkyLightDirectional(*wholeInputs, axes, skyOptions());
      PostStats stats;
      for (auto& pages : axes) stats = postProcess(scene, pages, postOptions());
      report["directional"] = {{"pages", axes[0].size() * 3}, {"seamMismatchAfter", stats.seamMismatchAfter}};
    });
  }

  // Whether the final gather's rays that leave the scene count the sky, which then stays out of D: a uniform
  // sky (its cosine rays are the sky stage's own estimator) in a scene without see-through surfaces (the
  // gather's closest hits stop at glass, where the sky stage's rays pass with its transmittance).
  bool skyByGather() const {
    return finalGatherOn && scene.environment.present() && scene.environment.isUniform() && !rayTracer->hasTransmission();
  }

  // Final gather: each texel's bounced light read from the finished map one bounce away (stages/gather).
  // With l1 (--directional) the L1 pages become D's plus the same rays' tangential vector.
  void finalGatherStage(std::vector<Lightmap>& maps, L1Pages* l1, nlohmann::json& report) {
    if (!finalGatherOn || directMaps.size() != maps.size()) return;
    timed("finalGather", [&] {
      FinalGatherOptions o = options.gather;
      o.seed = options.walk.seed;
      if (skyByGather()) o.missRadiance = scene.environment.uniformRadiance();
      FinalGatherStats stats;
      if (options.progress) options.progress("gather", 0.0);
      finalGather(*wholeInputs, directMaps, maps, o, &stats, l1 ? &directL1 : nullptr, l1);
      if (options.progress) options.progress("gather", 1.0);
      report["finalGather"] = stats.toJson();
    });
    directMaps = {};
    directL1 = {};
  }

  PostStats postStage(std::vector<Lightmap>& maps) {
    PostStats stats;
    timed("post", [&] {
      if (options.progress) options.progress("post", 0.0);
      stats = postProcess(scene, maps, postOptions());
      if (options.progress) options.progress("post", 1.0);
    });
    return stats;
  }

  // What was baked and how: each stage's stats as its own object.
  void describe(nlohmann::json& report, const PostStats& post) const {
    size_t texelCount = 0, covered = 0, valid = 0;
    for (const auto& t : texels) {
      texelCount += t.layerSize();
      for (auto c : t.covered) covered += c != 0;
      for (auto v : t.valid) valid += v != 0;
    }
    report["backendChoice"] = {{"asked", toString(options.backend)}, {"used", toString(backend)}, {"reason", backendReason}};
    report["compensationOverlapped"] = overlap;
    report["backend"] = toString(backend);
    if (backend == BackendKind::Gl) {
      report["renderer"] = glStats.renderer;
      report["gl"] = glStats.toJson();
      report["timings"]["gl"] = glStats.timingsJson();
    }
    if (backend != BackendKind::Reference) {
      report["interleave"] = interleaveStats.toJson();
      report["interleave"]["vplBlocks"] = blocks.size();
      report["interleave"]["vplsPerBlock"] = options.vplBlock;
    }
    report["scene"] = {{"source", scene.sourcePath},
                       {"triangles", scene.triangleCount()},
                       {"primitives", scene.primitives.size()},
                       {"lights", scene.lights.size()},
                       {"emitterPower", rgb(glm::dvec3(scene.emitterPower()))}};
    report["atlas"] = atlas.toJson();
    report["texels"] = {{"total", texelCount}, {"covered", covered}, {"valid", valid},
                        {"supersample", std::max(1, options.texels.supersample)},
                        {"leakControl", options.texels.leakControl}};
    report["vpls"] = vpls.toJson();
    report["vpls"]["paths"] = walkOptions().paths;
    report["vpls"]["seed"] = options.walk.seed;
    if (importanceFactor > 1.0 || importanceStats.evenness > 0.0) report["vplImportance"] = importanceStats.toJson();
    report["eval"] = {{"clampBound", eval.clampBound},
                      {"clampVplsPerMean", clampK},
                      {"clampDerived", clampDerived},
                      {"biasCompensation", eval.biasCompensation}};
    if (backend == BackendKind::Reference) report["eval"]["referenceSpp"] = options.referenceSpp;
    report["post"] = post.toJson();
  }
};

StagedBake::StagedBake(Scene scene, const BakeOptions& options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = options;
  s.scene = std::move(scene);
  if (s.scene.triangleCount() == 0) throw Error(ErrorCode::EmptyScene, s.scene.sourcePath, "no triangles to bake");
  checkOptionRanges(options);
  s.prepare();
}

StagedBake::~StagedBake() = default;

size_t StagedBake::blockCount() const { return state_->blocks.size(); }
BackendKind StagedBake::backend() const { return state_->backend; }

ExactVplSums StagedBake::emptySums() const {
  // Receivers: the texels a backend can return valid (GL and Embree keep the samples' valid flags).
  std::vector<std::vector<uint8_t>> receivers;
  for (const TexelSamples& ts : state_->texels)
    receivers.push_back(ts.valid.size() == ts.layerSize() ? ts.valid : std::vector<uint8_t>(ts.layerSize(), 1));
  return ExactVplSums::zeros(receivers, state_->coefficients());
}

void StagedBake::evaluateBlocks(size_t begin, size_t end, ExactVplSums& sums,
                                const std::function<void(size_t next)>& afterBlock) {
  State& s = *state_;
  end = std::min(end, s.blocks.size());
  if (s.overlap && !s.gather.valid() && begin == 0 && end == s.blocks.size()) {
    const ClampCompensationOptions o = s.compensationOptions();
    // The gather reads the pages' texel samples and the geometry only: it runs while the GL backend bakes.
    s.gather = std::async(std::launch::async, [&s, o] { return std::make_unique<ClampGather>(*s.wholeInputs, o); });
  }
  s.timed("backend", [&] {
    for (size_t b = begin; b < end; ++b) {
      ProgressCallback progress;
      if (s.options.progress) {
        const double count = static_cast<double>(std::max<size_t>(1, end - begin));
        progress = [&s, b, begin, count](const char* stage, double f) {
          s.options.progress(stage, (static_cast<double>(b - begin) + std::clamp(f, 0.0, 1.0)) / count);
        };
      }
      s.evaluateBlock(b, sums, progress);
      if (afterBlock) afterBlock(b + 1);
    }
  });
}

nlohmann::json StagedBake::backendCounts() const {
  nlohmann::json counts = state_->glStats.toJson();
  counts["texelsEvaluated"] = state_->glStats.texelsEvaluated;
  counts["backendCalls"] = state_->interleaveStats.backendCalls;
  return counts;
}

void StagedBake::addBackendCounts(const nlohmann::json& counts) {
  state_->glStats.addCounts(counts);
  state_->interleaveStats.backendCalls += counts.value("backendCalls", 0);
}

BakeResult StagedBake::finish(ExactVplSums sums) {
  State& s = *state_;
  BakeResult r;
  nlohmann::json& report = r.report;
  s.classPages = {};
  s.timed("backend", [&] { r.maps = s.backendMaps(sums, report, s.options.directional ? &r.directional : nullptr); });
  sums = {};  // rounded into the maps (freed page by page already): not needed at the peak (compensation)
  s.skyStage(r.maps, report);
  s.compensationStage(r.maps, s.options.directional ? &r.directional : nullptr, report);
  s.finalGatherStage(r.maps, s.options.directional ? &r.directional : nullptr, report);
  report["surfaceFilters"] = {{"plans", s.surfaceFilters->plansMade()}, {"fallbacks", s.surfaceFilters->fallbacks()}};
  s.directionalStage(r.directional, report);
  const PostStats post = s.postStage(r.maps);
  s.seconds["bake"] = s.total.seconds();
  s.describe(report, post);
  // Everything that differs between two runs of the same bake lives in "timings" (wall clock per stage,
  // the GL stage split, peak memory); the rest of the report is the same bytes every time.
  report["timings"]["seconds"] = s.seconds;
  report["timings"]["memoryPeakMiB"] = peakMemoryMiB();
  r.atlas = std::move(s.atlas);
  r.vpls = std::move(s.vpls);
  s.gather = {};
  s.wholeInputs.reset();
  s.rayTracer.reset();  // it refers to the scene, which moves into the result
  r.scene = std::move(s.scene);
  return r;
}

BakeResult bake(Scene scene, const BakeOptions& options) {
  StagedBake staged(std::move(scene), options);
  ExactVplSums sums = staged.emptySums();
  staged.evaluateBlocks(0, staged.blockCount(), sums);
  return staged.finish(std::move(sums));
}

}  // namespace irbake
