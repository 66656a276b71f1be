#include "pipeline/diff.h"

#include <algorithm>
#include <cmath>
#include <regex>
#include <string>

#include "common/error.h"
#include "export/exr_io.h"
#include "scene/gltf_loader.h"
#include "texels/texel_area.h"

namespace irbake {

MapDifference compareMaps(const std::vector<Lightmap>& a, const std::vector<Lightmap>& b,
                          const std::vector<std::vector<float>>& weights) {
  if (a.size() != b.size())
    throw Error(ErrorCode::InvalidData, "", "the bakes have " + std::to_string(a.size()) + " and " +
                                                std::to_string(b.size()) + " pages: not the same atlas");
  MapDifference d;
  d.pages = a.size();
  double sumSq = 0.0, sumRefSq = 0.0, sumDiff = 0.0, sumA = 0.0, sumB = 0.0;
  for (size_t p = 0; p < a.size(); ++p) {
    if (a[p].width != b[p].width || a[p].height != b[p].height)
      throw Error(ErrorCode::InvalidData, "", "page " + std::to_string(p) + " is " + std::to_string(a[p].width) + "x" +
                                                  std::to_string(a[p].height) + " in one bake and " +
                                                  std::to_string(b[p].width) + "x" + std::to_string(b[p].height) +
                                                  " in the other: not the same atlas");
    const bool weighted = p < weights.size() && weights[p].size() == a[p].size();
    for (size_t i = 0; i < a[p].size(); ++i) {
      double w;
      if (weighted) {
        w = weights[p][i];
      } else {
        bool va = i < a[p].valid.size() ? a[p].valid[i] != 0 : true;
        bool vb = i < b[p].valid.size() ? b[p].valid[i] != 0 : true;
        w = (va && vb) ? 1.0 : 0.0;
      }
      if (!(w > 0.0)) continue;
      glm::dvec3 x(a[p].texels[i]), y(b[p].texels[i]), e = x - y;
      ++d.texels;
      d.weightSum += w;
      sumSq += w * glm::dot(e, e) / 3.0;
      sumRefSq += w * glm::dot(y, y) / 3.0;
      sumDiff += w * (e.x + e.y + e.z) / 3.0;
      sumA += w * (x.x + x.y + x.z) / 3.0;
      sumB += w * (y.x + y.y + y.z) / 3.0;
      d.maxError = std::max({d.maxError, std::abs(e.x), std::abs(e.y), std::abs(e.z)});
    }
  }
  if (d.weightSum > 0.0) {
    d.rmse = std::sqrt(sumSq / d.weightSum);
    double refRms = std::sqrt(sumRefSq / d.weightSum);
    d.relativeRmse = refRms > 0.0 ? d.rmse / refRms : 0.0;
    d.meanBias = sumDiff / d.weightSum;
    d.meanA = sumA / d.weightSum;
    d.meanB = sumB / d.weightSum;
    d.relativeBias = d.meanB != 0.0 ? d.meanBias / d.meanB : 0.0;
  }
  return d;
}

namespace {
// A page with NaN or Inf texels scores nothing (every comparison with NaN is false): refuse it.
Lightmap readFinitePage(const std::filesystem::path& file) {
  Lightmap page = readExr(file);
  size_t bad = 0;
  for (const glm::vec3& t : page.texels)
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z)) ++bad;
  if (bad > 0)
    throw Error(ErrorCode::InvalidData, file.string(),
                std::to_string(bad) + " of " + std::to_string(page.texels.size()) +
                    " texels are NaN or Inf: not a light map that can be compared");
  return page;
}
}  // namespace

BakeOnDisk readBakeFromDisk(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  BakeOnDisk bake;
  if (!fs::exists(path)) throw Error(ErrorCode::Io, path.string(), "no such file or folder");
  if (!fs::is_directory(path)) {
    bake.pages.push_back(readFinitePage(path));
    bake.pages.back().page = 0;
    return bake;
  }
  // lightmap_<page>.exr, ordered by page number.
  std::vector<std::pair<int, fs::path>> found;
  const std::regex name("lightmap_([0-9]+)\\.exr");
  for (const auto& e : fs::directory_iterator(path)) {
    std::smatch m;
    std::string file = e.path().filename().string();
    if (e.is_regular_file() && std::regex_match(file, m, name)) found.emplace_back(std::stoi(m[1].str()), e.path());
  }
  if (found.empty()) throw Error(ErrorCode::Io, path.string(), "no lightmap_<page>.exr pages in this folder");
  std::sort(found.begin(), found.end());
  for (size_t i = 0; i < found.size(); ++i) {
    if (found[i].first != int(i))
      throw Error(ErrorCode::InvalidData, path.string(), "page " + std::to_string(i) + " is missing");
    bake.pages.push_back(readFinitePage(found[i].second));
    bake.pages.back().page = int(i);
  }
  for (const char* gltfName : {"scene.gltf", "scene.glb"}) {
    fs::path g = path / gltfName;
    if (!fs::exists(g)) continue;
    LoadOptions lo;
    lo.decodeImages = false;
    Scene scene = loadScene(g, lo);
    bake.areas = texelWorldAreas(scene);
    bake.gltf = g;
    break;
  }
  return bake;
}

}  // namespace irbake
