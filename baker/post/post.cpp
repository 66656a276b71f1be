// Finite checks, bilinear lookup and the post stage in order.
#include "post/post.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"

namespace irbake {

glm::vec3 sampleLightmap(const Lightmap& map, glm::vec2 uv) {
  if (map.width <= 0 || map.height <= 0) return glm::vec3(0.0f);
  float fx = uv.x * map.width - 0.5f, fy = uv.y * map.height - 0.5f;
  int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  float tx = fx - x0, ty = fy - y0;
  auto at = [&](int x, int y) {
    x = x < 0 ? 0 : (x >= map.width ? map.width - 1 : x);
    y = y < 0 ? 0 : (y >= map.height ? map.height - 1 : y);
    return map.texels[static_cast<size_t>(y) * map.width + x];
  };
  return (1 - tx) * (1 - ty) * at(x0, y0) + tx * (1 - ty) * at(x0 + 1, y0) + (1 - tx) * ty * at(x0, y0 + 1) +
         tx * ty * at(x0 + 1, y0 + 1);
}

void checkFinite(const Lightmap& map, const std::string& what) {
  for (size_t i = 0; i < map.texels.size(); ++i) {
    const glm::vec3& t = map.texels[i];
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z)) {
      bool nan = std::isnan(t.x) || std::isnan(t.y) || std::isnan(t.z);
      int x = map.width > 0 ? static_cast<int>(i % map.width) : 0;
      int y = map.width > 0 ? static_cast<int>(i / map.width) : 0;
      throw Error(ErrorCode::NumericError, what,
                  "page " + std::to_string(map.page) + " texel (" + std::to_string(x) + ", " + std::to_string(y) +
                      ") is " + (nan ? "NaN" : "Inf"));
    }
  }
}

PostStats postProcess(const Scene& scene, std::vector<Lightmap>& maps, const PostOptions& options) {
  PostStats stats;
  Stopwatch watch;
  for (const auto& m : maps) checkFinite(m, "backend output");
  if (options.dilate)
    for (auto& m : maps) stats.texelsFilled += dilate(m, options.dilation);
  const double dilated = watch.seconds();
  if (options.stitchSeams) {
    std::vector<SeamEdge> seams = findSeams(scene, options.seams);
    const double found = watch.seconds();
    stats.seamEdges = seams.size();
    stats.seamMismatchBefore = seamMismatch(maps, seams, options.seams);
    const double measured = watch.seconds();
    stats.seamMismatchAfter = stitchSeams(maps, seams, options.seams);
    log::debug("post: dilate " + std::to_string(dilated) + " s, find seams " + std::to_string(found - dilated) +
               " s, mismatch " + std::to_string(measured - found) + " s, stitch " +
               std::to_string(watch.seconds() - measured) + " s");
  }
  for (const auto& m : maps) checkFinite(m, "post-processed light map");
  return stats;
}

}  // namespace irbake
