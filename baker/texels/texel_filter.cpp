#include "texels/texel_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "texels/contact_cuts.h"

namespace irbake {

SurfaceFilter::SurfaceFilter(const TexelSamples& ts) : width_(ts.width), height_(ts.height) {
  const size_t layer = ts.layerSize();
  position_.assign(layer, glm::vec3(0.0f));
  normal_.assign(layer, glm::vec3(0.0f));
  hasSample_.assign(layer, 0);
  tbb::parallel_for(size_t(0), layer, [&](size_t t) {
    if (!texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.positionWeight[s]); }, position_[t])) return;
    texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.normal[s]); }, normal_[t]);
    const float len = glm::length(normal_[t]);
    if (len > 0.0f) normal_[t] /= len;
    hasSample_[t] = 1;
  });
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
  if (!d.empty()) {
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    spacing_ = d[d.size() / 2];
  }
  if (ts.cut.size() != layer) return;
  rowCuts_.assign(layer, 0);
  colCuts_.assign(layer, 0);
  tbb::parallel_for(0, H, [&](int y) {  // each row's counts
    for (int x = 1; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      rowCuts_[i] = rowCuts_[i - 1] + ((ts.cut[i - 1] & kCutRight) ? 1u : 0u);
    }
  });
  tbb::parallel_for(0, W, [&](int x) {  // each column's counts
    for (int y = 1; y < H; ++y) {
      const size_t i = static_cast<size_t>(y) * W + x;
      colCuts_[i] = colCuts_[i - W] + ((ts.cut[i - W] & kCutDown) ? 1u : 0u);
    }
  });
}

bool SurfaceFilter::uncut(int x, int y, int dx, int dy) const {
  const size_t W = static_cast<size_t>(width_);
  auto rowClear = [&](int row, int x0, int x1) {
    return rowCuts_[row * W + std::max(x0, x1)] == rowCuts_[row * W + std::min(x0, x1)];
  };
  auto colClear = [&](int col, int y0, int y1) {
    return colCuts_[std::max(y0, y1) * W + col] == colCuts_[std::min(y0, y1) * W + col];
  };
  return (rowClear(y, x, x + dx) && colClear(x + dx, y, y + dy)) || (colClear(x, y, y + dy) && rowClear(y + dy, x, x + dx));
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
  if (glm::dot(d, d) > unit * unit * static_cast<float>(dx * dx + dy * dy)) return false;
  return rowCuts_.empty() || uncut(static_cast<int>(i % width_), static_cast<int>(i / width_), dx, dy);
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
    : radius_(std::max(0, options.radius)),
      unchanged_(!(filter.spacing_ > 0.0f)),  // as SurfaceFilter::apply leaves such a page
      options_(options),
      hasSample_(filter.hasSample_) {
  if (radius_ > kMaxRadius) throw std::invalid_argument("SurfaceFilterPlan: radius above kMaxRadius");
  const int W = filter.width_, H = filter.height_, r = radius_;
  for (int dy = 0; dy <= r; ++dy)  // forward: the rest of the centre's row, then the rows below
    for (int dx = dy == 0 ? 1 : -r; dx <= r; ++dx) {
      offset_.push_back(static_cast<ptrdiff_t>(dy) * W + dx);
      dx_.push_back(dx);
      dy_.push_back(dy);
    }
  const size_t layer = static_cast<size_t>(W) * H;
  forward_.assign(layer, 0);
  backward_.assign(layer, 0);
  const int neighbours = static_cast<int>(offset_.size());
  // Forward: each pair tested once, from its earlier texel.
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (i >= valid.size() || !valid[i] || !hasSample_[i]) continue;  // not filtered: passed unchanged
      uint64_t bits = kFiltered;
      if (!unchanged_)
        for (int k = 0; k < neighbours; ++k) {
          const int xx = x + dx_[k], yy = y + dy_[k];
          if (xx < 0 || xx >= W || yy >= H) continue;
          const size_t j = i + offset_[k];
          if (j < valid.size() && filter.accepts(i, j, dx_[k], dy_[k], valid, options_)) bits |= uint64_t(1) << k;
        }
      forward_[i] = bits;
    }
  });
  // Backward: the same pair read from the later texel (accepts() is symmetric for two filtered texels).
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!(forward_[i] & kFiltered)) continue;
      uint64_t bits = 0;
      for (int k = 0; k < neighbours; ++k) {
        const int xx = x - dx_[k], yy = y - dy_[k];
        if (xx < 0 || xx >= W || yy < 0) continue;
        if ((forward_[i - offset_[k]] >> k) & 1) bits |= uint64_t(1) << k;
      }
      backward_[i] = bits;
    }
  });
}

bool SurfaceFilterPlan::serves(const std::vector<uint8_t>& valid, const TexelFilterOptions& options) const {
  if (std::max(0, options.radius) > radius_ || options.minNormalCos != options_.minNormalCos ||
      options.maxSpacings != options_.maxSpacings)
    return false;
  if (valid.size() != forward_.size()) return false;
  for (size_t i = 0; i < valid.size(); ++i)
    if ((valid[i] && hasSample_[i]) != static_cast<bool>(forward_[i] & kFiltered)) return false;
  return true;
}

std::vector<glm::vec3> SurfaceFilterPlan::apply(const std::vector<glm::vec3>& values) const {
  return apply(values, options_);
}

std::vector<glm::vec3> SurfaceFilterPlan::apply(const std::vector<glm::vec3>& values, const TexelFilterOptions& options) const {
  return std::move(apply(std::vector<const std::vector<glm::vec3>*>{&values}, options)[0]);
}

std::vector<std::vector<glm::vec3>> SurfaceFilterPlan::apply(const std::vector<const std::vector<glm::vec3>*>& sets,
                                                             const TexelFilterOptions& options) const {
  std::vector<std::vector<glm::vec3>> out;
  for (const std::vector<glm::vec3>* values : sets) out.push_back(*values);
  const int r = std::max(0, options.radius);
  if (r > radius_) throw std::invalid_argument("SurfaceFilterPlan: radius above the plan's");
  if (r == 0 || unchanged_) return out;
  // The window of radius r inside the plan's: its forward neighbours and their weights (the mirror's alike).
  uint64_t window = 0;
  std::array<float, 64> weight{};
  for (size_t k = 0; k < offset_.size(); ++k)
    if (std::abs(dx_[k]) <= r && dy_[k] <= r) {
      window |= uint64_t(1) << k;
      weight[k] = windowWeight(options, r, dx_[k], dy_[k]);
    }
  const float centreWeight = windowWeight(options, r, 0, 0);
  const bool symmetric = options.symmetric;
  const size_t layer = forward_.size(), setCount = sets.size();
  // Calls add(j, w) for texel i's window in row-major order, as SurfaceFilter::apply sums (so the sums round
  // alike): the mirror images of the forward neighbours last to first, the centre, the forward neighbours.
  auto forEachInWindow = [&](size_t i, auto&& add) {
    uint64_t ahead = forward_[i] & window, behind = backward_[i] & window;
    if (symmetric) ahead = behind = ahead & behind;
    for (uint64_t bits = behind; bits != 0;) {
      const int k = 63 - __builtin_clzll(bits);
      bits &= ~(uint64_t(1) << k);
      add(i - offset_[k], weight[k]);
    }
    add(i, centreWeight);
    for (uint64_t bits = ahead; bits != 0; bits &= bits - 1) {
      const int k = __builtin_ctzll(bits);
      add(i + offset_[k], weight[k]);
    }
  };
  // Up to four sets with their count known to the compiler (sums in registers, no per-set indirection); the
  // sums per set are the same either way.
  auto filterFixed = [&](auto sets_) {
    constexpr size_t N = decltype(sets_)::value;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, layer, 4096), [&](const tbb::blocked_range<size_t>& range) {
      const glm::vec3* values[N];
      for (size_t s = 0; s < N; ++s) values[s] = sets[s]->data();
      for (size_t i = range.begin(); i != range.end(); ++i) {
        if (!(forward_[i] & kFiltered)) continue;
        glm::vec3 sum[N];
        for (size_t s = 0; s < N; ++s) sum[s] = glm::vec3(0.0f);
        float count = 0.0f;
        forEachInWindow(i, [&](size_t j, float w) {
          for (size_t s = 0; s < N; ++s) sum[s] += w * values[s][j];
          count += w;
        });
        for (size_t s = 0; s < N; ++s) out[s][i] = sum[s] / count;
      }
    });
  };
  switch (setCount) {
    case 1: filterFixed(std::integral_constant<size_t, 1>{}); return out;
    case 2: filterFixed(std::integral_constant<size_t, 2>{}); return out;
    case 3: filterFixed(std::integral_constant<size_t, 3>{}); return out;
    case 4: filterFixed(std::integral_constant<size_t, 4>{}); return out;
    default: break;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, layer, 4096), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<glm::vec3> sum(setCount);
    for (size_t i = range.begin(); i != range.end(); ++i) {
      if (!(forward_[i] & kFiltered)) continue;
      std::fill(sum.begin(), sum.end(), glm::vec3(0.0f));
      float count = 0.0f;
      forEachInWindow(i, [&](size_t j, float w) {
        for (size_t s = 0; s < setCount; ++s) sum[s] += w * (*sets[s])[j];
        count += w;
      });
      for (size_t s = 0; s < setCount; ++s) out[s][i] = sum[s] / count;
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
