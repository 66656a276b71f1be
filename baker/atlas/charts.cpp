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

}  // namespace

std::vector<ChartFaces> segmentCharts(const AtlasMesh& mesh, const ChartOptions& options) {
  const size_t n = mesh.faceCount();
  const double planarCos = std::cos(glm::radians(options.planarDegrees));
  const double coneCos = std::cos(glm::radians(options.coneDegrees));
  const double creaseCos = std::cos(glm::radians(options.creaseDegrees));
  const double mergeCos = std::cos(glm::radians(options.mergeConeDegrees));
  const double softCos = std::cos(glm::radians(options.softBendDegrees));
  constexpr uint32_t kFree = kNone;

  std::vector<uint32_t> order;
  double totalArea = 0.0;
  for (uint32_t f = 0; f < n; ++f) {
    if (mesh.degenerate[f]) continue;
    order.push_back(f);
    totalArea += mesh.faceArea[f];
  }
  // Largest faces seed first: on architecture they are the big flat pieces. Ties by index keep it deterministic.
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return mesh.faceArea[a] > mesh.faceArea[b]; });

  struct Work {
    std::vector<uint32_t> faces;
    glm::dvec3 normalSum{0.0};
    double area = 0.0;
    bool planar = false;
    bool alive = true;
  };
  std::vector<Work> charts;
  std::vector<uint32_t> chartOf(n, kFree);

  // Phase 1: planar regions (flood fill within a small angle of the seed's normal).
  std::vector<uint8_t> tried(n, 0);
  std::vector<uint32_t> region, regionOf(n, kNone);
  for (uint32_t seed : order) {
    if (chartOf[seed] != kFree || tried[seed]) continue;
    region.assign(1, seed);
    tried[seed] = 1;
    double area = 0.0;
    for (size_t i = 0; i < region.size(); ++i) {
      const uint32_t f = region[i];
      area += mesh.faceArea[f];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = crossable(mesh, f, k, creaseCos);
        if (g == kNone || tried[g] || chartOf[g] != kFree) continue;
        if (glm::dot(mesh.faceNormal[g], mesh.faceNormal[seed]) < planarCos) continue;
        tried[g] = 1;
        region.push_back(g);
      }
    }
    // A flat strip of a finely faceted curved surface (a cylinder's side) is not a flat region:
    // lock only regions whose boundary is mostly hard (seams, creases or a clear bend).
    double softBoundary = 0.0, boundary = 0.0;
    if (region.size() >= 2 && area >= options.planarMinAreaFraction * totalArea) {
      for (uint32_t f : region) regionOf[f] = seed;
      for (uint32_t f : region)
        for (int k = 0; k < 3; ++k) {
          const uint32_t g = mesh.faceNeighbour[f][k];
          if (g != kNone && regionOf[g] == seed) continue;
          const double len = edgeLength(mesh, f, k);
          boundary += len;
          const uint32_t h = crossable(mesh, f, k, creaseCos);
          if (h != kNone && glm::dot(mesh.faceNormal[h], mesh.faceNormal[f]) > softCos) softBoundary += len;
        }
    }
    if (region.size() >= 2 && area >= options.planarMinAreaFraction * totalArea && softBoundary <= 0.5 * boundary) {
      Work w;
      w.faces = region;
      w.area = area;
      w.planar = true;
      for (uint32_t f : region) {
        chartOf[f] = uint32_t(charts.size());
        w.normalSum += mesh.faceNormal[f] * mesh.faceArea[f];
      }
      charts.push_back(std::move(w));
    } else {
      for (uint32_t f : region) tried[f] = (f == seed) ? 1 : 0;  // others may still seed their own region
    }
  }

  // Scanned surfaces are noisy: curved growth compares normals averaged over a few rings of faces
  // (never across seams or creases), so one bumpy face does not end a chart.
  std::vector<glm::dvec3> smooth(mesh.faceNormal), next(n);
  for (int it = 0; it < options.normalSmoothing; ++it) {
    for (uint32_t f = 0; f < n; ++f) {
      glm::dvec3 sum = smooth[f] * mesh.faceArea[f];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = crossable(mesh, f, k, creaseCos);
        if (g != kNone) sum += smooth[g] * mesh.faceArea[g];
      }
      const double len = glm::length(sum);
      next[f] = len > 0.0 ? sum / len : smooth[f];
    }
    smooth.swap(next);
  }

  const double maxArea = options.maxAreaFraction * totalArea;

  // Phase 2: curved charts grown one at a time from a front of rejected faces, nearest faces first,
  // while every face stays inside the cone around the chart's mean normal.
  std::deque<uint32_t> seeds;
  size_t nextOrdered = 0;
  for (;;) {
    uint32_t seed = kFree;
    while (!seeds.empty() && seed == kFree) {
      if (chartOf[seeds.front()] == kFree) seed = seeds.front();
      seeds.pop_front();
    }
    while (seed == kFree && nextOrdered < order.size()) {
      if (chartOf[order[nextOrdered]] == kFree) seed = order[nextOrdered];
      ++nextOrdered;
    }
    if (seed == kFree) break;
    const uint32_t id = uint32_t(charts.size());
    Work w;
    const glm::dvec3 seedCentre = centroidOf(mesh, seed);
    MinHeap heap;
    heap.push({0.0, seed});
    std::vector<uint32_t> rejected;
    while (!heap.empty()) {
      const uint32_t f = heap.top().second;
      heap.pop();
      if (chartOf[f] != kFree) continue;
      if (w.area >= maxArea) {
        rejected.push_back(f);
        continue;
      }
      const glm::dvec3 mean = w.area > 0.0 ? glm::normalize(w.normalSum) : smooth[f];
      if (glm::dot(smooth[f], mean) < coneCos) {
        rejected.push_back(f);
        continue;
      }
      chartOf[f] = id;
      w.faces.push_back(f);
      w.normalSum += smooth[f] * mesh.faceArea[f];
      w.area += mesh.faceArea[f];
      const glm::dvec3 now = glm::normalize(w.normalSum);
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = crossable(mesh, f, k, creaseCos);
        if (g == kNone || chartOf[g] != kFree) continue;
        const double deviation = 1.0 - glm::dot(smooth[g], now);
        heap.push({glm::length(centroidOf(mesh, g) - seedCentre) * (1.0 + 4.0 * deviation), g});
      }
    }
    for (uint32_t f : rejected)
      if (chartOf[f] == kFree) seeds.push_back(f);
    charts.push_back(std::move(w));
  }

  // Phase 3: small curved charts join the neighbour they share the longest boundary with.
  std::vector<double> curvedAreas;
  for (const Work& w : charts)
    if (!w.planar) curvedAreas.push_back(w.area);
  if (!curvedAreas.empty()) {
    std::nth_element(curvedAreas.begin(), curvedAreas.begin() + curvedAreas.size() / 2, curvedAreas.end());
    const double smallArea = options.mergeAreaFraction * curvedAreas[curvedAreas.size() / 2];
    std::vector<uint32_t> small;
    for (uint32_t c = 0; c < charts.size(); ++c)
      if (!charts[c].planar && charts[c].area < smallArea) small.push_back(c);
    std::stable_sort(small.begin(), small.end(), [&](uint32_t a, uint32_t b) { return charts[a].area < charts[b].area; });
    for (uint32_t c : small) {
      if (!charts[c].alive || charts[c].area >= smallArea) continue;
      std::map<uint32_t, double> shared;
      for (uint32_t f : charts[c].faces)
        for (int k = 0; k < 3; ++k) {
          const uint32_t g = crossable(mesh, f, k, creaseCos);
          if (g == kNone || chartOf[g] == c || charts[chartOf[g]].planar) continue;
          shared[chartOf[g]] += edgeLength(mesh, f, k);
        }
      std::vector<std::pair<double, uint32_t>> byLength;
      for (auto& [other, length] : shared) byLength.push_back({-length, other});
      std::sort(byLength.begin(), byLength.end());
      for (auto& [negLength, other] : byLength) {
        if (charts[c].area + charts[other].area > maxArea) continue;
        const glm::dvec3 mean = glm::normalize(charts[c].normalSum + charts[other].normalSum);
        bool inside = true;
        for (const Work* w : {&charts[c], &charts[other]})
          for (uint32_t f : w->faces)
            if (glm::dot(smooth[f], mean) < mergeCos) { inside = false; break; }
        if (!inside) continue;
        Work& into = charts[other];
        for (uint32_t f : charts[c].faces) {
          chartOf[f] = other;
          into.faces.push_back(f);
        }
        into.normalSum += charts[c].normalSum;
        into.area += charts[c].area;
        charts[c].alive = false;
        charts[c].faces.clear();
        break;
      }
    }
  }

  std::vector<ChartFaces> out;
  for (Work& w : charts) {
    if (!w.alive) continue;
    ChartFaces c;
    c.faces = std::move(w.faces);
    std::sort(c.faces.begin(), c.faces.end());
    c.planarRegion = w.planar;
    out.push_back(std::move(c));
  }
  return out;
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
