// A binary tree over positional lights that picks one in proportion to what it gives a point, for sampling many
// lights stochastically (after Conty Estevez and Kulla, "Importance Sampling of Many Lights", 2018, without
// orientation cones: the lights here are points). Each node keeps its lights' bounding box, their summed power and
// the band over which its lights' values rise from nothing (the light a cut leaves out rises over the cut's fade).
// Sampling walks down from the root, at each node choosing among its descendants kChoiceLevels levels down (a
// branch that ends in a single light sooner stands there for itself) in proportion to an estimate of what their
// lights give the point; a single light is weighed by the caller's exact value. Choosing among sixteen at once
// rather than between two halves: a large box's estimate is loose, its descendants' are tighter, and each step
// of the walk goes four levels down.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace irbake {

struct LightTreeEntry {
  uint32_t light = 0;       // the caller's index
  glm::vec3 position{0.0f};
  float power = 0.0f;       // the light's intensity (W/sr, the caller's channel weighting): its value at distance d
                            // and normal incidence is power / (π d²), on the scale of the caller's exact values
  float near = 0.0f;        // within this distance the light gives nothing the caller samples
  float far = 0.0f;         // beyond it, all of its value; in between a share that rises no faster than
                            // smoothstep((d − near) / (far − near)) (far ≤ near: a step at near)
};

class LightTree {
 public:
  LightTree() = default;
  explicit LightTree(std::vector<LightTreeEntry> entries);
  bool empty() const { return nodes_.empty(); }
  size_t size() const { return entries_.size(); }

  static constexpr int kChoiceLevels = 4;                // levels a walk's step goes down
  static constexpr int kChoices = 1 << kChoiceLevels;  // the most choices one step weighs
  struct Choice {
    uint32_t light = UINT32_MAX;  // UINT32_MAX: no light gives the point anything
    double pmf = 0.0;             // the probability of this light
  };
  // One light for the point x with unit normal n, from a uniform u in [0, 1); exact(light) is the non-negative
  // value that light gives x (it weighs a choice that is a single light). Every light
  // whose exact value is positive has a positive probability, so value / pmf is unbiased.
  template <class Exact>
  Choice sample(const glm::vec3& x, const glm::vec3& n, double u, Exact&& exact) const {
    Choice c;
    if (nodes_.empty()) return c;
    int32_t at = 0;
    double pmf = 1.0;
    while (nodes_[size_t(at)].left >= 0) {
      int32_t next[kChoices];
      double w[kChoices];
      int count = 0;
      const double total = weighChoices(nodes_[size_t(at)], x, n, exact, next, w, count);
      if (!(total > 0.0)) return c;
      // The choice whose share of the total holds u, u rescaled to it.
      const double target = u * total;
      double below = 0.0;
      int i = 0;
      while (i + 1 < count && !(target < below + w[i])) below += w[i++];
      while (!(w[i] > 0.0)) --i, below -= w[i];  // u on the top rounding edge of a last choice that gives nothing
      at = next[i], pmf *= w[i] / total;
      u = (target - below) / w[i];
      u = u < 0.0 ? 0.0 : u < 1.0 ? u : 0x1.fffffffffffffp-1;
    }
    const LightTreeEntry& e = entries_[nodes_[size_t(at)].entry];
    if (nodes_.size() == 1 && !(exact(e.light) > 0.0)) return c;
    c.light = e.light;
    c.pmf = pmf;
    return c;
  }
  // What sample() gives each of u_k = (k + shift) / m, k < m (stratified draws), walking every node once for all
  // of them: take(k, choice) for each k whose light gives x anything, in order of k, after the walk weighed that
  // light by exact(light), mostly within the last kChoices weighings (a caller may keep its recent values).
  template <class Exact, class Take>
  void sampleStratified(const glm::vec3& x, const glm::vec3& n, double shift, int m, Exact&& exact, Take&& take) const {
    auto one = [&](int, int k, const Choice& c) { take(k, c); };
    sampleSets<1>(x, n, &shift, &m, exact, one);
  }
  // Two independent sets of stratified draws at the same point, in one walk: what sampleStratified gives each set
  // (set s: m[s] draws from shift[s]), each node weighed once for both. take(s, k, choice) as there, per set.
  template <class Exact, class Take>
  void sampleStratifiedPair(const glm::vec3& x, const glm::vec3& n, const double shift[2], const int m[2], Exact&& exact,
                            Take&& take) const {
    sampleSets<2>(x, n, shift, m, exact, take);
  }
  // The probability that sample() picks `light` at (x, n) (0 for a light not in the tree).
  template <class Exact>
  double pmf(const glm::vec3& x, const glm::vec3& n, uint32_t light, Exact&& exact) const {
    if (nodes_.empty()) return 0.0;
    return pmfBelow(0, x, n, light, exact);
  }

 private:
  struct Node {
    glm::vec3 lo{0.0f}, hi{0.0f};
    float power = 0.0f, near = 0.0f, width = 0.0f;  // the lights' smallest near and far − near
    float radius = 0.0f;                              // half the box's diagonal
    glm::vec3 centre{0.0f};                           // the box's
    float full2 = 0.0f;                               // (near + width)²: from there on the share is 1
    int32_t left = -1, right = -1;  // children; -1: a leaf holding entries_[entry]
    uint32_t entry = 0;
  };
  int32_t build(size_t begin, size_t end);
  // An estimate of what the node's lights give x, on the scale of a single light's value: 0 where every light
  // lies behind the plane of (x, n) or within its own near distance of x.
  double importance(const Node& node, const glm::vec3& x, const glm::vec3& n) const;
  template <class Exact>
  double weight(int32_t child, const glm::vec3& x, const glm::vec3& n, Exact&& exact) const {
    const Node& node = nodes_[size_t(child)];
    if (node.left < 0) {
      const double v = exact(entries_[node.entry].light);
      return v > 0.0 ? v : 0.0;
    }
    return importance(node, x, n);
  }
  // One set's draws k in [k0, k1), the k-th at u[k] = (k + shift) / m.
  struct Draws {
    int k0, k1;
    const double* u;
  };
  template <int Sets, class Exact, class Take>
  void sampleSets(const glm::vec3& x, const glm::vec3& n, const double* shift, const int* m, Exact& exact, Take& take) const {
    int any = 0;
    for (int s = 0; s < Sets; ++s) any += std::max(m[s], 0);
    if (nodes_.empty() || any == 0) return;
    if (nodes_.size() == 1) {
      if (exact(entries_[0].light) > 0.0)
        for (int s = 0; s < Sets; ++s)
          for (int k = 0; k < m[s]; ++k) take(s, k, Choice{entries_[0].light, 1.0});
      return;
    }
    // The draws' positions, computed once: the walk compares them at every node it splits.
    constexpr int kLocal = 128;
    double local[Sets][kLocal];
    std::vector<double> heap[Sets];
    Draws draws[Sets];
    for (int s = 0; s < Sets; ++s) {
      const int count = std::max(m[s], 0);
      double* u = count <= kLocal ? local[s] : (heap[s].resize(size_t(count)), heap[s].data());
      for (int k = 0; k < count; ++k) u[k] = (k + shift[s]) / m[s];
      draws[s] = {0, count, u};
    }
    descend<Sets>(0, 1.0, 0.0, 1.0, draws, x, n, exact, take);
  }
  // The draws whose u lie in [lo, hi), through node `at` reached with probability pmf; a node is visited while any
  // set has draws through it, and weighed once for all.
  template <int Sets, class Exact, class Take>
  void descend(int32_t at, double pmf, double lo, double hi, const Draws* draws, const glm::vec3& x, const glm::vec3& n,
               Exact& exact, Take& take) const {
    const Node& node = nodes_[size_t(at)];
    if (node.left < 0) {
      for (int s = 0; s < Sets; ++s)
        for (int k = draws[s].k0; k < draws[s].k1; ++k) take(s, k, Choice{entries_[node.entry].light, pmf});
      return;
    }
    int32_t next[kChoices];
    double w[kChoices];
    int count = 0;
    const double total = weighChoices(node, x, n, exact, next, w, count);
    if (!(total > 0.0)) return;
    Draws part[Sets];
    for (int s = 0; s < Sets; ++s) part[s] = draws[s];
    int last = count - 1;  // the last choice that gives anything ends at hi (sample() goes there on the top edge)
    while (!(w[last] > 0.0)) --last;
    double below = 0.0, from = lo;
    for (int i = 0; i < count; ++i) {
      below += w[i];
      const double to = i < last ? lo + below / total * (hi - lo) : hi;
      bool any = false;
      for (int s = 0; s < Sets; ++s) {
        int ks = part[s].k0;
        const int end = draws[s].k1;
        while (ks < end && part[s].u[ks] < to) ++ks;
        part[s].k1 = ks;
        any |= ks > part[s].k0;
      }
      if (any && w[i] > 0.0) descend<Sets>(next[i], pmf * (w[i] / total), from, to, part, x, n, exact, take);
      for (int s = 0; s < Sets; ++s) part[s].k0 = part[s].k1;
      from = to;
    }
  }
  // The node's choices (choices()) into next[0, count), each weighed (weight()) into w; returns their sum.
  template <class Exact>
  double weighChoices(const Node& node, const glm::vec3& x, const glm::vec3& n, Exact& exact, int32_t next[kChoices],
                      double w[kChoices], int& count) const {
    count = choices(node, next);
    double total = 0.0;
    for (int i = 0; i < count; ++i) total += w[i] = weight(next[i], x, n, exact);
    return total;
  }
  // A node's choices: its descendants kChoiceLevels levels down (a single light sooner stands for itself).
  int choices(const Node& node, int32_t next[kChoices]) const {
    int count = 2;
    next[0] = node.left, next[1] = node.right;
    for (int level = 1; level < kChoiceLevels; ++level) {
      int32_t below[kChoices];
      int k = 0;
      for (int i = 0; i < count; ++i) {
        const Node& c = nodes_[size_t(next[i])];
        if (c.left < 0) below[k++] = next[i];
        else below[k++] = c.left, below[k++] = c.right;
      }
      std::copy(below, below + k, next);
      count = k;
    }
    return count;
  }
  template <class Exact>
  double pmfBelow(int32_t at, const glm::vec3& x, const glm::vec3& n, uint32_t light, Exact&& exact) const {
    const Node& node = nodes_[size_t(at)];
    if (node.left < 0) return entries_[node.entry].light == light ? 1.0 : 0.0;
    int32_t next[kChoices];
    double w[kChoices];
    int count = 0;
    const double total = weighChoices(node, x, n, exact, next, w, count);
    if (!(total > 0.0)) return 0.0;
    double p = 0.0;
    for (int i = 0; i < count; ++i)
      if (w[i] > 0.0) p += w[i] / total * pmfBelow(next[i], x, n, light, exact);
    return p;
  }

  std::vector<LightTreeEntry> entries_;
  std::vector<Node> nodes_;
};

}  // namespace irbake
