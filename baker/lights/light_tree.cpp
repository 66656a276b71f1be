#include "lights/light_tree.h"

#include <algorithm>
#include <cmath>

#include "common/maths.h"

namespace irbake {

LightTree::LightTree(std::vector<LightTreeEntry> entries) : entries_(std::move(entries)) {
  if (entries_.empty()) return;
  nodes_.reserve(2 * entries_.size());
  build(0, entries_.size());
}

// Splits [begin, end) at the median of the longest axis of its positions' box.
int32_t LightTree::build(size_t begin, size_t end) {
  const int32_t at = static_cast<int32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.lo = node.hi = entries_[begin].position;
  node.near = entries_[begin].near;
  node.width = entries_[begin].far - entries_[begin].near;
  for (size_t i = begin; i < end; ++i) {
    node.width = std::min(node.width, entries_[i].far - entries_[i].near);
    node.lo = glm::min(node.lo, entries_[i].position);
    node.hi = glm::max(node.hi, entries_[i].position);
    node.power += entries_[i].power;
    node.near = std::min(node.near, entries_[i].near);
  }
  node.radius = 0.5f * glm::length(node.hi - node.lo);
  node.centre = 0.5f * (node.lo + node.hi);
  node.full2 = (node.near + node.width) * (node.near + node.width);
  if (end - begin == 1) {
    node.entry = static_cast<uint32_t>(begin);
  } else {
    const glm::vec3 extent = node.hi - node.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(entries_.begin() + std::ptrdiff_t(begin), entries_.begin() + std::ptrdiff_t(mid),
                     entries_.begin() + std::ptrdiff_t(end), [axis](const LightTreeEntry& a, const LightTreeEntry& b) {
                       return a.position[axis] < b.position[axis] || (a.position[axis] == b.position[axis] && a.light < b.light);
                     });
    node.left = build(begin, mid);
    node.right = build(mid, end);
  }
  nodes_[size_t(at)] = node;
  return at;
}

double LightTree::importance(const Node& node, const glm::vec3& x, const glm::vec3& n) const {
  // Every light lies behind the receiver's plane: the box's corner farthest along n is.
  const glm::vec3 support(n.x > 0.0f ? node.hi.x : node.lo.x, n.y > 0.0f ? node.hi.y : node.lo.y,
                          n.z > 0.0f ? node.hi.z : node.lo.z);
  if (!(glm::dot(n, support - x) > 0.0f)) return 0.0;
  // Every light lies within its near distance: the box's farthest corner does.
  const glm::vec3 far = glm::max(glm::abs(x - node.lo), glm::abs(node.hi - x));
  const float near2 = node.near * node.near, farthest2 = glm::dot(far, far);
  if (farthest2 <= near2) return 0.0;
  // The share of their value the lights give at most: their rise at the farthest corner, from the smallest near
  // over the narrowest band (both only raise it).
  float share = 1.0f;
  if (node.width > 0.0f && farthest2 < node.full2) {
    const float t = std::min(1.0f, (std::sqrt(farthest2) - node.near) / node.width);
    share = t * t * (3.0f - 2.0f * t);
  }
  // A point light's own value at normal incidence, I/(π d²), from the box's centre, times a bound of the cosine
  // over the box (cos(θ − θb) ≤ cos θ + sin θb, θb the box's angular radius); d is kept from going below half the
  // box's diagonal (x inside the box) and the lights' near distance (where they give nothing), times the share. The
  // same scale as a single light's exact value, so a leaf and an inner node weigh alike. In float: an estimate
  // that only steers the walk (the draws weigh by their exact light), at the walk's every node.
  const glm::vec3 towards = node.centre - x;
  const float centre2 = glm::dot(towards, towards), radius2 = node.radius * node.radius;
  float cosine = 1.0f;
  if (centre2 > radius2) {
    const float inverse = 1.0f / std::sqrt(centre2);
    cosine = std::clamp((glm::dot(n, towards) + node.radius) * inverse, 0.0f, 1.0f);
  }
  const float d2 = std::max({centre2, radius2, near2, 1e-12f});
  return double(node.power * share * cosine / (float(kPi) * d2));
}

}  // namespace irbake
