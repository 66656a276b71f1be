#include "atlas/charts.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <queue>

namespace irbake::atlas {
namespace {

glm::dvec3 centroidOf(const AtlasMesh& mesh, uint32_t f) {
  const auto& v = mesh.faceVertex[f];
  return (mesh.vertexPos[v[0]] + mesh.vertexPos[v[1]] + mesh.vertexPos[v[2]]) / 3.0;
}

// The face across edge k of f when growth may cross it (not a seam, not a crease), else kNone.
uint32_t crossable(const AtlasMesh& mesh, uint32_t f, int k, double creaseCos) {
  const uint32_t g = mesh.faceNeighbour[f][k];
  if (g == kNone || (mesh.seamEdge[f] >> k & 1u) || mesh.degenerate[g]) return kNone;
  if (glm::dot(mesh.faceNormal[f], mesh.faceNormal[g]) < creaseCos) return kNone;
  return g;
}

double edgeLength(const AtlasMesh& mesh, uint32_t f, int k) {
  return glm::length(mesh.vertexPos[mesh.faceVertex[f][(k + 1) % 3]] - mesh.vertexPos[mesh.faceVertex[f][k]]);
}

using Entry = std::pair<double, uint32_t>;
using MinHeap = std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>>;

constexpr uint32_t kFree = kNone;  // chartOf of a face no chart holds yet

// A chart while it grows.
struct GrowingChart {
  std::vector<uint32_t> faces;
  glm::dvec3 normalSum{0.0};
  double area = 0.0;
  bool planar = false;
  bool alive = true;  // false once merged into another
};

// The state segmentCharts builds up phase by phase: the charts so far and which chart holds each face.
class Segmenter {
 public:
  Segmenter(const AtlasMesh& mesh, const ChartOptions& options)
      : mesh_(mesh), options_(options), creaseCos_(std::cos(glm::radians(options.creaseDegrees))),
        chartOf_(mesh.faceCount(), kFree) {
    for (uint32_t f = 0; f < mesh.faceCount(); ++f) {
      if (mesh.degenerate[f]) continue;
      order_.push_back(f);
      totalArea_ += mesh.faceArea[f];
    }
    // Largest faces seed first: on architecture they are the big flat pieces. Ties by index keep it deterministic.
    std::stable_sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) { return mesh.faceArea[a] > mesh.faceArea[b]; });
  }

  void findPlanarRegions();
  void smoothNormals();
  void growCurvedCharts();
  void mergeSmallCharts();
  std::vector<ChartFaces> finish();

 private:
  double planarBoundarySoftness(const std::vector<uint32_t>& region, uint32_t seed, std::vector<uint32_t>& regionOf,
                                double& boundary) const;
  void growChartFrom(uint32_t seed, std::deque<uint32_t>& seeds);
  bool mergeIntoNeighbour(uint32_t c, double maxArea);

  const AtlasMesh& mesh_;
  const ChartOptions& options_;
  const double creaseCos_;
  std::vector<uint32_t> order_;  // non-degenerate faces, largest first
  double totalArea_ = 0.0;
  std::vector<GrowingChart> charts_;
  std::vector<uint32_t> chartOf_;
  std::vector<glm::dvec3> smooth_;  // face normals averaged over a few rings (smoothNormals)
};

// Length of the region's boundary that a soft bend crosses (growth could go on there), and in `boundary`
// the whole boundary's length.
double Segmenter::planarBoundarySoftness(const std::vector<uint32_t>& region, uint32_t seed,
                                         std::vector<uint32_t>& regionOf, double& boundary) const {
  const double softCos = std::cos(glm::radians(options_.softBendDegrees));
  double softBoundary = 0.0;
  for (uint32_t f : region) regionOf[f] = seed;
  for (uint32_t f : region)
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = mesh_.faceNeighbour[f][k];
      if (g != kNone && regionOf[g] == seed) continue;
      const double len = edgeLength(mesh_, f, k);
      boundary += len;
      const uint32_t h = crossable(mesh_, f, k, creaseCos_);
      if (h != kNone && glm::dot(mesh_.faceNormal[h], mesh_.faceNormal[f]) > softCos) softBoundary += len;
    }
  return softBoundary;
}

// Phase 1: planar regions (flood fill within a small angle of the seed's normal).
void Segmenter::findPlanarRegions() {
  const double planarCos = std::cos(glm::radians(options_.planarDegrees));
  const size_t n = mesh_.faceCount();
  std::vector<uint8_t> tried(n, 0);
  std::vector<uint32_t> region, regionOf(n, kNone);
  for (uint32_t seed : order_) {
    if (chartOf_[seed] != kFree || tried[seed]) continue;
    region.assign(1, seed);
    tried[seed] = 1;
    double area = 0.0;
    for (size_t i = 0; i < region.size(); ++i) {
      const uint32_t f = region[i];
      area += mesh_.faceArea[f];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = crossable(mesh_, f, k, creaseCos_);
        if (g == kNone || tried[g] || chartOf_[g] != kFree) continue;
        if (glm::dot(mesh_.faceNormal[g], mesh_.faceNormal[seed]) < planarCos) continue;
        tried[g] = 1;
        region.push_back(g);
      }
    }
    // A flat strip of a finely faceted curved surface (a cylinder's side) is not a flat region:
    // lock only regions whose boundary is mostly hard (seams, creases or a clear bend).
    double softBoundary = 0.0, boundary = 0.0;
    const bool bigEnough = region.size() >= 2 && area >= options_.planarMinAreaFraction * totalArea_;
    if (bigEnough) softBoundary = planarBoundarySoftness(region, seed, regionOf, boundary);
    if (bigEnough && softBoundary <= 0.5 * boundary) {
      GrowingChart chart;
      chart.faces = region;
      chart.area = area;
      chart.planar = true;
      for (uint32_t f : region) {
        chartOf_[f] = uint32_t(charts_.size());
        chart.normalSum += mesh_.faceNormal[f] * mesh_.faceArea[f];
      }
      charts_.push_back(std::move(chart));
    } else {
      for (uint32_t f : region) tried[f] = (f == seed) ? 1 : 0;  // others may still seed their own region
    }
  }
}

// Scanned surfaces are noisy: curved growth compares normals averaged over a few rings of faces
// (never across seams or creases), so one bumpy face does not end a chart.
void Segmenter::smoothNormals() {
  const size_t n = mesh_.faceCount();
  smooth_ = mesh_.faceNormal;
  std::vector<glm::dvec3> next(n);
  for (int it = 0; it < options_.normalSmoothing; ++it) {
    for (uint32_t f = 0; f < n; ++f) {
      glm::dvec3 sum = smooth_[f] * mesh_.faceArea[f];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = crossable(mesh_, f, k, creaseCos_);
        if (g != kNone) sum += smooth_[g] * mesh_.faceArea[g];
      }
      const double len = glm::length(sum);
      next[f] = len > 0.0 ? sum / len : smooth_[f];
    }
    smooth_.swap(next);
  }
}

// One curved chart grown from seed, nearest faces first, while every face stays inside the cone around
// the chart's mean normal; the faces it rejected go to the back of `seeds`.
void Segmenter::growChartFrom(uint32_t seed, std::deque<uint32_t>& seeds) {
  const double coneCos = std::cos(glm::radians(options_.coneDegrees));
  const double maxArea = options_.maxAreaFraction * totalArea_;
  const uint32_t id = uint32_t(charts_.size());
  GrowingChart chart;
  const glm::dvec3 seedCentre = centroidOf(mesh_, seed);
  MinHeap heap;
  heap.push({0.0, seed});
  std::vector<uint32_t> rejected;
  while (!heap.empty()) {
    const uint32_t f = heap.top().second;
    heap.pop();
    if (chartOf_[f] != kFree) continue;
    if (chart.area >= maxArea) {
      rejected.push_back(f);
      continue;
    }
    const glm::dvec3 mean = chart.area > 0.0 ? glm::normalize(chart.normalSum) : smooth_[f];
    if (glm::dot(smooth_[f], mean) < coneCos) {
      rejected.push_back(f);
      continue;
    }
    chartOf_[f] = id;
    chart.faces.push_back(f);
    chart.normalSum += smooth_[f] * mesh_.faceArea[f];
    chart.area += mesh_.faceArea[f];
    const glm::dvec3 now = glm::normalize(chart.normalSum);
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = crossable(mesh_, f, k, creaseCos_);
      if (g == kNone || chartOf_[g] != kFree) continue;
      const double deviation = 1.0 - glm::dot(smooth_[g], now);
      heap.push({glm::length(centroidOf(mesh_, g) - seedCentre) * (1.0 + 4.0 * deviation), g});
    }
  }
  for (uint32_t f : rejected)
    if (chartOf_[f] == kFree) seeds.push_back(f);
  charts_.push_back(std::move(chart));
}

// Phase 2: curved charts grown one at a time, each seeded from the front of faces the previous ones
// rejected, then from the largest free face.
void Segmenter::growCurvedCharts() {
  std::deque<uint32_t> seeds;
  size_t nextOrdered = 0;
  for (;;) {
    uint32_t seed = kFree;
    while (!seeds.empty() && seed == kFree) {
      if (chartOf_[seeds.front()] == kFree) seed = seeds.front();
      seeds.pop_front();
    }
    while (seed == kFree && nextOrdered < order_.size()) {
      if (chartOf_[order_[nextOrdered]] == kFree) seed = order_[nextOrdered];
      ++nextOrdered;
    }
    if (seed == kFree) break;
    growChartFrom(seed, seeds);
  }
}

// Chart c joins the curved neighbour it shares the longest boundary with, if the union stays inside the
// merge cone and under maxArea; true if it did.
bool Segmenter::mergeIntoNeighbour(uint32_t c, double maxArea) {
  const double mergeCos = std::cos(glm::radians(options_.mergeConeDegrees));
  std::map<uint32_t, double> shared;
  for (uint32_t f : charts_[c].faces)
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = crossable(mesh_, f, k, creaseCos_);
      if (g == kNone || chartOf_[g] == c || charts_[chartOf_[g]].planar) continue;
      shared[chartOf_[g]] += edgeLength(mesh_, f, k);
    }
  std::vector<std::pair<double, uint32_t>> byLength;
  for (auto& [other, length] : shared) byLength.push_back({-length, other});
  std::sort(byLength.begin(), byLength.end());
  for (auto& [negLength, other] : byLength) {
    if (charts_[c].area + charts_[other].area > maxArea) continue;
    const glm::dvec3 mean = glm::normalize(charts_[c].normalSum + charts_[other].normalSum);
    bool inside = true;
    for (const GrowingChart* chart : {&charts_[c], &charts_[other]})
      for (uint32_t f : chart->faces)
        if (glm::dot(smooth_[f], mean) < mergeCos) { inside = false; break; }
    if (!inside) continue;
    GrowingChart& into = charts_[other];
    for (uint32_t f : charts_[c].faces) {
      chartOf_[f] = other;
      into.faces.push_back(f);
    }
    into.normalSum += charts_[c].normalSum;
    into.area += charts_[c].area;
    charts_[c].alive = false;
    charts_[c].faces.clear();
    return true;
  }
  return false;
}

// Phase 3: small curved charts join the neighbour they share the longest boundary with.
void Segmenter::mergeSmallCharts() {
  std::vector<double> curvedAreas;
  for (const GrowingChart& chart : charts_)
    if (!chart.planar) curvedAreas.push_back(chart.area);
  if (curvedAreas.empty()) return;
  const double maxArea = options_.maxAreaFraction * totalArea_;
  std::nth_element(curvedAreas.begin(), curvedAreas.begin() + curvedAreas.size() / 2, curvedAreas.end());
  const double smallArea = options_.mergeAreaFraction * curvedAreas[curvedAreas.size() / 2];
  std::vector<uint32_t> small;
  for (uint32_t c = 0; c < charts_.size(); ++c)
    if (!charts_[c].planar && charts_[c].area < smallArea) small.push_back(c);
  std::stable_sort(small.begin(), small.end(), [&](uint32_t a, uint32_t b) { return charts_[a].area < charts_[b].area; });
  for (uint32_t c : small) {
    if (!charts_[c].alive || charts_[c].area >= smallArea) continue;
    mergeIntoNeighbour(c, maxArea);
  }
}

std::vector<ChartFaces> Segmenter::finish() {
  std::vector<ChartFaces> out;
  for (GrowingChart& chart : charts_) {
    if (!chart.alive) continue;
    ChartFaces c;
    c.faces = std::move(chart.faces);
    std::sort(c.faces.begin(), c.faces.end());
    c.planarRegion = chart.planar;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace

std::vector<ChartFaces> segmentCharts(const AtlasMesh& mesh, const ChartOptions& options) {
  Segmenter segmenter(mesh, options);
  segmenter.findPlanarRegions();
  segmenter.smoothNormals();
  segmenter.growCurvedCharts();
  segmenter.mergeSmallCharts();
  return segmenter.finish();
}

std::vector<ChartFaces> bisectChart(const AtlasMesh& mesh, const ChartFaces& chart) {
  const size_t m = chart.faces.size();
  if (m < 2) return {chart};
  std::map<uint32_t, uint32_t> local;
  for (uint32_t i = 0; i < m; ++i) local[chart.faces[i]] = i;
  std::vector<glm::dvec3> centre(m);
  std::vector<std::array<uint32_t, 3>> adj(m);
  for (uint32_t i = 0; i < m; ++i) {
    const uint32_t f = chart.faces[i];
    centre[i] = centroidOf(mesh, f);
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = mesh.faceNeighbour[f][k];
      auto it = (g == kNone || (mesh.seamEdge[f] >> k & 1u)) ? local.end() : local.find(g);
      adj[i][k] = it == local.end() ? kNone : it->second;
    }
  }
  // Multi-source Dijkstra over face centroids; label[i] is the nearest source.
  auto grow = [&](const std::vector<uint32_t>& sources, std::vector<double>& dist, std::vector<uint32_t>& label) {
    dist.assign(m, 1e300);
    label.assign(m, kNone);
    MinHeap heap;
    for (uint32_t s = 0; s < sources.size(); ++s) {
      dist[sources[s]] = 0.0;
      label[sources[s]] = s;
      heap.push({0.0, sources[s]});
    }
    while (!heap.empty()) {
      auto [d, i] = heap.top();
      heap.pop();
      if (d > dist[i]) continue;
      for (uint32_t j : adj[i]) {
        if (j == kNone) continue;
        const double nd = d + glm::length(centre[j] - centre[i]);
        if (nd < dist[j]) {
          dist[j] = nd;
          label[j] = label[i];
          heap.push({nd, j});
        }
      }
    }
  };
  std::vector<double> dist;
  std::vector<uint32_t> label;
  auto farthest = [&]() {
    uint32_t best = 0;
    for (uint32_t i = 0; i < m; ++i)
      if (dist[i] < 1e300 && dist[i] > dist[best]) best = i;
    return best;
  };
  grow({0}, dist, label);
  const uint32_t a = farthest();
  grow({a}, dist, label);
  const uint32_t b = farthest();
  if (a == b) {  // disconnected pieces: split off what the first source reaches
    grow({0}, dist, label);
  } else {
    grow({a, b}, dist, label);
  }
  ChartFaces first, second;
  for (uint32_t i = 0; i < m; ++i) (label[i] == 0 ? first : second).faces.push_back(chart.faces[i]);
  if (first.faces.empty() || second.faces.empty()) {  // cannot happen for m ≥ 2 with distinct seeds; keep a valid split
    first.faces.assign(chart.faces.begin(), chart.faces.begin() + long(m / 2));
    second.faces.assign(chart.faces.begin() + long(m / 2), chart.faces.end());
  }
  return {first, second};
}

}  // namespace irbake::atlas
