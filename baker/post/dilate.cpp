// Dilation: valid texels grow outwards ring by ring into invalid and padding texels.
#include <vector>

#include "post/post.h"

namespace irbake {

size_t dilate(Lightmap& map, const DilateOptions& options) {
  const int w = map.width, h = map.height;
  const size_t n = map.size();
  if (n == 0) return 0;
  std::vector<uint8_t> filled(n, 0);
  bool any = false;
  for (size_t i = 0; i < n; ++i) {
    filled[i] = (i < map.valid.size() && map.valid[i]) ? 1 : 0;
    any = any || filled[i];
  }
  if (!any) return 0;  // nothing to grow from: the page stays as baked (zeros)

  // The first ring: unfilled texels with a filled 8-neighbour. Later rings come from the neighbours of
  // the previous ring only, so the whole fill costs O(texels) instead of O(texels × rings).
  std::vector<uint8_t> queued(n, 0);
  std::vector<size_t> ring;
  auto pushNeighbours = [&](int x, int y) {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        size_t j = static_cast<size_t>(ny) * w + nx;
        if (!filled[j] && !queued[j]) {
          queued[j] = 1;
          ring.push_back(j);
        }
      }
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (filled[static_cast<size_t>(y) * w + x]) pushNeighbours(x, y);

  size_t count = 0;
  std::vector<glm::vec3> values;
  for (int distance = 1; !ring.empty(); ++distance) {
    if (options.maxDistance >= 0 && distance > options.maxDistance) break;
    // Values first, from texels filled before this ring (so the result does not depend on order).
    values.resize(ring.size());
    for (size_t k = 0; k < ring.size(); ++k) {
      int x = static_cast<int>(ring[k] % w), y = static_cast<int>(ring[k] / w);
      glm::dvec3 sum(0.0);
      int m = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          size_t j = static_cast<size_t>(ny) * w + nx;
          if (filled[j] == 1) {
            sum += glm::dvec3(map.texels[j]);
            ++m;
          }
        }
      values[k] = m ? glm::vec3(sum / double(m)) : glm::vec3(0.0f);
    }
    std::vector<size_t> current;
    current.swap(ring);
    for (size_t k = 0; k < current.size(); ++k) {
      map.texels[current[k]] = values[k];
      filled[current[k]] = 1;
    }
    count += current.size();
    for (size_t j : current) pushNeighbours(static_cast<int>(j % w), static_cast<int>(j / w));
  }
  return count;
}

}  // namespace irbake
