#include "evaluators/gl/shadow_views.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "texels/texel_filter.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {

// Rows of the GL cube-map face selection (OpenGL 4.5, table 8.19): sc, tc and the major axis ma
// as linear functions of the direction; s = (sc/|ma| + 1)/2, t = (tc/|ma| + 1)/2.
struct FaceAxes {
  glm::vec3 sc, tc, ma;
};
constexpr FaceAxes kFaceAxes[6] = {
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},   // +X
    {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}},   // −X
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},     // +Y
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // −Y
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},    // +Z
    {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},  // −Z
};

glm::mat4 fromRows(const glm::vec4& r0, const glm::vec4& r1, const glm::vec4& r2, const glm::vec4& r3) {
  return glm::transpose(glm::mat4(r0, r1, r2, r3));
}

// A row acting on world points: local vector a (in the frame) applied to (p − origin).
glm::vec4 worldRow(const glm::vec3& local, const VplFrame& f, const glm::vec3& origin) {
  const glm::vec3 a = local.x * f.tangent + local.y * f.bitangent + local.z * f.normal;
  return glm::vec4(a, -glm::dot(a, origin));
}

// Frustum planes from a clip matrix (inside: −w ≤ x, y ≤ w and 0 ≤ z ≤ w).
std::vector<glm::vec4> clipPlanes(const glm::mat4& clip) {
  const glm::mat4 t = glm::transpose(clip);  // t[i] = row i
  return {t[3] + t[0], t[3] - t[0], t[3] + t[1], t[3] - t[1], t[2], t[3] - t[2]};
}

}  // namespace

VplFrame vplFrame(const glm::vec3& normal) {
  glm::vec3 n = glm::length(normal) > 0.0f ? glm::normalize(normal) : glm::vec3(0, 0, 1);
  // Helper axis least aligned with n, so the cross product is well conditioned.
  const glm::vec3 a = std::abs(n.x) < 0.57f ? glm::vec3(1, 0, 0) : (std::abs(n.y) < 0.57f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1));
  const glm::vec3 t = glm::normalize(glm::cross(a, n));
  return {t, glm::cross(n, t), n};
}

int cubeFaceOf(const glm::vec3& d, glm::vec2& st) {
  const glm::vec3 a = glm::abs(d);
  int face;
  if (a.x >= a.y && a.x >= a.z)
    face = d.x >= 0 ? 0 : 1;
  else if (a.y >= a.z)
    face = d.y >= 0 ? 2 : 3;
  else
    face = d.z >= 0 ? 4 : 5;
  const FaceAxes& f = kFaceAxes[face];
  const float ma = glm::dot(f.ma, d);
  st = glm::vec2(0.5f * (glm::dot(f.sc, d) / ma + 1.0f), 0.5f * (glm::dot(f.tc, d) / ma + 1.0f));
  return face;
}

std::optional<ShadowView> cubeFaceView(const glm::vec3& origin, const VplFrame& frame, int face, int size,
                                       float nearPlane, bool hemisphereOnly) {
  const FaceAxes& f = kFaceAxes[face];
  if (hemisphereOnly && f.ma.z < 0.0f) return std::nullopt;  // the face behind the surface
  ShadowView v;
  v.clip = fromRows(worldRow(f.sc, frame, origin), worldRow(f.tc, frame, origin), glm::vec4(0, 0, 0, nearPlane),
                    worldRow(f.ma, frame, origin));
  v.scissor = glm::ivec4(0, 0, size, size);
  v.planes = clipPlanes(v.clip);
  if (hemisphereOnly && f.ma.z == 0.0f) {
    // Local z ≥ 0 is one half of a side face: sc or tc has the z coefficient; keep that half + 1 texel.
    const int half = size / 2 + 1;
    if (f.sc.z < 0) v.scissor = {0, 0, half, size};
    if (f.sc.z > 0) v.scissor = {size - half, 0, half, size};
    if (f.tc.z < 0) v.scissor = {0, 0, size, half};
    if (f.tc.z > 0) v.scissor = {0, size - half, size, half};
    v.planes.push_back(glm::vec4(frame.normal, -glm::dot(frame.normal, origin)));
  }
  return v;
}

ShadowView spotView(const glm::vec3& position, const glm::vec3& direction, float outerConeAngle, int size,
                    float nearPlane, float& tanHalfFov) {
  const VplFrame f = vplFrame(direction);
  // A margin of a few texels so the cone edge never falls on the map border.
  const float half = std::min(outerConeAngle, 1.45f);
  tanHalfFov = std::tan(half) * (1.0f + 4.0f / size);
  const float s = 1.0f / tanHalfFov;
  ShadowView v;
  v.clip = fromRows(worldRow({s, 0, 0}, f, position), worldRow({0, s, 0}, f, position), glm::vec4(0, 0, 0, nearPlane),
                    worldRow({0, 0, 1}, f, position));
  v.scissor = glm::ivec4(0, 0, size, size);
  v.planes = clipPlanes(v.clip);
  return v;
}

ShadowView directionalView(const glm::vec3& direction, const Bounds3& bounds, int size, float& texelSize,
                           float& depthRange) {
  const VplFrame f = vplFrame(-direction);  // local +Z points at the light
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c((i & 1) ? bounds.max.x : bounds.min.x, (i & 2) ? bounds.max.y : bounds.min.y,
                      (i & 4) ? bounds.max.z : bounds.min.z);
    const glm::vec3 l(glm::dot(f.tangent, c), glm::dot(f.bitangent, c), glm::dot(f.normal, c));
    lo = glm::min(lo, l);
    hi = glm::max(hi, l);
  }
  // Pad by 1% (and a little absolute) so geometry on the bounds is inside the box.
  const glm::vec3 pad = 0.01f * (hi - lo) + glm::vec3(1e-4f * glm::length(hi - lo) + 1e-6f);
  lo -= pad;
  hi += pad;
  const glm::vec3 ext = hi - lo;
  texelSize = std::max(ext.x, ext.y) / size;
  depthRange = ext.z;
  ShadowView v;
  // x, y: [lo, hi] → [−1, 1]; window depth (hi.z − z) / range: 0 at the light side.
  v.clip = fromRows(glm::vec4(2.0f * f.tangent / ext.x, -2.0f * lo.x / ext.x - 1.0f),
                    glm::vec4(2.0f * f.bitangent / ext.y, -2.0f * lo.y / ext.y - 1.0f),
                    glm::vec4(-f.normal / ext.z, hi.z / ext.z), glm::vec4(0, 0, 0, 1));
  v.scissor = glm::ivec4(0, 0, size, size);
  v.planes = clipPlanes(v.clip);
  return v;
}

void appendClusters(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices, size_t firstIndex,
                    size_t triangleCount, int clusterTriangles, std::vector<TriangleCluster>& clusters) {
  for (size_t t0 = 0; t0 < triangleCount; t0 += clusterTriangles) {
    const size_t n = std::min<size_t>(clusterTriangles, triangleCount - t0);
    TriangleCluster c;
    c.firstIndex = firstIndex + 3 * t0;
    c.indexCount = 3 * n;
    for (size_t i = 0; i < c.indexCount; ++i) c.bounds.extend(positions[indices[c.firstIndex + i]]);
    clusters.push_back(c);
  }
}

void cullClusters(const ShadowView& view, const std::vector<TriangleCluster>& clusters, std::vector<int>& counts,
                  std::vector<const void*>& offsets, size_t& trianglesDrawn) {
  size_t runStart = 0, runEnd = 0;  // current merged range of indices
  auto flush = [&] {
    if (runEnd > runStart) {
      counts.push_back(static_cast<int>(runEnd - runStart));
      offsets.push_back(reinterpret_cast<const void*>(runStart * sizeof(uint32_t)));
      trianglesDrawn += (runEnd - runStart) / 3;
    }
    runStart = runEnd = 0;
  };
  for (const TriangleCluster& c : clusters) {
    bool inside = true;
    for (const glm::vec4& p : view.planes) {
      // The box corner furthest along the plane normal; if even it is outside, the box is.
      const glm::vec3 corner(p.x >= 0 ? c.bounds.max.x : c.bounds.min.x, p.y >= 0 ? c.bounds.max.y : c.bounds.min.y,
                             p.z >= 0 ? c.bounds.max.z : c.bounds.min.z);
      if (glm::dot(glm::vec3(p), corner) + p.w < 0.0f) {
        inside = false;
        break;
      }
    }
    if (!inside) continue;
    if (runEnd == c.firstIndex && runEnd > runStart) {
      runEnd += c.indexCount;
    } else {
      flush();
      runStart = c.firstIndex;
      runEnd = c.firstIndex + c.indexCount;
    }
  }
  flush();
}

CubeFaceChoice chooseCubeFaceSize(const std::vector<Vpl>& vpls, const std::vector<TexelSamples>& pages,
                                  float clampBound, float footprintPerTexel, int minSize, int maxSize,
                                  int pairSamples) {
  maxSize = std::max(1, maxSize);
  minSize = std::clamp(minSize, 1, maxSize);
  CubeFaceChoice choice;
  choice.size = maxSize;
  std::vector<float> spacings;
  for (const TexelSamples& ts : pages)
    if (const float h = texelSpacing(ts); h > 0.0f) spacings.push_back(h);
  // Valid texels: their mean sample position and normal.
  std::vector<std::pair<glm::vec3, glm::vec3>> receivers;
  for (const TexelSamples& ts : pages)
    for (size_t t = 0; t < ts.layerSize() && t < ts.valid.size(); ++t) {
      glm::vec3 p, n;
      if (ts.valid[t] && texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.positionWeight[s]); }, p) &&
          texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.normal[s]); }, n))
        receivers.emplace_back(p, n);
    }
  if (spacings.empty() || receivers.empty() || vpls.empty()) return choice;
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  choice.texelSpacing = spacings[spacings.size() / 2];

  // Pairs drawn by a fixed-seed generator, so the choice is deterministic.
  Rng rng(hashSeed(0x63756265u));
  auto pick = [&rng](size_t n) { return std::min(n - 1, static_cast<size_t>(rng.uniform() * double(n))); };
  // (distance, contribution) of each facing pair; contribution = VPL power × clamped geometry term.
  std::vector<std::pair<float, double>> pairs;
  pairs.reserve(static_cast<size_t>(std::max(0, pairSamples)));
  double total = 0.0;
  for (int i = 0; i < pairSamples; ++i) {
    const Vpl& v = vpls[pick(vpls.size())];
    const auto& [p, n] = receivers[pick(receivers.size())];
    const glm::vec3 d = p - v.position;
    const float r = glm::length(d);
    if (!(r > 0.0f)) continue;
    const float cv = glm::dot(v.normal, d) / r, cr = -glm::dot(n, d) / r;
    if (cv <= 0.0f || cr <= 0.0f) continue;
    double g = double(cv) * cr / (double(r) * r);
    if (clampBound > 0.0f) g = std::min(g, double(clampBound));
    const double w = g * (v.power.r + v.power.g + v.power.b);
    if (!(w > 0.0)) continue;
    pairs.emplace_back(r, w);
    total += w;
  }
  if (pairs.empty()) return choice;
  std::sort(pairs.begin(), pairs.end());
  double acc = 0.0;
  for (const auto& [r, w] : pairs) {
    acc += w;
    choice.medianDistance = r;
    if (acc >= 0.5 * total) break;
  }
  const double faces =
      2.0 * choice.medianDistance / (std::max(footprintPerTexel, 1e-3f) * double(choice.texelSpacing));
  const double rounded = 32.0 * std::ceil(std::min(faces, double(maxSize)) / 32.0);
  choice.size = static_cast<int>(std::clamp(rounded, double(minSize), double(maxSize)));
  return choice;
}

}  // namespace irbake
