// Contact cuts: a slab lying 1 mm over a floor (a cupboard against a wall) cuts exactly the texel steps that
// cross its edge, and the surface filters then keep a light step across that edge as it is.
#include <gtest/gtest.h>

#include "raytrace/ray_tracer.h"
#include "texels/contact_cuts.h"
#include "texels/texel_filter.h"
#include "texels/texel_samples.h"

using namespace irbake;

namespace {
constexpr int kSize = 48;      // texels over the unit floor: spacing 1/48 m
constexpr int kEdgeColumn = 24;  // the slab covers x ≥ 0.5: texel columns 24 and up

// The unit floor z = 0 (normal +z), uv1 = (x, y), and a closed slab with outward faces over x ∈ [0.5, 1.2],
// y ∈ [−0.2, 1.2], z ∈ [0.001, 0.3]: its bottom faces the floor 1 mm above it, so the texels under it stay valid.
Scene floorUnderSlab() {
  Scene s;
  s.materials.emplace_back();
  Primitive floor;
  floor.name = "floor";
  floor.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  for (const auto& q : floor.positions) {
    floor.normals.push_back({0, 0, 1});
    floor.uv1.push_back({q.x, q.y});
  }
  floor.lightmap = {0, kSize, kSize};
  Primitive slab;
  slab.name = "slab";
  const glm::vec3 lo(0.5f, -0.2f, 0.001f), hi(1.2f, 1.2f, 0.3f);
  auto v = [&](int i) { return glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
  for (int i = 0; i < 8; ++i) slab.positions.push_back(v(i));
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (const auto& f : faces) {
    uint32_t q[6] = {uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2]), uint32_t(f[0]), uint32_t(f[2]), uint32_t(f[3])};
    const glm::vec3 a = slab.positions[q[0]], b = slab.positions[q[1]], c = slab.positions[q[2]];
    if (glm::dot(glm::cross(b - a, c - a), a - centre) < 0.0f) std::swap(q[1], q[2]), std::swap(q[4], q[5]);
    slab.indices.insert(slab.indices.end(), q, q + 6);
  }
  s.primitives = {floor, slab};
  return s;
}
}  // namespace

TEST(ContactCuts, CutExactlyTheStepsAcrossTheSlabsEdge) {
  const Scene s = floorUnderSlab();
  const RayTracer rt(s);
  const TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  for (uint8_t v : ts.valid) ASSERT_EQ(v, 1);  // the floor under the slab is lit through the 1 mm gap: valid
  ASSERT_EQ(ts.cut.size(), ts.layerSize());
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const uint8_t bits = ts.cut[static_cast<size_t>(y) * kSize + x];
      EXPECT_EQ(bits, x == kEdgeColumn - 1 ? kCutRight : 0) << x << " " << y;
    }
}

// Light 1 beside the slab and 0 under it (its exact value at the contact: the slab's side blocks the room):
// every window the bake uses (the interleave's class mix, a tent of half-width 6; the compensation's box of
// radius 4; the symmetric box) returns the step as it is. Without the cuts the class mix reads 0 across the
// edge: the lit column at the edge falls below 0.6 and the first column under the slab rises above 0.4.
TEST(ContactCuts, FiltersKeepALightStepAcrossAContactLine) {
  const Scene s = floorUnderSlab();
  const RayTracer rt(s);
  TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  std::vector<glm::vec3> values(ts.layerSize());
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) values[static_cast<size_t>(y) * kSize + x] = glm::vec3(x < kEdgeColumn ? 1.0f : 0.0f);
  TexelFilterOptions box, symmetricBox;
  box.radius = 4;
  box.symmetric = false;
  symmetricBox.radius = 4;
  TexelFilterOptions planned;
  planned.radius = SurfaceFilterPlan::kMaxRadius;
  const SurfaceFilterPlan plan(SurfaceFilter(ts), ts.valid, planned);  // the bake's shared plan: the same cuts
  for (const TexelFilterOptions& o : {classMixFilter(6), box, symmetricBox}) {
    const std::vector<glm::vec3> out = SurfaceFilter(ts).apply(values, ts.valid, o);
    for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i].x, values[i].x, 1e-6f) << i << " radius " << o.radius;
    ASSERT_TRUE(plan.serves(ts.valid, o));
    EXPECT_EQ(plan.apply(values, o), out) << "radius " << o.radius;
  }
  ts.cut.clear();
  const std::vector<glm::vec3> mixed = SurfaceFilter(ts).apply(values, ts.valid, classMixFilter(6));
  const size_t row = static_cast<size_t>(kSize / 2) * kSize;
  EXPECT_LT(mixed[row + kEdgeColumn - 1].x, 0.6f);
  EXPECT_GT(mixed[row + kEdgeColumn].x, 0.4f);
}
