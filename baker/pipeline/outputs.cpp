// Writing a finished bake: EXR pages, glTF with the maps attached, the portable GLB when asked, the JSON report.
#include <algorithm>
#include <fstream>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <utility>

#include "atlas/atlas_from_bake.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "common/version.h"
#include "export/directional_export.h"
#include "export/exr_io.h"
#include "export/gltf_export.h"
#include "export/light_layers.h"
#include "export/portable_export.h"
#include "pipeline/bake.h"
#include "pipeline/light_modes.h"

namespace irbake {

namespace {

// With --error-map: each texel's standard error (BakeResult::standardError) as error_<page>.exr.
std::vector<PendingFile> errorPageFiles(const BakeResult& result, const std::filesystem::path& outDir,
                                        std::vector<std::filesystem::path>& written) {
  std::vector<PendingFile> files;
  for (const Lightmap& m : result.standardError) {
    const std::filesystem::path path = outDir / ("error_" + std::to_string(m.page) + ".exr");
    const Lightmap* map = &m;
    files.push_back({path, [map, path](const std::filesystem::path& temp) { writeExrFile(*map, temp, path); }});
    written.push_back(path);
  }
  return files;
}

// A page of an earlier bake into the same folder that this bake does not have would be read as part of it
// (irbake diff): remove it, but only when the folder's manifest proves irbake wrote it and it is unchanged.
void removeStalePage(const std::filesystem::path& stale, const OutputGuard& guard, const std::string& why) {
  if (guard.removeIfOurs(stale))
    log::warn("removed " + stale.string() + " left by an earlier bake " + why);
  else
    log::warn("left " + stale.string() + " as it is: it has the name of a page this bake does not write, but "
              "irbake did not write it (or it changed since); it is not part of this bake");
}

void removeStalePages(const BakeResult& result, const std::filesystem::path& outDir, const OutputGuard& guard) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (size_t page = result.maps.size();; ++page) {
    const fs::path stale = outDir / ("lightmap_" + std::to_string(page) + ".exr");
    if (!fs::exists(fs::symlink_status(stale, ec))) break;
    removeStalePage(stale, guard, "with more pages");
  }
  // Light-group layers of an earlier bake that this one does not have (other groups, fewer pages, or none):
  // lightmap_<page>_<group>.exr and .png, the names the shadow-mask and directional pages use left aside
  // (otherPageName).
  std::set<std::string> layers;  // this bake's, without the extension
  for (const LightLayer& layer : result.layers)
    for (const Lightmap& m : layer.maps) layers.insert(fs::path(layerPageUri("lightmap", m.page, layer.name)).stem().string());
  static const std::regex kLayerPage("lightmap_[0-9]+_(.+)\\.(exr|png)");
  std::vector<fs::path> staleLayers;
  for (const fs::directory_entry& entry : fs::directory_iterator(outDir, ec)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, kLayerPage) || !validLayerName(m[1].str()) || otherPageName(m[1].str()) ||
        layers.count(entry.path().stem().string()))
      continue;
    staleLayers.push_back(entry.path());
  }
  std::sort(staleLayers.begin(), staleLayers.end());
  for (const fs::path& stale : staleLayers) removeStalePage(stale, guard, "with other light groups");
  // Shadow-mask pages of an earlier bake that this one does not have (fewer pages, or no mask light now).
  for (size_t page = result.shadowMask.rgb.size();; ++page) {
    bool found = false;
    for (const char* ext : {".exr", ".png"}) {
      const fs::path stale = outDir / ("lightmap_" + std::to_string(page) + "_shadowmask" + ext);
      if (!fs::exists(fs::symlink_status(stale, ec))) continue;
      found = true;
      removeStalePage(stale, guard, "with shadow-mask lights");
    }
    if (!found) break;
  }
}

// Shadow masks: lightmap_<page>_shadowmask.exr beside the pages (and PNGs in the glTF), appended to exrs.
ShadowMaskExport shadowMaskExport(const BakeResult& result, const std::filesystem::path& outDir,
                                  std::vector<std::pair<std::filesystem::path, const Lightmap*>>& exrs) {
  ShadowMaskExport mask;
  if (result.shadowMask.empty()) return mask;
  mask.rgb = &result.shadowMask.rgb;
  mask.alpha = &result.shadowMask.alpha;
  mask.scene = &result.scene;
  for (size_t i = 0; i < result.maskChannels.channel.size(); ++i)
    if (result.maskChannels.channel[i] >= 0)
      mask.lights.push_back({&result.scene.lights[i], lightModeName(result.scene.lights[i]), result.maskChannels.channel[i]});
  for (const Lightmap& m : result.shadowMask.rgb) exrs.push_back({outDir / shadowMaskPageUri("lightmap", m.page), &m});
  return mask;
}

// The portable GLB, built now (its report entry, summary, says how) and written with the rest; none without
// a path.
std::vector<PendingFile> portableFiles(const BakeResult& result, const OutputOptions& options,
                                       nlohmann::json& summary) {
  namespace fs = std::filesystem;
  if (options.portablePath.empty()) return {};
  std::error_code ec;
  const fs::path folder = options.portablePath.parent_path();
  if (!folder.empty()) fs::create_directories(folder, ec);
  if (!folder.empty() && !fs::is_directory(folder))
    throw Error(ErrorCode::Io, folder.string(), "cannot create the portable GLB's folder");
  return {portableGlbFile(result.scene, result.maps, options.portablePath, options.portable, &summary)};
}

// The report, naming what is written: glTF (+ .bin, PNG), EXR pages and report are one all-or-nothing set,
// so a failed bake leaves the previous outputs, report included, untouched.
PendingFile reportFile(const BakeResult& result, const std::vector<std::filesystem::path>& written,
                       const nlohmann::json* portableSummary, double portableSeconds,
                       const std::filesystem::path& reportPath) {
  nlohmann::json report = result.report;
  if (portableSummary) {
    // The portable GLB is made (its textures encoded) before the report: its time and memory count in it.
    nlohmann::json& timings = report["timings"];
    timings["seconds"]["portable"] = portableSeconds;
    timings["memoryPeakMiB"] = std::max(timings.value("memoryPeakMiB", 0.0), peakMemoryMiB());
  }
  report["reportSchema"] = 2;  // bumped when a field changes meaning or goes away (2: timings in one object)
  report["irbakeVersion"] = versionLine("irbake");
  report["outputs"] = nlohmann::json::array();
  for (const auto& p : written) report["outputs"].push_back(p.string());
  if (portableSummary) report["portable"] = *portableSummary;
  // A path is bytes, not always UTF-8: a name JSON cannot hold is written with U+FFFD in its place.
  const auto text =
      std::make_shared<const std::string>(report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  return {reportPath, [text, reportPath](const std::filesystem::path& temp) {
            std::ofstream out(temp, std::ios::binary);
            out << *text;
            out.close();
            if (!out) throw Error(ErrorCode::Io, reportPath.string(), "cannot write the report");
          }};
}

// Without the glTF: the EXR pages, the L1 and shadow-mask pages (extraExrs, the mask's last), then `more`.
void writeExrPages(const BakeResult& result, const std::vector<std::filesystem::path>& exrs,
                   const std::vector<std::pair<std::filesystem::path, const Lightmap*>>& extraExrs,
                   const ShadowMaskExport& mask, const std::vector<PendingFile>& more, const OutputGuard& guard) {
  namespace fs = std::filesystem;
  std::vector<PendingFile> files;
  for (size_t i = 0; i < result.maps.size(); ++i) {
    const Lightmap* map = &result.maps[i];
    const fs::path finalPath = exrs[i];
    files.push_back({finalPath, [map, finalPath](const fs::path& temp) { writeExrFile(*map, temp, finalPath); }});
  }
  const size_t l1Count = extraExrs.size() - (mask.empty() ? 0 : mask.rgb->size());
  for (size_t i = 0; i < extraExrs.size(); ++i) {
    const Lightmap* map = extraExrs[i].second;
    const fs::path finalPath = extraExrs[i].first;
    const ShadowMaskExport* m = &mask;
    const size_t page = i - l1Count;
    if (i < l1Count) files.push_back({finalPath, [map, finalPath](const fs::path& temp) { writeExrFile(*map, temp, finalPath); }});
    else files.push_back({finalPath, [m, page, finalPath](const fs::path& temp) { writeShadowMaskExr(*m, page, temp, finalPath); }});
  }
  files.insert(files.end(), more.begin(), more.end());
  guard.write(files);
}

// The glTF with the maps attached (exportGltf writes the EXR pages too), then `more` in the same set.
void writeGltfAndPages(const BakeResult& result, const std::filesystem::path& gltfPath, const ShadowMaskExport& mask,
                       const std::vector<PendingFile>& more, const OutputOptions& options, const OutputGuard& guard) {
  ExportOptions ex;
  ex.output = gltfPath;
  ex.writeExrPages = true;
  ex.exrPrefix = "lightmap";
  ex.alsoWrite = more;
  ex.inputs = options.inputs;
  ex.guard = &guard;
  if (!result.directional[0].empty()) ex.directional = &result.directional;
  ex.probes = &result.probes;
  if (!mask.empty()) ex.shadowMask = &mask;
  ex.lightModes = &result.lightModes;
  if (!result.layers.empty()) ex.layers = &result.layers;
  ex.atlasRecord = atlasRecordJson(result.atlas);
  exportGltf(result.scene, result.maps, ex);
}

}  // namespace

std::vector<std::filesystem::path> writeBakeOutputs(const BakeResult& result, const OutputOptions& options) {
  namespace fs = std::filesystem;
  // -o OUT.glb / OUT.gltf names the glTF itself (a GLB embeds its images); its folder takes the rest.
  const fs::path outDir = outputFolderOf(options.outDir);
  const fs::path gltfPath = namesGltfFile(options.outDir) ? options.outDir : outDir / "scene.gltf";
  std::error_code ec;
  fs::create_directories(outDir, ec);
  if (!fs::is_directory(outDir))
    throw Error(ErrorCode::Io, outDir.string(), "cannot create the output folder");
  std::vector<fs::path> exrs;
  for (const Lightmap& m : result.maps) exrs.push_back(outDir / ("lightmap_" + std::to_string(m.page) + ".exr"));
  // Directional bakes: the L1 pages beside them (lightmap_<page>_l1x.exr, …), then the shadow-mask pages.
  std::vector<std::pair<fs::path, const Lightmap*>> l1Exrs;
  for (int k = 0; k < 3; ++k)
    for (const Lightmap& m : result.directional[k])
      l1Exrs.push_back({outDir / directionalPageUri("lightmap", m.page, k), &m});
  // Light groups: each layer's pages (lightmap_<page>_<group>.exr), before the shadow-mask pages.
  for (const LightLayer& layer : result.layers)
    for (const Lightmap& m : layer.maps) l1Exrs.push_back({outDir / layerPageUri("lightmap", m.page, layer.name), &m});
  const ShadowMaskExport mask = shadowMaskExport(result, outDir, l1Exrs);
  const fs::path reportPath = options.reportPath.empty() ? outDir / "report.json" : options.reportPath;
  OutputGuard unguarded;  // a caller without a command guard: one that knows the inputs
  unguarded.addInputs(options.inputs);
  const OutputGuard& guard = options.guard ? *options.guard : unguarded;
  std::vector<fs::path> written;
  if (options.writeGltf) written.push_back(gltfPath);
  written.insert(written.end(), exrs.begin(), exrs.end());
  for (const auto& [path, map] : l1Exrs) written.push_back(path);
  const std::vector<PendingFile> errorPages = errorPageFiles(result, outDir, written);
  nlohmann::json portableSummary;
  const Stopwatch portableTime;
  const std::vector<PendingFile> portable = portableFiles(result, options, portableSummary);
  const double portableSeconds = portableTime.seconds();
  if (!portable.empty()) written.push_back(options.portablePath);
  for (const PendingFile& f : options.alsoWrite) written.push_back(f.finalPath);

  // The report first, then the portable GLB, the error pages and the caller's files, with the pages.
  std::vector<PendingFile> more = {reportFile(result, written, portable.empty() ? nullptr : &portableSummary, portableSeconds, reportPath)};
  more.insert(more.end(), portable.begin(), portable.end());
  more.insert(more.end(), errorPages.begin(), errorPages.end());
  more.insert(more.end(), options.alsoWrite.begin(), options.alsoWrite.end());
  if (options.writeGltf) writeGltfAndPages(result, gltfPath, mask, more, options, guard);
  else writeExrPages(result, exrs, l1Exrs, mask, more, guard);

  removeStalePages(result, outDir, guard);
  written.push_back(reportPath);
  return written;
}

}  // namespace irbake
