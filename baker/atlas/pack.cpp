#include "atlas/pack.h"

#include "common/error.h"

#include <algorithm>
#include <atomic>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace irbake::atlas {
namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

constexpr double kMargin = 1e-3;  // texels; far above float32 rounding of uv1 on a 16k page (~1e-3 × 1)

// Convex hull (Andrew's monotone chain), counter-clockwise.
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  if (p.size() < 3) return p;
  std::vector<glm::dvec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross2(h[k - 1] - h[k - 2], p[i - 1] - h[k - 2]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

// Rotates the chart so its bounding box has the least area (an edge of the hull lies on the box).
void rotateToMinimumBox(ChartUv& chart) {
  const auto hull = convexHull(chart.uv);
  if (hull.size() < 3) return;
  double bestArea = 1e300, bestAngle = 0.0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const glm::dvec2 e = hull[(i + 1) % hull.size()] - hull[i];
    if (glm::length(e) <= 0.0) continue;
    const glm::dvec2 d = glm::normalize(e), n(-d.y, d.x);
    double lo0 = 1e300, hi0 = -1e300, lo1 = 1e300, hi1 = -1e300;
    for (const glm::dvec2& p : hull) {
      lo0 = std::min(lo0, glm::dot(p, d)); hi0 = std::max(hi0, glm::dot(p, d));
      lo1 = std::min(lo1, glm::dot(p, n)); hi1 = std::max(hi1, glm::dot(p, n));
    }
    const double area = (hi0 - lo0) * (hi1 - lo1);
    if (area < bestArea * (1.0 - 1e-6)) { bestArea = area; bestAngle = std::atan2(d.y, d.x); }
  }
  const double c = std::cos(-bestAngle), s = std::sin(-bestAngle);
  for (glm::dvec2& p : chart.uv) p = {c * p.x - s * p.y, s * p.x + c * p.y};
}

// One orientation of a chart as texels: the conservative mask and the padded mask as row runs.
struct Mask {
  int w = 0, h = 0;
  glm::dvec2 shift{0.0};  // added to the rotated uv so the chart sits in [0,w]×[0,h]
  std::vector<uint8_t> bits;  // w*h
  std::vector<std::vector<std::pair<int, int>>> paddedRuns;  // h+2p rows; columns relative to the chart origin
  std::vector<int> longestRun;  // per padded row: its longest run (a row of the page needs a free gap this long)
  int widestRow = 0;            // padded row with the longest run: tested first
  size_t texels = 0;
};

glm::dvec2 rotate90(const glm::dvec2& p, int quarterTurns) {
  switch (quarterTurns & 3) {
    case 1: return {-p.y, p.x};
    case 2: return {-p.x, -p.y};
    case 3: return {p.y, -p.x};
    default: return p;
  }
}

Mask buildMask(const ChartUv& chart, int quarterTurns, int padding) {
  Mask m;
  glm::dvec2 lo(1e300), hi(-1e300);
  for (const glm::dvec2& p : chart.uv) {
    const glm::dvec2 r = rotate90(p, quarterTurns);
    lo = glm::min(lo, r);
    hi = glm::max(hi, r);
  }
  const glm::dvec2 size = hi - lo;
  // kMargin keeps every chart a hair inside its texels, so float32 rounding of uv1 cannot reach a neighbour.
  m.w = std::max(1, int(std::ceil(size.x + 2 * kMargin)));
  m.h = std::max(1, int(std::ceil(size.y + 2 * kMargin)));
  m.shift = -lo + glm::dvec2(kMargin);
  m.bits.assign(size_t(m.w) * m.h, 0);
  for (const auto& c : chart.corner) {
    const glm::dvec2 a = rotate90(chart.uv[c[0]], quarterTurns) + m.shift, b = rotate90(chart.uv[c[1]], quarterTurns) + m.shift,
                     d = rotate90(chart.uv[c[2]], quarterTurns) + m.shift;
    const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, d.x}) - kMargin))), x1 = std::min(m.w - 1, int(std::ceil(std::max({a.x, b.x, d.x}) + kMargin)) - 1);
    const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, d.y}) - kMargin))), y1 = std::min(m.h - 1, int(std::ceil(std::max({a.y, b.y, d.y}) + kMargin)) - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (!m.bits[size_t(y) * m.w + x] && triangleOverlapsTexel(a, b, d, x, y, kMargin)) m.bits[size_t(y) * m.w + x] = 1;
  }
  m.texels = size_t(std::count(m.bits.begin(), m.bits.end(), uint8_t(1)));
  // Square dilation by the padding: horizontal then vertical, as runs per padded row.
  const int pw = m.w + 2 * padding, ph = m.h + 2 * padding;
  std::vector<uint8_t> horiz(size_t(pw) * m.h, 0), padded(size_t(pw) * ph, 0);
  for (int y = 0; y < m.h; ++y)
    for (int x = 0; x < m.w; ++x)
      if (m.bits[size_t(y) * m.w + x])
        for (int dx = 0; dx <= 2 * padding; ++dx) horiz[size_t(y) * pw + x + dx] = 1;
  for (int y = 0; y < m.h; ++y)
    for (int x = 0; x < pw; ++x)
      if (horiz[size_t(y) * pw + x])
        for (int dy = 0; dy <= 2 * padding; ++dy) padded[size_t(y + dy) * pw + x] = 1;
  m.paddedRuns.resize(size_t(ph));
  for (int y = 0; y < ph; ++y) {
    for (int x = 0; x < pw;) {
      if (!padded[size_t(y) * pw + x]) { ++x; continue; }
      int e = x;
      while (e + 1 < pw && padded[size_t(y) * pw + e + 1]) ++e;
      m.paddedRuns[size_t(y)].push_back({x - padding, e - padding});
      x = e + 1;
    }
  }
  m.longestRun.assign(size_t(ph), 0);
  for (int y = 0; y < ph; ++y) {
    for (const auto& [a, b] : m.paddedRuns[size_t(y)]) m.longestRun[size_t(y)] = std::max(m.longestRun[size_t(y)], b - a + 1);
    if (m.longestRun[size_t(y)] > m.longestRun[size_t(m.widestRow)]) m.widestRow = y;
  }
  return m;
}

// A page's occupancy (conservative chart texels, unpadded), one bit per texel.
class PageGrid {
 public:
  PageGrid(int width, int maxHeight) : width_(width), maxHeight_(maxHeight), words_((width + 63) / 64) {}
  int width() const { return width_; }
  int maxHeight() const { return maxHeight_; }
  int usedWidth() const { return usedW_; }
  int usedHeight() const { return usedH_; }

  // Highest set column in [lo, hi] of row y, or -1.
  int lastSet(int y, int lo, int hi) const {
    if (y < 0 || size_t(y) >= rowsUsed_ || lo > hi) return -1;
    const uint64_t* row = &bits_[size_t(y) * words_];
    int wHi = hi >> 6, wLo = lo >> 6;
    for (int w = wHi; w >= wLo; --w) {
      uint64_t word = row[w];
      if (w == wHi && (hi & 63) != 63) word &= (uint64_t(1) << ((hi & 63) + 1)) - 1;
      if (w == wLo) word &= ~uint64_t(0) << (lo & 63);
      if (word) return w * 64 + 63 - std::countl_zero(word);
    }
    return -1;
  }
  // Smallest z ≥ from where columns [z, z+length-1] are all free (z may run past the width).
  int nextFreeStretch(int y, int from, int length) const {
    if (y < 0 || size_t(y) >= rowsUsed_) return from;
    const uint64_t* row = &bits_[size_t(y) * words_];
    int z = from;
    for (;;) {
      z = nextWithValue(row, z, false);  // first free column
      if (z >= width_) return z;
      const int s = nextWithValue(row, z, true);  // first occupied column after it
      if (s - z >= length || s >= width_) return z;
      z = s;
    }
  }
  void set(int x, int y) {
    if (size_t(y) >= rowsUsed_) {
      rowsUsed_ = size_t(y) + 1;
      bits_.resize(rowsUsed_ * words_, 0);
      freeGap_.resize(rowsUsed_, width_);
    }
    bits_[size_t(y) * words_ + (x >> 6)] |= uint64_t(1) << (x & 63);
  }

  // Rows of the mask tested first: the one that last failed (a page row that is full stays full nearby).
  struct RowHints {
    size_t run = 0, gap = 0;  // padded rows tested first by the run scan and by the gap rejection
  };
  static RowHints hintsFor(const Mask& m, int padding) { return {size_t(padding), size_t(m.widestRow)}; }

  // Leftmost x where the padded mask with its chart's bottom row at page row y overlaps nothing, or -1.
  int fitInRow(const Mask& m, int padding, int y, RowHints& hints) const {
    // Cheap rejection: each padded row needs a free gap as long as its longest run somewhere in its page row
    // (runs that reach past the page edges are clipped, so only rows fully inside the page are tested).
    const int ph = int(m.paddedRuns.size());
    for (int i = 0; i < ph; ++i) {
      const size_t j = i == 0 ? hints.gap : (i == int(hints.gap) ? 0 : size_t(i));
      const int row = y - padding + int(j);
      if (row < 0 || size_t(row) >= rowsUsed_) continue;
      if (freeGap_[size_t(row)] < std::min(m.longestRun[j] - 2 * padding, width_)) {
        hints.gap = j;
        return -1;
      }
    }
    for (int x = 0; x + m.w <= width_;) {
      bool clear = true;
      for (size_t i = 0; i < m.paddedRuns.size() && clear; ++i) {
        const size_t j = i == 0 ? hints.run : (i == hints.run ? 0 : i);
        const int row = y - padding + int(j);
        for (const auto& [a, b] : m.paddedRuns[j]) {
          const int q = lastSet(row, std::max(0, x + a), std::min(width_ - 1, x + b));
          if (q >= 0) {
            // Every x whose run still reaches q fails; jump to where this run finds a long-enough gap.
            x = nextFreeStretch(row, q + 1, b - a + 1) - a;
            hints.run = j;
            clear = false;
            break;
          }
        }
      }
      if (clear) return x;
    }
    return -1;
  }
  // Where to start looking: an earlier chart about as large (both box sides ≥ 90% of it) found no room
  // below its row, so this one starts there. A heuristic (shapes differ): it costs a little density and
  // halves the packing time of scenes with many similar charts.
  int searchStart(const Mask& m) const {
    const int lo = std::min(m.w, m.h), hi = std::max(m.w, m.h);
    int y = 0;
    for (const auto& r : placedRows_)
      if (10 * lo >= 9 * r[0] && 10 * hi >= 9 * r[1]) y = std::max(y, r[2]);
    return y;
  }
  void place(const Mask& m, int x0, int y0) {
    // One entry per box size (the highest row): many charts share a size, and searchStart reads them all.
    const uint64_t size = uint64_t(std::min(m.w, m.h)) << 32 | uint32_t(std::max(m.w, m.h));
    auto [it, added] = rowOfSize_.try_emplace(size, placedRows_.size());
    if (added) placedRows_.push_back({std::min(m.w, m.h), std::max(m.w, m.h), y0});
    else placedRows_[it->second][2] = std::max(placedRows_[it->second][2], y0);
    for (int y = 0; y < m.h; ++y)
      for (int x = 0; x < m.w; ++x)
        if (m.bits[size_t(y) * m.w + x]) set(x0 + x, y0 + y);
    for (int y = 0; y < m.h; ++y) freeGap_[size_t(y0 + y)] = longestFreeGap(y0 + y);
    usedW_ = std::max(usedW_, x0 + m.w);
    usedH_ = std::max(usedH_, y0 + m.h);
  }

 private:
  // First column ≥ from whose bit equals value (width_ or more when none).
  int nextWithValue(const uint64_t* row, int from, bool value) const {
    for (int w = from >> 6; w < words_; ++w) {
      uint64_t word = value ? row[w] : ~row[w];
      if (w == (from >> 6)) word &= ~uint64_t(0) << (from & 63);
      if (word) return std::min(width_ + 64, w * 64 + std::countr_zero(word));
    }
    return width_ + 64;
  }
  int longestFreeGap(int y) const {
    const uint64_t* row = &bits_[size_t(y) * words_];
    int best = 0;
    for (int z = nextWithValue(row, 0, false); z < width_;) {
      const int s = std::min(width_, nextWithValue(row, z, true));
      best = std::max(best, s - z);
      if (s >= width_) break;
      z = nextWithValue(row, s, false);
    }
    return best;
  }
  std::vector<std::array<int, 3>> placedRows_;  // (short side, long side, highest row) of the placed box sizes
  std::unordered_map<uint64_t, size_t> rowOfSize_;  // box size -> its entry in placedRows_
  std::vector<int> freeGap_;  // per used row: its longest run of free columns
  int width_, maxHeight_, words_;
  size_t rowsUsed_ = 0;
  std::vector<uint64_t> bits_;
  int usedW_ = 0, usedH_ = 0;
};

int roundUp4(int v) { return std::max(4, (v + 3) / 4 * 4); }

struct Placement {
  int page = -1, quarterTurns = 0, x = 0, y = 0;
};

// The place of one chart on a page: of the turns, the one whose lowest fit has the lowest top (the earliest
// turn on a tie), at its leftmost position. Rows are tested in order of (top, turn), in waves of `wave` tops
// whose rows are tested in parallel; the first wave with a fit holds the answer, so any wave size (and thread
// count) gives the same place.
bool placeOnPage(const std::array<Mask, 4>& masks, const PageGrid& grid, int width, int maxPage, int padding, int wave,
                 Placement& out) {
  const int startY = grid.searchStart(masks[0]);
  std::array<bool, 4> usable{};
  std::array<PageGrid::RowHints, 4> hints{};
  int lowTop = maxPage + 1;
  for (size_t t = 0; t < 4; ++t) {
    usable[t] = masks[t].w <= width && masks[t].h <= maxPage;
    hints[t] = PageGrid::hintsFor(masks[t], padding);
    if (usable[t]) lowTop = std::min(lowTop, startY + masks[t].h);
  }
  std::vector<int> fitX;
  for (int firstTop = lowTop, size = 1; firstTop <= maxPage; firstTop += size, size = std::min(2 * size, wave)) {
    const int tops = std::min(size, maxPage - firstTop + 1), items = 4 * tops;
    std::atomic<int> best{items};  // the first item (in (top, turn) order) that fits
    fitX.assign(size_t(items), -1);
    auto test = [&](int i, PageGrid::RowHints& h) {
      const size_t t = size_t(i % 4);
      const int y = firstTop + i / 4 - masks[t].h;
      if (!usable[t] || y < startY || i > best.load(std::memory_order_relaxed)) return false;
      fitX[size_t(i)] = grid.fitInRow(masks[t], padding, y, h);
      if (fitX[size_t(i)] < 0) return false;
      for (int seen = best.load(std::memory_order_relaxed); i < seen && !best.compare_exchange_weak(seen, i);) {
      }
      return true;
    };
    if (items <= 4) {  // one top: in order, keeping each turn's hints from row to row
      for (int i = 0; i < items; ++i)
        if (test(i, hints[size_t(i % 4)])) break;
    } else {
      tbb::parallel_for(0, items, [&](int i) {
        PageGrid::RowHints h = hints[size_t(i % 4)];
        test(i, h);
      });
    }
    const int i = best.load();
    if (i < items) {
      const size_t t = size_t(i % 4);
      out.quarterTurns = int(t);
      out.x = fitX[size_t(i)];
      out.y = firstTop + i / 4 - masks[t].h;
      return true;
    }
  }
  return false;
}

// Packs masks (in order) into pages of the given width; returns the total page area.
double packAll(const std::vector<std::array<Mask, 4>>& masks, const std::vector<size_t>& order, int width, int maxPage,
               int padding, const std::atomic<double>& giveUp, std::vector<Placement>& placement,
               std::vector<PageGrid>& pages) {
  pages.clear();
  placement.assign(masks.size(), Placement{});
  // Tops tested at once: enough rows to keep the threads busy, one at a time on one thread.
  const int threads = std::min(tbb::this_task_arena::max_concurrency(),
                               int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  const int wave = threads > 1 ? std::max(2, threads / 2) : 1;
  for (size_t c : order) {
    for (int p = 0;; ++p) {
      if (p == int(pages.size())) pages.emplace_back(width, maxPage);
      Placement where;
      if (placeOnPage(masks[c], pages[size_t(p)], width, maxPage, padding, wave, where)) {
        where.page = p;
        pages[size_t(p)].place(masks[c][size_t(where.quarterTurns)], where.x, where.y);
        placement[c] = where;
        break;
      }
      if (pages[size_t(p)].usedHeight() == 0)  // cannot happen: charts are scaled to fit a page
        throw Error(ErrorCode::InvalidData, "", "atlas: a chart does not fit an empty page");
    }
    // Pages only grow: once this trial is larger than a finished one it cannot win (strictly larger: an equal
    // area may still win the tie, which goes to the narrower width whatever order the trials finish in).
    double partial = 0.0;
    for (const PageGrid& g : pages) partial += double(roundUp4(g.usedWidth())) * roundUp4(g.usedHeight());
    if (partial > giveUp.load(std::memory_order_relaxed)) return 1e300;
  }
  double area = 0.0;
  for (const PageGrid& g : pages) area += double(roundUp4(g.usedWidth())) * roundUp4(g.usedHeight());
  return area;
}

}  // namespace

bool triangleOverlapsTexel(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, int x, int y, double margin) {
  const double x0 = x - margin, x1 = x + 1.0 + margin, y0 = y - margin, y1 = y + 1.0 + margin;
  if (std::max({a.x, b.x, c.x}) <= x0 || std::min({a.x, b.x, c.x}) >= x1) return false;
  if (std::max({a.y, b.y, c.y}) <= y0 || std::min({a.y, b.y, c.y}) >= y1) return false;
  double area = cross2(b - a, c - a);
  if (area == 0.0) return true;  // a segment or point: its box test above is the conservative answer
  if (area < 0.0) std::swap(b, c);
  const glm::dvec2 v[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    const glm::dvec2 p = v[k], e = v[(k + 1) % 3] - v[k];
    // Inside is left of the edge: cross(e, q - p) > 0. Take the box corner that maximises it.
    const double qx = e.y < 0.0 ? x1 : x0, qy = e.x > 0.0 ? y1 : y0;
    if (e.x * (qy - p.y) - e.y * (qx - p.x) <= 0.0) return false;
  }
  return true;
}

PackResult packCharts(std::vector<ChartUv>& charts, const PackOptions& options) {
  PackResult result;
  const int pad = std::max(0, options.padding);
  const int limit = std::max(8, options.maxPageSize);
  std::vector<std::array<Mask, 4>> masks(charts.size());
  std::vector<double> scaledFrom(charts.size(), 0.0);  // a chart's longest side before it was scaled to fit a page
  // Per chart, then per (chart, turn): each writes its own slot, so the masks do not depend on the thread count.
  tbb::parallel_for(size_t(0), charts.size(), [&](size_t i) {
    ChartUv& chart = charts[i];
    for (glm::dvec2& p : chart.uv) p *= options.texelsPerUnit;
    rotateToMinimumBox(chart);
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const glm::dvec2& p : chart.uv) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
    const double longest = std::max(hi.x - lo.x, hi.y - lo.y);
    if (longest > limit - 2) {  // keep the chart whole: scale it to fit a page
      const double s = (limit - 2) / longest;
      for (glm::dvec2& p : chart.uv) p = lo + (p - lo) * s;
      scaledFrom[i] = longest;
    }
  });
  tbb::parallel_for(size_t(0), 4 * charts.size(), [&](size_t k) {
    masks[k / 4][k % 4] = buildMask(charts[k / 4], int(k % 4), pad);
  });
  double paddedArea = 0.0;
  int widest = 1;
  for (size_t i = 0; i < charts.size(); ++i) {
    if (scaledFrom[i] > 0.0)
      result.warnings.push_back("a chart of " + std::to_string(int(std::ceil(scaledFrom[i]))) + " texels was scaled by " +
                                std::to_string((limit - 2) / scaledFrom[i]) + " to fit a " + std::to_string(limit) + "-texel page");
    const Mask& m = masks[i][0];
    paddedArea += double(m.w + pad) * double(m.h + pad);
    widest = std::max(widest, std::min(m.w, m.h));
  }
  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return size_t(masks[a][0].w) * masks[a][0].h > size_t(masks[b][0].w) * masks[b][0].h;
  });

  // Width trials around the square that would hold every padded chart box.
  std::vector<int> widths;
  const double side = std::sqrt(paddedArea);
  if (side >= limit) {
    widths.push_back(limit);
  } else {
    for (int i = 0; i < std::max(1, options.widthTrials); ++i) {
      const double f = 0.85 + 0.1 * i;
      widths.push_back(std::clamp(roundUp4(int(std::ceil(side * f))), roundUp4(widest), limit));
    }
    std::sort(widths.begin(), widths.end());
    widths.erase(std::unique(widths.begin(), widths.end()), widths.end());
  }
  // The trials run in parallel (a level has thousands of charts); a finished trial's area lets
  // the others give up early; the smallest area wins, the narrowest width on a tie.
  struct Trial {
    double area = 1e300;
    std::vector<Placement> placement;
    std::vector<PageGrid> grids;
  };
  std::vector<Trial> trials(widths.size());
  std::atomic<double> finished{1e300};
  tbb::parallel_for(size_t(0), widths.size(), [&](size_t i) {
    Trial& t = trials[i];
    t.area = packAll(masks, order, widths[i], limit, pad, finished, t.placement, t.grids);
    for (double seen = finished.load(); t.area < seen && !finished.compare_exchange_weak(seen, t.area);) {
    }
  });
  size_t winner = 0;
  for (size_t i = 1; i < trials.size(); ++i)
    if (trials[i].area < trials[winner].area) winner = i;
  const std::vector<Placement>& best = trials[winner].placement;
  const std::vector<PageGrid>& bestGrids = trials[winner].grids;
  for (const PageGrid& g : bestGrids) result.pages.push_back({roundUp4(g.usedWidth()), roundUp4(g.usedHeight())});
  result.chartPage.resize(charts.size());
  for (size_t i = 0; i < charts.size(); ++i) {
    const Placement& p = best[i];
    const Mask& m = masks[i][size_t(p.quarterTurns)];
    for (glm::dvec2& uv : charts[i].uv) uv = rotate90(uv, p.quarterTurns) + m.shift + glm::dvec2(p.x, p.y);
    result.chartPage[i] = p.page;
  }
  return result;
}

}  // namespace irbake::atlas
