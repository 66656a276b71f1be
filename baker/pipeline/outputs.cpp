// Writing a finished bake: EXR pages, glTF with the maps attached, the portable GLB when asked, the JSON report.
#include <fstream>
#include <string>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/log.h"
#include "common/version.h"
#include "export/directional_export.h"
#include "export/exr_io.h"
#include "export/gltf_export.h"
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
  // Directional bakes: the L1 pages beside them (lightmap_<page>_l1x.exr, …).
  std::vector<std::pair<fs::path, const Lightmap*>> l1Exrs;
  for (int k = 0; k < 3; ++k)
    for (const Lightmap& m : result.directional[k])
      l1Exrs.push_back({outDir / directionalPageUri("lightmap", m.page, k), &m});
  // Shadow masks: lightmap_<page>_shadowmask.exr beside the pages (and PNGs in the glTF).
  ShadowMaskExport mask;
  if (!result.shadowMask.empty()) {
    mask.rgb = &result.shadowMask.rgb;
    mask.alpha = &result.shadowMask.alpha;
    mask.scene = &result.scene;
    for (size_t i = 0; i < result.maskChannels.channel.size(); ++i)
      if (result.maskChannels.channel[i] >= 0)
        mask.lights.push_back({&result.scene.lights[i], lightModeName(result.scene.lights[i]), result.maskChannels.channel[i]});
    for (const Lightmap& m : result.shadowMask.rgb) l1Exrs.push_back({outDir / shadowMaskPageUri("lightmap", m.page), &m});
  }
  const fs::path reportPath = options.reportPath.empty() ? outDir / "report.json" : options.reportPath;
  OutputGuard unguarded;  // a caller without a command guard: one that knows the inputs
  unguarded.addInputs(options.inputs);
  const OutputGuard& guard = options.guard ? *options.guard : unguarded;
  std::vector<fs::path> written;
  if (options.writeGltf) written.push_back(gltfPath);
  written.insert(written.end(), exrs.begin(), exrs.end());
  for (const auto& [path, map] : l1Exrs) written.push_back(path);
  const std::vector<PendingFile> errorPages = errorPageFiles(result, outDir, written);
  // The portable GLB is built now (its report entry says how), written with the rest.
  std::vector<PendingFile> portable;
  nlohmann::json portableSummary;
  if (!options.portablePath.empty()) {
    const fs::path folder = options.portablePath.parent_path();
    if (!folder.empty()) fs::create_directories(folder, ec);
    if (!folder.empty() && !fs::is_directory(folder))
      throw Error(ErrorCode::Io, folder.string(), "cannot create the portable GLB's folder");
    portable.push_back(portableGlbFile(result.scene, result.maps, options.portablePath, options.portable, &portableSummary));
    written.push_back(options.portablePath);
  }
  for (const PendingFile& f : options.alsoWrite) written.push_back(f.finalPath);

  // The report names what is written, and is written with it: glTF (+ .bin, PNG), EXR pages and report are
  // one all-or-nothing set, so a failed bake leaves the previous outputs, report included, untouched.
  nlohmann::json report = result.report;
  report["reportSchema"] = 2;  // bumped when a field changes meaning or goes away (2: timings in one object)
  report["irbakeVersion"] = versionLine("irbake");
  report["outputs"] = nlohmann::json::array();
  for (const auto& p : written) report["outputs"].push_back(p.string());
  if (!portable.empty()) report["portable"] = portableSummary;
  // A path is bytes, not always UTF-8: a name JSON cannot hold is written with U+FFFD in its place.
  const std::string text = report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  PendingFile reportFile{reportPath, [&text, reportPath](const fs::path& temp) {
                           std::ofstream out(temp, std::ios::binary);
                           out << text;
                           out.close();
                           if (!out) throw Error(ErrorCode::Io, reportPath.string(), "cannot write the report");
                         }};
  if (options.writeGltf) {
    ExportOptions ex;
    ex.output = gltfPath;
    ex.writeExrPages = true;
    ex.exrPrefix = "lightmap";
    ex.alsoWrite = {reportFile};
    ex.alsoWrite.insert(ex.alsoWrite.end(), portable.begin(), portable.end());
    ex.alsoWrite.insert(ex.alsoWrite.end(), errorPages.begin(), errorPages.end());
    ex.alsoWrite.insert(ex.alsoWrite.end(), options.alsoWrite.begin(), options.alsoWrite.end());
    ex.inputs = options.inputs;
    ex.guard = &guard;
    if (!result.directional[0].empty()) ex.directional = &result.directional;
    ex.probes = &result.probes;
    if (!mask.empty()) ex.shadowMask = &mask;
    ex.lightModes = &result.lightModes;
    exportGltf(result.scene, result.maps, ex);
  } else {
    std::vector<PendingFile> files;
    for (size_t i = 0; i < result.maps.size(); ++i) {
      const Lightmap* map = &result.maps[i];
      const fs::path finalPath = exrs[i];
      files.push_back({finalPath, [map, finalPath](const fs::path& temp) { writeExrFile(*map, temp, finalPath); }});
    }
    const size_t l1Count = l1Exrs.size() - (mask.empty() ? 0 : mask.rgb->size());
    for (size_t i = 0; i < l1Exrs.size(); ++i) {
      const Lightmap* map = l1Exrs[i].second;
      const fs::path finalPath = l1Exrs[i].first;
      const ShadowMaskExport* m = &mask;
      const size_t page = i - l1Count;
      if (i < l1Count) files.push_back({finalPath, [map, finalPath](const fs::path& temp) { writeExrFile(*map, temp, finalPath); }});
      else files.push_back({finalPath, [m, page, finalPath](const fs::path& temp) { writeShadowMaskExr(*m, page, temp, finalPath); }});
    }
    files.push_back(reportFile);
    files.insert(files.end(), portable.begin(), portable.end());
    files.insert(files.end(), errorPages.begin(), errorPages.end());
    files.insert(files.end(), options.alsoWrite.begin(), options.alsoWrite.end());
    guard.write(files);
  }

  removeStalePages(result, outDir, guard);
  written.push_back(reportPath);
  return written;
}

}  // namespace irbake
