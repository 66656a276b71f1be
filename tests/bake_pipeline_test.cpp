// End-to-end bakes through the pipeline in-process (Embree backend): the furnace's closed form and
// the thin wall's darkness, with every stage (atlas, texels, walk, backend, post) in the loop.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/exr_io.h"
#include "pipeline/bake.h"
#include "raytrace/ray_tracer.h"
#include "scene/environment.h"
#include "scene/gltf_loader.h"
#include "samples/sample_scenes.h"
#include "texels/texel_samples.h"
#include "transport/geometry_term.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
// The sample scenes, written once by `irbake samples` into the build folder.
fs::path samplesDir() {
  static fs::path dir = [] {
    fs::path d = fs::current_path() / "test_scratch" / "bake_pipeline_samples";
    fs::create_directories(d);
    std::string cmd = std::string("\"") + IRBAKE_EXE + "\" samples \"" + d.string() + "\" --quiet";
    if (std::system(cmd.c_str()) != 0) return fs::path();
    return d;
  }();
  return dir;
}

Scene loadSample(const std::string& name) {
  fs::path dir = samplesDir();
  if (dir.empty()) throw std::runtime_error("irbake samples failed");
  return loadScene(dir / (name + ".gltf"));
}

BakeOptions smallEmbreeBake(float texelsPerUnit, int paths) {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = texelsPerUnit;
  o.walk.paths = paths;
  o.walk.seed = 7;
  return o;
}

// Area-weighted mean over the valid texels of one class (selected by position and normal).
struct TexelClassMean {
  double sum = 0.0, weight = 0.0;
  size_t count = 0;
  double mean() const { return weight > 0 ? sum / weight : 0.0; }
};
}  // namespace

TEST(BakePipeline, FurnaceMatchesTheClosedFormWithBiasCompensation) {
  // Closed cube, ρ = 0.5, Le = 1 on every wall: every texel sees L = Le/(1−ρ) = 2 (all bounces).
  BakeOptions o = smallEmbreeBake(8.0f, 1024);
  o.eval.biasCompensation = true;
  BakeResult r = bake(loadSample("furnace"), o);
  ASSERT_FALSE(r.maps.empty());
  double sum = 0.0, maxDev = 0.0;
  size_t n = 0;
  for (const auto& m : r.maps)
    for (size_t i = 0; i < m.size(); ++i) {
      if (!m.valid[i]) continue;
      double v = (m.texels[i].x + m.texels[i].y + m.texels[i].z) / 3.0;
      ASSERT_TRUE(std::isfinite(v));
      sum += v;
      maxDev = std::max(maxDev, std::abs(v - 2.0) / 2.0);
      ++n;
    }
  ASSERT_GT(n, 1000u);
  double mean = sum / n;
  RecordProperty("furnace_mean", std::to_string(mean));
  RecordProperty("furnace_max_relative_deviation", std::to_string(maxDev));
  std::printf("furnace rho 0.5: mean %.5f (exact 2), %zu texels, max relative deviation %.4f\n", mean, n, maxDev);
  EXPECT_NEAR(mean, 2.0, 0.02);
  // The report accounts for the walk: VPL power = emitted × Σ ρ̄^j, so with ρ̄ = 0.5 below 2× emitted.
  const auto& vp = r.report["vpls"];
  EXPECT_GT(vp["count"].get<size_t>(), 1024u);
  double emitted = vp["emittedPower"][0].get<double>(), total = vp["totalPower"][0].get<double>();
  EXPECT_GT(total, emitted);
  EXPECT_LT(total, 2.0 * emitted * 1.0001);
  EXPECT_EQ(r.report["backend"], "embree");
  EXPECT_TRUE(r.report["eval"]["biasCompensation"].get<bool>());
}

// The default bake (GL backend, k = 1024 clamp: emitters cover the surface, compensation gather, automatic
// interleaving) and the same with 2×2 interleaving forced: the furnace's mean within 1% of Le/(1−ρ) = 2, and
// the report says what ran.
TEST(BakePipeline, DefaultGlBakeOfTheFurnaceIsWithinOnePercent) {
  for (int interleave : {0, 2}) {  // 0: automatic
    BakeOptions o;
    o.atlas.texelsPerUnit = 12.0f;
    o.walk.paths = 1024;
    if (interleave > 0) o.interleave = interleave;
    BakeResult r = bake(loadSample("furnace"), o);
    double sum = 0.0;
    size_t n = 0;
    for (const auto& m : r.maps)
      for (size_t i = 0; i < m.size(); ++i)
        if (m.valid[i]) sum += m.texels[i].x, ++n;
    ASSERT_GT(n, 1000u);
    std::printf("default GL furnace, interleave %d: mean %.5f (exact 2), %zu texels, gather added %.2f%%\n", interleave,
                sum / n, n, 100 * r.report["compensation"]["addedFraction"].get<double>());
    EXPECT_NEAR(sum / n, 2.0, 0.02) << "interleave " << interleave;
    EXPECT_EQ(r.report["backend"], "gl");
    EXPECT_EQ(r.report["eval"]["clampVplsPerMean"].get<double>(), 1024.0);  // no small emitters
    EXPECT_GT(r.report["compensation"]["addedFraction"].get<double>(), 0.02);  // the tight clamp really bit
    if (interleave == 2) {
      EXPECT_EQ(r.report["interleave"]["classes"].get<int>(), 4);
    }
  }
}

// High albedo with default options (only the texel density lowered to keep the test short:
// the mean does not depend on it). The walk follows the light up to its VPL budget and adds the rest as a
// geometric tail (docs/units.md, "Bounce depth"): a fixed bounce count would lose most of the light at ρ = 0.99.
TEST(BakePipeline, HighAlbedoFurnacesWithDefaultOptionsOnBothBackends) {
  for (float rho : {0.9f, 0.99f})
    for (BackendKind backend : {BackendKind::Gl, BackendKind::Embree}) {
      BakeOptions o;
      o.backend = backend;
      o.atlas.texelsPerUnit = 12.0f;
      const float Le = 1.0f - rho;  // exact map Le/(1−ρ) = 1
      BakeResult r = bake(samples::makeFurnace(rho, Le), o);
      double sum = 0.0, worst = 0.0;
      size_t n = 0;
      for (const auto& m : r.maps)
        for (size_t i = 0; i < m.size(); ++i)
          if (m.valid[i]) {
            const double v = (m.texels[i].x + m.texels[i].y + m.texels[i].z) / 3.0;
            sum += v;
            worst = std::max(worst, std::abs(v - 1.0));
            ++n;
          }
      ASSERT_GT(n, 1000u);
      const double mean = sum / n;
      std::printf("[ figure ] furnace rho %.2f %s, defaults: mean %.5f (exact 1), worst texel %+.2f%%, %d bounces, "
                  "%zu VPLs, tail factor %.2f\n",
                  rho, toString(backend), mean, 100 * worst, r.report["vpls"]["bounces"].get<int>(),
                  r.report["vpls"]["count"].get<size_t>(), r.vpls.tailFactor.x);
      EXPECT_NEAR(mean, 1.0, rho < 0.95f ? 0.01 : 0.03) << "rho " << rho << " " << toString(backend);
    }
}

// Corners and edges of the white furnace (ρ = 0.9, Le = 0.1: map 1 everywhere) at the command's defaults, the
// final gather included (auto: emitters cover the surface), on both backends: every texel, those along the
// edges and in the corners included, within 1.5% of 1 and the 99th percentile within 1%. The default bake's
// proportions on a budget of seconds: its 3072 paths and one 1024² page become 512 paths and a 418² page (1/6
// of each), which keeps the texel spacing against the clamp radius, and with it the automatic 6×6 interleave.
// Emitters that cover the surface are no small emitters, so the clamp is the tight one (k = 1024): the VPLs
// within a corner's clamp radius, whose count was its noise, hand their light to the compensation.
TEST(BakePipeline, FurnaceCornersAndEdgesAtDefaults) {
  for (BackendKind backend : {BackendKind::Gl, BackendKind::Embree}) {
    BakeOptions o;
    o.backend = backend;
    o.finalGather = FinalGatherMode::Auto;
    o.walk.paths = 512;
    o.atlas.targetPageSize = 418;  // texelsPerUnit left automatic
    BakeResult r = bake(samples::makeFurnace(0.9f, 0.1f), o);
    ASSERT_TRUE(r.report.contains("finalGather"));
    EXPECT_EQ(r.report["plan"]["clamp-k"]["value"].get<double>(), 1024.0) << toString(backend);
    EXPECT_EQ(r.report["plan"]["interleave"]["value"].get<int>(), 6) << toString(backend);
    std::vector<double> deviation;
    for (const auto& m : r.maps)
      for (size_t i = 0; i < m.size(); ++i)
        if (m.valid[i]) deviation.push_back(std::abs(channelMean(m.texels[i]) - 1.0));
    ASSERT_GT(deviation.size(), 100000u);
    std::sort(deviation.begin(), deviation.end());
    const double p99 = deviation[deviation.size() * 99 / 100], worst = deviation.back();
    std::printf("[ figure ] furnace rho 0.9 %s, defaults at 1/6 scale: %zu texels, %.1f texels/m, p99 |map - 1| %.2f%%, "
                "worst %.2f%%\n",
                toString(backend), deviation.size(), r.report["plan"]["texels-per-unit"]["value"].get<double>(), 100 * p99,
                100 * worst);
    EXPECT_LE(p99, 0.01) << toString(backend);     // k = 256: 1.28%
    EXPECT_LE(worst, 0.015) << toString(backend);  // k = 256: 2.58%
  }
}

// A uniform sky over an open plane gives map = L on every backend and with the final gather, which
// counts the sky with its own rays (its bounces cannot reach the plane again); a plane under a box's overhang gets less, the same on GL and Embree.
TEST(BakePipeline, UniformSkyOverAnOpenPlaneOnEveryBackend) {
  for (int run = 0; run < 4; ++run) {  // GL, Embree, reference, and Embree with the final gather (the sky its misses)
    const BackendKind backend = run == 0 ? BackendKind::Gl : run == 2 ? BackendKind::Reference : BackendKind::Embree;
    Scene s = samples::makePointOverPlane();
    s.lights.clear();
    s.environment = Environment::uniform({0.5f, 0.7f, 1.0f});
    BakeOptions o;
    o.backend = backend;
    if (run == 3) o.finalGather = FinalGatherMode::On;
    o.atlas.texelsPerUnit = 3.0f;
    o.walk.paths = 256;
    o.referenceSpp = 16;
    BakeResult r = bake(std::move(s), o);
    glm::dvec3 sum(0.0), worst(0.0);
    size_t n = 0;
    for (const auto& m : r.maps)
      for (size_t i = 0; i < m.size(); ++i)
        if (m.valid[i]) {
          sum += glm::dvec3(m.texels[i]);
          worst = glm::max(worst, glm::abs(glm::dvec3(m.texels[i]) - glm::dvec3(0.5, 0.7, 1.0)));
          ++n;
        }
    ASSERT_GT(n, 100u);
    std::printf("[ figure ] uniform sky, open plane, %s%s: mean (%.5f %.5f %.5f), exact (0.5 0.7 1), worst |err| %.2e\n",
                toString(backend), run == 3 ? " + final gather" : "", sum.x / n, sum.y / n, sum.z / n, worst.z);
    EXPECT_NEAR(sum.x / n, 0.5, 1e-4) << toString(backend);
    EXPECT_NEAR(sum.z / n, 1.0, 2e-4) << toString(backend);
    EXPECT_LT(worst.z, 1e-3) << toString(backend);
  }
}

// The final gather (--final-gather): a spot-lit open corner (floor and wall, ρ = 0.7), whose bounced light
// is all the gather's to read. Its mean agrees with the plain bake's and with the reference path tracer's
// on each face, and auto turns it on here (no emissive surface).
TEST(BakePipeline, FinalGatherAgreesWithThePlainBakeAndTheReference) {
  std::vector<double> means;
  for (int mode = 0; mode < 3; ++mode) {  // plain, final gather, reference
    BakeOptions o = smallEmbreeBake(12.0f, 4096);
    if (mode == 1) o.finalGather = FinalGatherMode::Auto;
    if (mode == 2) {
      o.backend = BackendKind::Reference;
      o.referenceSpp = 64;
    }
    BakeResult r = bake(samples::makeCorner(), o);
    double sum = 0.0;
    size_t n = 0;
    for (const auto& m : r.maps)
      for (size_t i = 0; i < m.size(); ++i)
        if (m.valid[i]) {
          ASSERT_TRUE(std::isfinite(m.texels[i].x));
          sum += channelMean(m.texels[i]), ++n;
        }
    ASSERT_GT(n, 1000u);
    means.push_back(sum / n);
    EXPECT_EQ(r.report.contains("finalGather"), mode == 1) << mode;
    if (mode == 1) {
      std::printf("[ figure ] corner: final gather %d rays per sample, gathered share %.3f, moved the map by %.2f%%\n",
                  r.report["finalGather"]["raysPerSample"].get<int>(),
                  r.report["finalGather"]["gatheredFraction"].get<double>(),
                  100 * r.report["finalGather"]["changeFraction"].get<double>());
      EXPECT_GT(r.report["finalGather"]["gatheredFraction"].get<double>(), 0.05);
    }
  }
  std::printf("[ figure ] corner mean map: plain %.5f, final gather %.5f, reference %.5f\n", means[0], means[1], means[2]);
  EXPECT_NEAR(means[1] / means[0], 1.0, 0.01);
  EXPECT_NEAR(means[1] / means[2], 1.0, 0.02);
  // With --directional the map keeps the plain bake's bytes and the L1 pages come from the same rays.
  BakeOptions directional = smallEmbreeBake(12.0f, 4096);
  directional.finalGather = FinalGatherMode::Auto;
  BakeOptions plain = directional;
  directional.directional = true;
  const BakeResult withL1 = bake(samples::makeCorner(), directional), withoutL1 = bake(samples::makeCorner(), plain);
  ASSERT_EQ(withL1.maps.size(), withoutL1.maps.size());
  for (size_t p = 0; p < withL1.maps.size(); ++p) EXPECT_EQ(withL1.maps[p].texels, withoutL1.maps[p].texels) << p;
  ASSERT_TRUE(withL1.report.contains("finalGather"));
  double tangential = 0.0;
  for (const auto& axis : withL1.directional)
    for (const Lightmap& page : axis)
      for (size_t t = 0; t < page.size(); ++t) {
        ASSERT_TRUE(std::isfinite(page.texels[t].x));
        tangential = std::max(tangential, double(std::abs(page.texels[t].x)));
      }
  EXPECT_GT(tangential, 0.01);  // the corner's wall lights the floor from the side
  // Auto leaves it off under a small emitter (the Cornell box's light: its rays would find it by chance) and
  // turns it on where emitters cover most of the surface (the furnace's walls).
  BakeOptions autoGather = smallEmbreeBake(4.0f, 256);
  autoGather.finalGather = FinalGatherMode::Auto;
  EXPECT_FALSE(bake(loadSample("cornell_box"), autoGather).report.contains("finalGather"));
  EXPECT_TRUE(bake(loadSample("furnace"), autoGather).report.contains("finalGather"));
}

// --backend auto (the default): GL for a small scene (on llvmpipe too), Embree as soon as a material is
// see-through (GL's shadow maps would treat it as opaque); the choice and its reason in the report.
TEST(BakePipeline, AutoBackendSaysWhatItChoseAndWhy) {
  BakeOptions o;
  o.atlas.texelsPerUnit = 4.0f;
  o.walk.paths = 64;
  BakeResult small = bake(samples::makeFurnace(), o);
  EXPECT_EQ(small.report["backendChoice"]["asked"], "auto");
  EXPECT_EQ(small.report["backend"], "gl");
  EXPECT_FALSE(small.report["backendChoice"]["reason"].get<std::string>().empty());
  Scene glass = samples::makeCornellBox();
  glass.materials[0].alphaMode = AlphaMode::Blend;
  BakeResult seeThrough = bake(std::move(glass), o);
  EXPECT_EQ(seeThrough.report["backend"], "embree");
  EXPECT_NE(seeThrough.report["backendChoice"]["reason"].get<std::string>().find("BLEND"), std::string::npos);
}

// Each clamp mode reaches the backends as one bound: derived = deriveClampBound at the plan's k (with bias
// compensation) on the walk at seed 0 (in the closed furnace every seed's walk leaves as many VPLs, so the
// bake's own), off = 0 (no clamp), fixed = the given bound; fixed and off leave k at 0.
TEST(BakePipeline, ClampModeGivesTheBackendsOneBound) {
  for (ClampMode mode : {ClampMode::Derived, ClampMode::Off, ClampMode::Fixed}) {
    BakeOptions o = smallEmbreeBake(4.0f, 64);
    o.clamp = mode;
    o.clampBound = 5.0f;  // read by Fixed only
    const BakeResult r = bake(loadSample("furnace"), o);
    const nlohmann::json& eval = r.report["eval"];
    // k = 1024: the furnace's emitters cover its surface, so no small emitter is near (the tight clamp).
    const float expected = mode == ClampMode::Derived ? deriveClampBound(r.scene, r.vpls, 1024.0)
                           : mode == ClampMode::Fixed ? 5.0f
                                                      : 0.0f;
    EXPECT_EQ(eval["clampBound"].get<float>(), expected) << static_cast<int>(mode);
    EXPECT_EQ(eval["clampDerived"].get<bool>(), mode == ClampMode::Derived);
    EXPECT_EQ(eval["clampVplsPerMean"].get<double>(), mode == ClampMode::Derived ? 1024.0 : 0.0);
    if (mode == ClampMode::Derived) {
      EXPECT_GT(expected, 0.0f);
    }
  }
}

// The derived bound is settled once per scene: the walk at seed 0's lit VPLs, whatever the bake's seed, and with
// the error estimate too (whose replicate 0 walks half the paths). In the open corner the walks of other seeds
// leave other counts, so their own bounds would differ: bakes at two seeds would not share the clamp's bias.
TEST(BakePipeline, DerivedClampIsSettledOncePerScene) {
  const Scene corner = samples::makeCorner(0.5f);
  BakeOptions o = smallEmbreeBake(8.0f, 64);
  o.walk.seed = 0;
  o.probes.enabled = false;
  const BakeResult first = bake(corner, o);
  const double k = first.report["eval"]["clampVplsPerMean"].get<double>();
  const float bound = first.report["eval"]["clampBound"].get<float>();
  EXPECT_GT(bound, 0.0f);
  EXPECT_EQ(bound, deriveClampBound(first.scene, first.vpls, k));
  int ownDiffers = 0;
  for (const auto& [seed, estimate] : std::vector<std::pair<uint32_t, bool>>{{3, false}, {7, false}, {3, true}}) {
    o.walk.seed = seed;
    o.errorEstimate.enabled = estimate;
    const BakeResult r = bake(corner, o);
    EXPECT_EQ(r.report["eval"]["clampBound"].get<float>(), bound) << "seed " << seed << ", estimate " << estimate;
    if (!estimate) ownDiffers += deriveClampBound(r.scene, r.vpls, k) != bound ? 1 : 0;  // the seed's own bound
  }
  EXPECT_EQ(ownDiffers, 2);
}

// A set option out of its range is a usage error naming the option, never a silent "automatic" (as 0 and
// −1 were when they stood for it).
TEST(BakePipeline, OptionsOutOfRangeAreUsageErrors) {
  const std::vector<std::pair<std::string, std::function<void(BakeOptions&)>>> cases = {
      {"interleave", [](BakeOptions& o) { o.interleave = 0; }},
      {"cube face", [](BakeOptions& o) { o.gl.cubeFaceSize = 0; }},
      {"bounce count", [](BakeOptions& o) { o.walk.maxBounces = -1; }},
      {"filter radius", [](BakeOptions& o) { o.compensation.filterRadius = -1; }},
      {"fixed clamp", [](BakeOptions& o) { o.clamp = ClampMode::Fixed; }},  // clampBound left at 0
  };
  for (const auto& [name, spoil] : cases) {
    BakeOptions o = smallEmbreeBake(4.0f, 64);
    spoil(o);
    try {
      bake(loadSample("furnace"), o);
      ADD_FAILURE() << name << " out of range accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage) << name;
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

// The compensation's rays traced while the GL backend bakes (what a hardware renderer gets by default)
// give the same map, bit for bit, as tracing them after it: the trace reads no map.
TEST(BakePipeline, CompensationTracedDuringTheGlBakeGivesTheSameMap) {
  BakeResult runs[2];
  for (int overlap : {0, 1}) {
    BakeOptions o;
    o.atlas.texelsPerUnit = 12.0f;
    o.walk.paths = 256;
    o.overlapCompensation = overlap == 1 ? OverlapCompensation::Always : OverlapCompensation::Never;
    runs[overlap] = bake(loadSample("furnace"), o);
    EXPECT_EQ(runs[overlap].report["compensationOverlapped"].get<bool>(), overlap == 1);
    EXPECT_GT(runs[overlap].report["compensation"]["hitsKept"].get<size_t>(), 0u);
  }
  ASSERT_EQ(runs[0].maps.size(), runs[1].maps.size());
  for (size_t p = 0; p < runs[0].maps.size(); ++p)
    for (size_t i = 0; i < runs[0].maps[p].size(); ++i) ASSERT_EQ(runs[0].maps[p].texels[i], runs[1].maps[p].texels[i]) << i;
}

TEST(BakePipeline, ThinWallDarkSideStaysDark) {
  // A zero-thickness partition at x = 0 between a lit room (light at x = −1) and a dark one.
  BakeResult r = bake(loadSample("thin_wall"), smallEmbreeBake(10.0f, 512));
  // Texel positions from the baked atlas (no leak control: every covered texel gets its centre).
  RayTracer rt(r.scene);
  TexelSampleOptions to;
  to.leakControl = false;
  auto texels = buildTexelSamples(r.scene, rt, to);
  ASSERT_EQ(texels.size(), r.maps.size());
  auto isDark = [&](size_t p, size_t i) {
    return r.scene.primitives[texels[p].primitive[i]].name.find("dark") != std::string::npos;
  };
  TexelClassMean lit, dark;
  for (size_t p = 0; p < texels.size(); ++p)
    for (size_t i = 0; i < texels[p].layerSize(); ++i) {
      const glm::vec4& pw = texels[p].positionWeight[i];
      if (pw.w <= 0.0f || !r.maps[p].valid[i]) continue;
      // The sample's room (texels on the partition line, x = 0, belong to either room).
      bool inDark = isDark(p, i);
      double v = (r.maps[p].texels[i].x + r.maps[p].texels[i].y + r.maps[p].texels[i].z) / 3.0;
      TexelClassMean& c = inDark ? dark : lit;
      c.sum += v;
      c.weight += 1.0;
      ++c.count;
    }
  ASSERT_GT(lit.count, 100u);
  ASSERT_GT(dark.count, 100u);
  std::printf("thin wall: lit mean %.5g, dark mean %.5g, ratio %.3g\n", lit.mean(), dark.mean(), dark.mean() / lit.mean());
  EXPECT_GT(lit.mean(), 0.01);
  EXPECT_LT(dark.mean(), 1e-3 * lit.mean());
  // And no dark texel anywhere near the lit level (a leak would show as a bright line).
  for (size_t p = 0; p < texels.size(); ++p)
    for (size_t i = 0; i < texels[p].layerSize(); ++i) {
      const glm::vec4& pw = texels[p].positionWeight[i];
      if (pw.w <= 0.0f || !isDark(p, i)) continue;
      EXPECT_LT(r.maps[p].texels[i].x, 1e-2 * lit.mean()) << "page " << p << " texel " << i;
    }
}

namespace {
// A smooth unit sphere (shared vertices, normals = positions) under a point light: the atlas must
// cut it into charts, so its lightmap has real seams on a smooth surface.
Scene litSphere() {
  Scene s;
  s.materials.emplace_back();
  Primitive p;
  p.name = "sphere";
  const int rings = 12, segments = 24;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      if ((r == 0 || r == rings) && k > 0) break;  // one vertex per pole
      double theta = M_PI * r / rings, phi = 2.0 * M_PI * k / segments;
      glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      p.positions.push_back(n);
      p.normals.push_back(n);
    }
  auto vertex = [&](int r, int k) -> uint32_t {
    if (r == 0) return 0;
    if (r == rings) return static_cast<uint32_t>(p.positions.size() - 1);
    return static_cast<uint32_t>(1 + (r - 1) * segments + (k % segments));
  };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      uint32_t a = vertex(r, k), b = vertex(r, k + 1), c = vertex(r + 1, k), d = vertex(r + 1, k + 1);
      // Counter-clockwise seen from outside (phi grows towards +z, theta downwards).
      if (r > 0) p.indices.insert(p.indices.end(), {a, b, c});
      if (r < rings - 1) p.indices.insert(p.indices.end(), {b, d, c});
    }
  s.primitives.push_back(p);
  Light l;
  l.type = LightType::Point;
  l.position = glm::vec3(0.5f, 3.0f, 0.3f);
  l.intensity = 10.0f;
  s.lights.push_back(l);
  return s;
}
}  // namespace

TEST(BakePipeline, SeamsOfASmoothSphereAreStitched) {
  BakeOptions o = smallEmbreeBake(24.0f, 16);
  BakeResult r = bake(litSphere(), o);
  const auto& post = r.report["post"];
  size_t seams = post["seamEdges"].get<size_t>();
  double before = post["seamMismatchBefore"].get<double>(), after = post["seamMismatchAfter"].get<double>();
  std::printf("sphere: %zu charts, %zu seam edges, seam mismatch RMS %.3g -> %.3g\n",
              r.report["atlas"]["charts"].get<size_t>(), seams, before, after);
  ASSERT_GT(r.report["atlas"]["charts"].get<size_t>(), 1u);
  ASSERT_GT(seams, 10u);
  EXPECT_GT(before, 0.0);
  EXPECT_LT(after, 0.2 * before);
  // Stitching moves seam texels only slightly: the brightest texel is still the closed form
  // I·cosθ/(π r²) at the point nearest the light within 3%.
  glm::vec3 light = r.scene.lights[0].position;
  double dist = glm::length(light) - 1.0, exact = 10.0 / (M_PI * dist * dist);
  double brightest = 0.0;
  for (const auto& m : r.maps)
    for (size_t i = 0; i < m.size(); ++i)
      if (m.valid[i]) brightest = std::max(brightest, double(m.texels[i].x));
  EXPECT_NEAR(brightest, exact, 0.03 * exact);
}

// An equirectangular EXR read through the imageio plugin keeps every texel, its size and its source;
// a file that is not an image is InvalidData naming it.
TEST(EnvironmentFile, LoadsThroughTheImagePluginTexelForTexel) {
  const std::filesystem::path dir = std::filesystem::current_path() / "test_scratch" / "environment_file";
  std::filesystem::create_directories(dir);
  Lightmap map;
  map.width = 4;
  map.height = 2;
  for (int i = 0; i < 8; ++i) map.texels.push_back(glm::vec3(0.5f * i, 1.0f + i, 0.25f));
  map.valid.assign(8, 1);
  writeExr(map, dir / "sky.exr");
  const Environment env = loadEnvironment(dir / "sky.exr", 2.0f);
  ASSERT_EQ(env.width(), 4);
  ASSERT_EQ(env.height(), 2);
  EXPECT_EQ(env.source(), (dir / "sky.exr").string());
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const glm::vec3 t = map.texels[size_t(y) * 4 + x] * 2.0f;  // the intensity scales every texel
      // The direction through the texel's centre (+Y up; φ from -Z towards +X).
      const double theta = M_PI * (y + 0.5) / 2.0, phi = 2.0 * M_PI * (x + 0.5) / 4.0 - M_PI;
      const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const glm::vec3 e = env.radiance(d);
      EXPECT_NEAR(e.x, t.x, 1e-6f);
      EXPECT_NEAR(e.y, t.y, 1e-6f);
      EXPECT_NEAR(e.z, t.z, 1e-6f);
    }
  std::ofstream(dir / "not_an_image.exr") << "plain text";
  try {
    loadEnvironment(dir / "not_an_image.exr");
    FAIL() << "text accepted as an environment";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    EXPECT_NE(std::string(e.what()).find("not_an_image.exr"), std::string::npos) << e.what();
  }
}
