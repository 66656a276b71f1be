#include "lights/light_reach.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/maths.h"
#include "lights/light_kind.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

constexpr float kEverywhere = std::numeric_limits<float>::infinity();
// At most this many grid cells.
constexpr size_t kMaxCells = size_t(1) << 20;

float channelMax(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// What the lights at infinity and the sky give a surface facing them, as a map value: each directional light's
// E/π and the sky's cosine-weighted mean radiance over the hemisphere about +Y (the glTF up axis).
float infiniteReference(const Scene& scene) {
  float sum = 0.0f;
  for (const Light& l : scene.lights)
    if (lightKind(l.type).atInfinity()) sum += channelMax(l.color) * l.intensity / kPiF;
  if (scene.environment.present()) {
    glm::vec3 mean(0.0f);
    const int n = 64;
    for (int k = 0; k < n; ++k) {
      const double v = k * 0.6180339887498949;
      mean += scene.environment.radiance(cosineHemisphere(glm::vec3(0, 1, 0), (k + 0.5) / n, v - std::floor(v)));
    }
    sum += channelMax(mean / float(n));
  }
  return sum;
}

// The median over the positional lights of the map value each gives at the distance of its nearest other
// positional light (0 with fewer than two).
float neighbourReference(const Scene& scene) {
  std::vector<size_t> pos;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (!lightKind(scene.lights[i].type).atInfinity()) pos.push_back(i);
  if (pos.size() < 2) return 0.0f;
  std::vector<float> values;
  values.reserve(pos.size());
  for (size_t i : pos) {
    const glm::vec3 p = scene.lights[i].position;
    float best2 = kEverywhere;
    for (size_t j : pos) {
      const glm::vec3 d = scene.lights[j].position - p;
      if (j != i) best2 = std::min(best2, glm::dot(d, d));
    }
    if (!(best2 > 0.0f) || std::isinf(best2)) continue;  // lights at one point: no spacing to speak of
    values.push_back(channelMax(scene.lights[i].color) * peakIntensity(scene.lights[i]) / (kPiF * best2));
  }
  if (values.empty()) return 0.0f;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The largest distance from p to a corner of b.
float farthestCorner(const glm::vec3& p, const Bounds3& b) {
  const glm::vec3 d = glm::max(glm::abs(p - b.min), glm::abs(b.max - p));
  return glm::length(d);
}

// Squared distance from p to the box [lo, hi].
float boxDistance2(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 d = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
  return glm::dot(d, d);
}

}  // namespace

float peakIntensity(const Light& light) {
  float peak = light.intensity;
  if (light.type == LightType::Ies) peak *= light.profile ? static_cast<float>(light.profile->maxCandela) : 0.0f;
  return std::max(0.0f, peak);
}

size_t LightReach::cutLights() const {
  return static_cast<size_t>(std::count(cut.begin(), cut.end(), uint8_t(1)));
}

LightReach settleLightReach(const Scene& scene, const Bounds3& bounds, const LightCullOptions& options) {
  LightReach r;
  const size_t n = scene.lights.size();
  r.reach.assign(n, kEverywhere);
  r.cut.assign(n, 0);
  if (!(options.fraction > 0.0f)) return r;
  // With a single positional light and nothing at infinity there is no reference: a lamp alone is never cut.
  r.reference = std::max(infiniteReference(scene), neighbourReference(scene));
  r.threshold = options.fraction * r.reference;
  for (size_t i = 0; i < n; ++i) {
    const Light& l = scene.lights[i];
    if (lightKind(l.type).atInfinity()) continue;
    float reach = l.range > 0.0f ? l.range : kEverywhere;
    bool cut = false;
    if (r.threshold > 0.0f && l.range <= 0.0f) {
      reach = std::sqrt(channelMax(l.color) * peakIntensity(l) / (kPiF * r.threshold));
      cut = true;
    }
    if (bounds.valid() && reach >= farthestCorner(l.position, bounds)) reach = kEverywhere, cut = false;
    r.reach[i] = reach;
    r.cut[i] = cut ? 1 : 0;
  }
  return r;
}

void applyLightCutoffs(Scene& scene, const LightReach& reach) {
  for (size_t i = 0; i < scene.lights.size() && i < reach.cut.size(); ++i)
    scene.lights[i].cutoff = reach.cut[i] ? reach.reach[i] : 0.0f;
}

bool reachesEverywhere(const Scene& scene, const LightReach& reach, const Bounds3& bounds) {
  for (size_t i = 0; i < scene.lights.size() && i < reach.reach.size(); ++i)
    if (!std::isinf(reach.reach[i]) && reach.reach[i] < farthestCorner(scene.lights[i].position, bounds)) return false;
  return true;
}

LightGrid::LightGrid(size_t lights) {
  all_.resize(lights);
  for (size_t i = 0; i < lights; ++i) all_[i] = static_cast<uint32_t>(i);
  spheres_.assign(lights, glm::vec4(0.0f, 0.0f, 0.0f, kEverywhere));
}

LightGrid::LightGrid(const Scene& scene, const LightReach& reach, const Bounds3& bounds) : LightGrid(scene.lights.size()) {
  const size_t n = scene.lights.size();
  std::vector<float> finite;
  for (size_t i = 0; i < n; ++i) {
    const float r = i < reach.reach.size() ? reach.reach[i] : kEverywhere;
    spheres_[i] = glm::vec4(scene.lights[i].position, r);
    if (!std::isinf(r)) finite.push_back(r);
  }
  if (finite.empty() || !bounds.valid() || reachesEverywhere(scene, reach, bounds)) return;
  culls_ = true;
  // Cells about the median reach, widened until the grid holds at most kMaxCells.
  std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
  const glm::vec3 extent = glm::max(bounds.extent(), glm::vec3(1e-6f));
  float edge = std::max(finite[finite.size() / 2], 1e-6f * glm::length(extent));
  auto dimsFor = [&](float e) { return glm::max(glm::ivec3(glm::ceil(extent / e)), glm::ivec3(1)); };
  while (double(dimsFor(edge).x) * dimsFor(edge).y * dimsFor(edge).z > double(kMaxCells)) edge *= 1.5f;
  dims_ = dimsFor(edge);
  lo_ = bounds.min;
  cell_ = extent / glm::vec3(dims_);
  const size_t cells = size_t(dims_.x) * dims_.y * dims_.z;
  std::vector<std::vector<uint32_t>> lists(cells);
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3 c(spheres_[i]);
    const float r = spheres_[i].w;
    glm::ivec3 a(0), b = dims_ - 1;
    if (!std::isinf(r)) {
      a = glm::clamp(glm::ivec3(glm::floor((c - r - lo_) / cell_)), glm::ivec3(0), dims_ - 1);
      b = glm::clamp(glm::ivec3(glm::floor((c + r - lo_) / cell_)), glm::ivec3(0), dims_ - 1);
      if (glm::any(glm::lessThan(c + r, lo_)) || glm::any(glm::greaterThan(c - r, bounds.max))) continue;
    }
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) {
          const glm::vec3 clo = lo_ + glm::vec3(x, y, z) * cell_, chi = clo + cell_;
          if (std::isinf(r) || boxDistance2(c, clo, chi) <= r * r) lists[cellOf({x, y, z})].push_back(uint32_t(i));
        }
  }
  offsets_.assign(cells + 1, 0);
  for (size_t k = 0; k < cells; ++k) offsets_[k + 1] = offsets_[k] + static_cast<uint32_t>(lists[k].size());
  ids_.reserve(offsets_[cells]);
  for (const auto& list : lists) ids_.insert(ids_.end(), list.begin(), list.end());
}

LightSpan LightGrid::near(const glm::vec3& x) const {
  lookups_.fetch_add(1, std::memory_order_relaxed);
  if (!culls_) return {nullptr, static_cast<uint32_t>(all_.size())};
  const glm::vec3 u = (x - lo_) / cell_;
  if (!(u.x >= 0.0f && u.y >= 0.0f && u.z >= 0.0f && u.x <= float(dims_.x) && u.y <= float(dims_.y) &&
        u.z <= float(dims_.z)))
    return {nullptr, static_cast<uint32_t>(all_.size())};
  const glm::ivec3 c = glm::min(glm::ivec3(u), dims_ - 1);
  const size_t k = cellOf(c);
  return {ids_.data() + offsets_[k], offsets_[k + 1] - offsets_[k]};
}

bool LightGrid::touches(size_t i, const glm::vec3& lo, const glm::vec3& hi) const {
  const float r = spheres_[i].w;
  return std::isinf(r) || boxDistance2(glm::vec3(spheres_[i]), lo, hi) <= r * r;
}

std::vector<uint32_t> LightGrid::touching(const glm::vec3& lo, const glm::vec3& hi) const {
  lookups_.fetch_add(1, std::memory_order_relaxed);
  std::vector<uint32_t> out;
  if (!culls_) return all_;
  for (size_t i = 0; i < spheres_.size(); ++i)
    if (touches(i, lo, hi)) out.push_back(static_cast<uint32_t>(i));
  return out;
}

}  // namespace irbake
