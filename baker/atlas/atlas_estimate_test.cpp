// The texel-density rule on closed forms (quads of known area), the budget, the per-object scale, the page
// edge, and the estimate against the real atlas on a generated level (on the samples: samples/).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "atlas/atlas.h"
#include "atlas/atlas_estimate.h"
#include "common/error.h"

namespace irbake {
namespace {

// A flat rectangle of w × h metres in the xz plane at height y, split into n × n quads.
Primitive rectangle(const char* name, int node, float w, float h, float y = 0.0f, float x0 = 0.0f, int n = 1) {
  Primitive p;
  p.name = name;
  p.node = node;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      p.positions.push_back({x0 + w * float(i) / float(n), y, h * float(j) / float(n)});
      p.normals.push_back({0.0f, 1.0f, 0.0f});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      for (uint32_t v : {a, c, d, a, d, b}) p.indices.push_back(v);  // counter-clockwise seen from +y
    }
  return p;
}

Scene sceneOf(std::vector<Primitive> prims) {
  Scene s;
  s.materials.push_back(Material{});
  s.primitives = std::move(prims);
  return s;
}

// The command's --quality default: 16 texels per metre, a small scene at least one 1024² page.
AtlasOptions ruleOptions() {
  AtlasOptions o;
  o.autoTexelsPerUnit = 16.0;
  return o;
}

// Texel centres a page's triangles cover (centreUtilisation is their share of the page area).
double coveredTexels(const AtlasResult& r) {
  double pageArea = 0.0;
  for (const AtlasPage& pg : r.pages) pageArea += double(pg.width) * pg.height;
  return r.stats.centreUtilisation * pageArea;
}

double pageTexels(const AtlasResult& r) {
  double texels = 0.0;
  for (const AtlasPage& pg : r.pages) texels += double(pg.width) * pg.height;
  return texels;
}

bool hasWarning(const std::vector<std::string>& warnings, const std::string& part) {
  for (const std::string& w : warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// A 100 m × 40 m ground (4,000 m², two triangles): one 1024² page would give it 12.2 texels per metre, so the
// rule's 16 per metre holds, and it gets 4000 × 16² = 1,024,000 texels.
TEST(AtlasDensity, QuadGetsAreaTimesTheRuleDensitySquared) {
  Scene s = sceneOf({rectangle("ground", 0, 100.0f, 40.0f)});
  const AtlasOptions o = ruleOptions();
  const AtlasEstimate e = estimateAtlas(s, o);
  EXPECT_DOUBLE_EQ(e.texelsPerUnit, o.autoTexelsPerUnit);
  EXPECT_NEAR(e.texels, 4000.0 * 16.0 * 16.0, 1e-6 * e.texels);
  EXPECT_TRUE(e.warnings.empty());
  const AtlasResult r = buildAtlas(s, o);
  EXPECT_DOUBLE_EQ(r.stats.texelsPerUnit, 16.0);
  EXPECT_NEAR(coveredTexels(r), 4000.0 * 16.0 * 16.0, 0.1 * 4000.0 * 16.0 * 16.0);
  // The page edge: twice 1,024,000 / 0.6 texels is 3.4M, which a 2048² page holds.
  EXPECT_EQ(r.stats.pageSize, 2048);
  EXPECT_EQ(e.pageSize, 2048);
  ASSERT_EQ(r.pages.size(), 1u);
  EXPECT_EQ(e.pages, 1);
  ASSERT_EQ(r.stats.sparsest.size(), 1u);
  EXPECT_NEAR(r.stats.sparsest[0].texelsPerSquareMetre, 256.0, 1e-6 * 256.0);
  EXPECT_EQ(r.stats.sparsest[0].name, "ground");
}

// A small scene keeps at least one page's worth: a 1 m² quad fills 60% of a 1024² page, sqrt(0.6 · 1024²) per metre.
TEST(AtlasDensity, SmallSceneFillsOnePage) {
  Scene s = sceneOf({rectangle("tile", 0, 1.0f, 1.0f)});
  const AtlasOptions o = ruleOptions();
  const double onePage = std::sqrt(0.6 * 1024.0 * 1024.0);
  EXPECT_NEAR(estimateAtlas(s, o).texelsPerUnit, onePage, 1e-9 * onePage);
  EXPECT_NEAR(buildAtlas(s, o).stats.texelsPerUnit, onePage, 1e-9 * onePage);
}

// lightmapScale set by hand: two 10 m × 10 m quads at 16 per metre, one scaled by 2, get 100 · 16² and
// 100 · 32² texels; the budget and the small-scene floor are kept out of the way.
TEST(AtlasDensity, LightmapScaleScalesTexelsBySquare) {
  Primitive plain = rectangle("plain", 0, 10.0f, 10.0f);
  Primitive fine = rectangle("fine", 1, 10.0f, 10.0f, 0.0f, 20.0f);
  fine.lightmapScale = 2.0f;
  Scene s = sceneOf({plain, fine});
  AtlasOptions o = ruleOptions();
  o.targetPageSize = 16;
  o.texelsPerTriangle = 0.0f;
  const AtlasEstimate e = estimateAtlas(s, o);
  EXPECT_DOUBLE_EQ(e.texelsPerUnit, 16.0);
  EXPECT_NEAR(e.texels, 100.0 * 256.0 + 100.0 * 1024.0, 1e-6 * e.texels);
  const AtlasResult r = buildAtlas(s, o);
  EXPECT_DOUBLE_EQ(r.stats.texelsPerUnit, 16.0);
  ASSERT_EQ(r.stats.sparsest.size(), 2u);
  EXPECT_EQ(r.stats.sparsest[0].name, "plain");
  EXPECT_NEAR(r.stats.sparsest[0].texelsPerSquareMetre, 256.0, 1e-6 * 256.0);
  EXPECT_EQ(r.stats.sparsest[1].name, "fine");
  EXPECT_NEAR(r.stats.sparsest[1].texelsPerSquareMetre, 1024.0, 1e-6 * 1024.0);
  // Texel centres covered: 102,400 on the fine quad, 25,600 on the plain one (±10%).
  EXPECT_NEAR(coveredTexels(r), 128000.0, 0.1 * 128000.0);
  for (const Primitive& p : s.primitives) EXPECT_FLOAT_EQ(p.lightmapScale, p.name == "fine" ? 2.0f : 1.0f);
}

TEST(AtlasDensity, BadLightmapScaleIsRefusedNamingThePrimitive) {
  Primitive p = rectangle("crate", 0, 1.0f, 1.0f);
  p.lightmapScale = 0.0f;
  Scene s = sceneOf({p});
  try {
    buildAtlas(s, ruleOptions());
    FAIL() << "a zero lightmapScale was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("crate"), std::string::npos) << e.what();
  }
}

// Over the budget the rule's density is lowered uniformly, with a warning in the stats and the estimate: the
// 4,000 m² ground at 16 per metre would need 4000 · 256 / 0.6 = 1.7M page texels; a budget of 1M lowers it to
// sqrt(0.6 · 1M / 4000) = 12.25 texels per metre, and the pages stay within the budget.
TEST(AtlasDensity, OverTheBudgetTheRuleIsLoweredWithAWarning) {
  Scene s = sceneOf({rectangle("ground", 0, 100.0f, 40.0f)});
  AtlasOptions o = ruleOptions();
  o.maxTexels = 1000000;
  const double fits = std::sqrt(0.6 * 1e6 / 4000.0);
  const AtlasEstimate e = estimateAtlas(s, o);
  EXPECT_NEAR(e.texelsPerUnit, fits, 1e-9 * fits);
  EXPECT_TRUE(hasWarning(e.warnings, "over the budget")) << (e.warnings.empty() ? "" : e.warnings[0]);
  const AtlasResult r = buildAtlas(s, o);
  EXPECT_NEAR(r.stats.texelsPerUnit, fits, 1e-9 * fits);
  EXPECT_TRUE(hasWarning(r.stats.warnings, "lowered to 12.25 texels per metre"));
  EXPECT_LE(pageTexels(r), 1e6);
  EXPECT_NEAR(coveredTexels(r), 4000.0 * fits * fits, 0.1 * 4000.0 * fits * fits);
  const nlohmann::json report = r.toJson();
  EXPECT_TRUE(hasWarning(report["warnings"].get<std::vector<std::string>>(), "--max-texels"));
}

// The page edge: the smallest power of two from 512 to 4096 whose square holds twice the rule's page texels
// (area × density² / 0.6), else 4096; a given edge wins.
TEST(AtlasDensity, PageEdgeRule) {
  AtlasOptions o;
  const double density = 10.0, perSquareMetre = density * density / 0.6;
  auto edgeFor = [&](double pageTexels) { return choosePageSize(pageTexels / perSquareMetre, density, o); };
  EXPECT_EQ(edgeFor(1000.0), 512);
  EXPECT_EQ(edgeFor(512.0 * 512.0 / 2.0 * 0.999), 512);
  EXPECT_EQ(edgeFor(512.0 * 512.0 / 2.0 * 1.001), 1024);
  EXPECT_EQ(edgeFor(2048.0 * 2048.0 / 2.0 * 1.001), 4096);
  EXPECT_EQ(edgeFor(1e9), 4096);
  o.maxPageSize = 300;
  EXPECT_EQ(edgeFor(1e9), 300);
}

// Estimate against the real atlas: texels (chart texel centres) and page texels within ±15%, the page edge and
// count equal, the density the same.
void expectEstimateMatches(const std::string& name, Scene scene, const AtlasOptions& o) {
  const AtlasEstimate e = estimateAtlas(scene, o);
  const AtlasResult r = buildAtlas(scene, o);
  std::printf("%-18s density %8.4g / %8.4g  texels %9.0f / %9.0f  page texels %9.0f / %9.0f  pages %d / %zu\n",
              name.c_str(), e.texelsPerUnit, r.stats.texelsPerUnit, e.texels, coveredTexels(r), e.pageTexels,
              pageTexels(r), e.pages, r.pages.size());
  EXPECT_NEAR(e.texelsPerUnit, r.stats.texelsPerUnit, 1e-6 * r.stats.texelsPerUnit) << name;
  EXPECT_NEAR(e.texels, coveredTexels(r), 0.15 * coveredTexels(r)) << name;
  EXPECT_NEAR(e.pageTexels, pageTexels(r), 0.15 * pageTexels(r)) << name;
  EXPECT_EQ(e.pageSize, r.stats.pageSize) << name;
  EXPECT_EQ(size_t(e.pages), r.pages.size()) << name;
}

// A generated level: a 120 m × 120 m ground and 64 blocks of 6 m × 6 m × 10 m (open boxes of 4 walls and a roof),
// 32,064 m² at the rule's 16 per metre (one page's floor would give 4.4): 8.2M chart texels, within the budget.
TEST(AtlasDensity, EstimateMatchesTheAtlasOnAGeneratedLevel) {
  std::vector<Primitive> prims{rectangle("ground", 0, 120.0f, 120.0f, 0.0f, 0.0f, 8)};
  int node = 1;
  for (int bx = 0; bx < 8; ++bx)
    for (int bz = 0; bz < 8; ++bz) {
      const float x = 4.0f + 14.0f * float(bx), z = 4.0f + 14.0f * float(bz);
      Primitive block = rectangle("roof", node, 6.0f, 6.0f, 10.0f, 0.0f, 2);
      for (glm::vec3& p : block.positions) p += glm::vec3(x, 0.0f, z);
      // Four walls: each a 6 m × 10 m quad.
      const glm::vec3 corner[4] = {{x, 0, z}, {x + 6, 0, z}, {x + 6, 0, z + 6}, {x, 0, z + 6}};
      for (int k = 0; k < 4; ++k) {
        const glm::vec3 a = corner[k], b = corner[(k + 1) % 4], up(0, 10, 0);
        const glm::vec3 n = glm::normalize(glm::cross(b - a, up));
        const uint32_t base = uint32_t(block.positions.size());
        for (glm::vec3 q : {a, b, b + up, a + up}) {
          block.positions.push_back(q);
          block.normals.push_back(n);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) block.indices.push_back(base + i);
      }
      block.name = "block" + std::to_string(node);
      prims.push_back(std::move(block));
      ++node;
    }
  Scene level = sceneOf(std::move(prims));
  EXPECT_TRUE(estimateAtlas(level, ruleOptions()).warnings.empty());
  expectEstimateMatches("level", std::move(level), ruleOptions());
}

}  // namespace
}  // namespace irbake
