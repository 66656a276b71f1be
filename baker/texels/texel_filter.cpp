#include "texels/texel_filter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace irbake {

SurfaceFilter::SurfaceFilter(const TexelSamples& ts) : width_(ts.width), height_(ts.height) {
  const size_t layer = ts.layerSize();
  position_.assign(layer, glm::vec3(0.0f));
  normal_.assign(layer, glm::vec3(0.0f));
  hasSample_.assign(layer, 0);
  for (size_t t = 0; t < layer; ++t) {
    if (!texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.positionWeight[s]); }, position_[t])) continue;
    texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.normal[s]); }, normal_[t]);
    const float len = glm::length(normal_[t]);
    if (len > 0.0f) normal_[t] /= len;
    hasSample_[t] = 1;
  }
  // Spacing: median over every other texel's right and lower neighbours on the same surface.
  std::vector<float> d;
  const int W = width_, H = height_;
  auto ok = [&](size_t i) { return i < ts.valid.size() && ts.valid[i] && hasSample_[i]; };
  for (int y = 0; y < H; y += 2)
    for (int x = 0; x < W; x += 2) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!ok(i)) continue;
      for (size_t j : {i + 1, i + static_cast<size_t>(W)}) {
        if ((j == i + 1 && x + 1 >= W) || (j != i + 1 && y + 1 >= H) || !ok(j)) continue;
        if (glm::dot(normal_[i], normal_[j]) < 0.99f) continue;
        d.push_back(glm::length(position_[i] - position_[j]));
      }
    }
  if (d.empty()) return;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  spacing_ = d[d.size() / 2];
}

std::vector<glm::vec3> SurfaceFilter::apply(const std::vector<glm::vec3>& values, const std::vector<uint8_t>& valid,
                                            const TexelFilterOptions& options) const {
  return std::move(apply(std::vector<const std::vector<glm::vec3>*>{&values}, valid, options)[0]);
}

// Inlined: called once per window position per texel, the filter's inner loop.
[[gnu::always_inline]] inline bool SurfaceFilter::accepts(size_t i, size_t j, int dx, int dy,
                                                         const std::vector<uint8_t>& valid,
                                                         const TexelFilterOptions& options) const {
  if (!valid[j] || !hasSample_[j]) return false;
  if (j == i) return true;
  if (glm::dot(normal_[i], normal_[j]) < options.minNormalCos) return false;
  const float unit = options.maxSpacings * spacing_;  // reach = unit × |(dx, dy)|, compared squared
  const glm::vec3 d = position_[j] - position_[i];
  return glm::dot(d, d) <= unit * unit * static_cast<float>(dx * dx + dy * dy);
}

template <class Visit>
void SurfaceFilter::forEachAccepted(int x, int y, int r, const std::vector<uint8_t>& valid,
                                    const TexelFilterOptions& options, Visit&& visit) const {
  const int W = width_, H = height_;
  const size_t i = static_cast<size_t>(y) * W + x;
  // The window's positions inside the page, row by row, with i's own test.
  auto forEachTested = [&](auto&& f) {
    for (int dy = -r; dy <= r; ++dy) {
      const int yy = y + dy;
      if (yy < 0 || yy >= H) continue;
      for (int dx = -r; dx <= r; ++dx) {
        const int xx = x + dx;
        if (xx < 0 || xx >= W) continue;
        const size_t j = static_cast<size_t>(yy) * W + xx;
        if (accepts(i, j, dx, dy, valid, options)) f(j, dx, dy);
      }
    }
  };
  constexpr int kBitRadius = 8;  // windows up to 17² = 289 positions: 5 words of bits
  if (options.symmetric && r <= kBitRadius) {
    // Each window position tested once; a position counts with its mirror image (−dx, −dy), which is position
    // n − 1 − b in row-major order: half the tests of testing each mirror again, the same set in the same order.
    const int side = 2 * r + 1, n = side * side;
    uint64_t bits[5] = {0, 0, 0, 0, 0};
    forEachTested([&](size_t, int dx, int dy) {
      const int b = (dy + r) * side + (dx + r);
      bits[b >> 6] |= uint64_t(1) << (b & 63);
    });
    auto has = [&](int b) { return (bits[b >> 6] >> (b & 63)) & 1; };
    for (int b = 0; b < n; ++b) {
      if (!has(b) || !has(n - 1 - b)) continue;
      const int dy = b / side - r, dx = b % side - r;
      visit(static_cast<size_t>(static_cast<ptrdiff_t>(i) + static_cast<ptrdiff_t>(dy) * W + dx), dx, dy);
    }
    return;
  }
  forEachTested([&](size_t j, int dx, int dy) {
    if (options.symmetric && j != i) {  // windows wider than the bits hold: the mirror tested again
      const int mx = x - dx, my = y - dy;
      if (mx < 0 || my < 0 || mx >= W || my >= H) return;
      if (!accepts(i, static_cast<size_t>(my) * W + mx, -dx, -dy, valid, options)) return;
    }
    visit(j, dx, dy);
  });
}

namespace {
float windowWeight(const TexelFilterOptions& options, int r, int dx, int dy) {
  return options.tent ? static_cast<float>((r + 1 - std::abs(dx)) * (r + 1 - std::abs(dy))) : 1.0f;
}
}  // namespace

std::vector<std::vector<glm::vec3>> SurfaceFilter::apply(const std::vector<const std::vector<glm::vec3>*>& sets,
                                                         const std::vector<uint8_t>& valid,
                                                         const TexelFilterOptions& options) const {
  std::vector<std::vector<glm::vec3>> out;
  for (const std::vector<glm::vec3>* values : sets) out.push_back(*values);
  const int r = std::max(0, options.radius);
  if (r == 0 || !(spacing_ > 0.0f)) return out;
  const int W = width_, H = height_;
  const size_t setCount = sets.size();
  tbb::parallel_for(0, H, [&](int y) {
    std::vector<glm::vec3> sum(setCount);
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!valid[i] || !hasSample_[i]) continue;
      std::fill(sum.begin(), sum.end(), glm::vec3(0.0f));
      float count = 0.0f;
      forEachAccepted(x, y, r, valid, options, [&](size_t j, int dx, int dy) {
        const float w = windowWeight(options, r, dx, dy);
        for (size_t s = 0; s < setCount; ++s) sum[s] += w * (*sets[s])[j];
        count += w;
      });
      for (size_t s = 0; s < setCount; ++s) out[s][i] = sum[s] / count;
    }
  });
  return out;
}

SurfaceFilterPlan::SurfaceFilterPlan(const SurfaceFilter& filter, const std::vector<uint8_t>& valid,
                                     const TexelFilterOptions& options)
    : radius_(std::max(0, options.radius)) {
  if (radius_ > kMaxRadius) throw std::invalid_argument("SurfaceFilterPlan: radius above kMaxRadius");
  if (!(filter.spacing_ > 0.0f)) radius_ = 0;  // SurfaceFilter::apply returns such a page unchanged
  const int W = filter.width_, H = filter.height_, r = radius_, side = 2 * r + 1;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      offset_.push_back(static_cast<ptrdiff_t>(dy) * W + dx);
      weight_.push_back(windowWeight(options, r, dx, dy));
    }
  const size_t layer = static_cast<size_t>(W) * H;
  accepted_.assign(layer, {0, 0});
  if (r == 0) return;
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!valid[i] || !filter.hasSample_[i]) continue;  // no bits: passed unchanged
      filter.forEachAccepted(x, y, r, valid, options, [&](size_t, int dx, int dy) {
        const int b = (dy + r) * side + (dx + r);
        accepted_[i][b >> 6] |= uint64_t(1) << (b & 63);
      });
    }
  });
}

std::vector<glm::vec3> SurfaceFilterPlan::apply(const std::vector<glm::vec3>& values) const {
  std::vector<glm::vec3> out = values;
  if (radius_ == 0) return out;
  const size_t layer = accepted_.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, layer, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      // A filtered texel always accepts itself, so no bits means: not filtered, value passes unchanged.
      if ((accepted_[i][0] | accepted_[i][1]) == 0) continue;
      glm::vec3 sum(0.0f);
      float count = 0.0f;
      // Bits in window order (row by row), so the sums round exactly as SurfaceFilter::apply's.
      for (int word = 0; word < 2; ++word)
        for (uint64_t bits = accepted_[i][word]; bits != 0; bits &= bits - 1) {
          const int b = 64 * word + __builtin_ctzll(bits);
          const float w = weight_[b];
          sum += w * values[static_cast<size_t>(static_cast<ptrdiff_t>(i) + offset_[b])];
          count += w;
        }
      out[i] = sum / count;
    }
  });
  return out;
}

float texelSpacing(const TexelSamples& ts) { return SurfaceFilter(ts).spacing(); }

std::vector<glm::vec3> filterOnSurface(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  return SurfaceFilter(ts).apply(values, valid, options);
}

}  // namespace irbake
