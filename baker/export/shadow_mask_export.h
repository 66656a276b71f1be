// Shadow masks in the export (docs/export.md "IRBAKE_shadowmask"): per light-map page one RGBA mask page, as
// an 8-bit linear PNG referenced from a vendor extension on each light-mapped material and as a float EXR;
// the root extension maps each shadow-mask light to its channel. MOZ_lightmap is unchanged.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "export/gltf_writer.h"
#include "lightmap/lightmap.h"
#include "scene/scene.h"

namespace irbake {

constexpr const char* kShadowMaskExtension = "IRBAKE_shadowmask";

struct ShadowMaskLight {
  const Light* light = nullptr;  // the scene's light (its KHR_lights_punctual index, or the command line's sun)
  std::string name;              // as --light-mode names it
  int channel = 0;               // 0..3: R, G, B, A
};

struct ShadowMaskExport {
  const std::vector<Lightmap>* rgb = nullptr;    // channels 0–2 per page
  const std::vector<Lightmap>* alpha = nullptr;  // channel 3 (x) per page, or null / empty: 1
  std::vector<ShadowMaskLight> lights;
  const Scene* scene = nullptr;  // the lights' scene (documentLightIndex); null: only gltfLight says
  bool empty() const { return !rgb || rgb->empty(); }
};

// The index of scene light `l` in the exported document's KHR_lights_punctual.lights: its source index, or for
// a scene the export generates (no source file) its place in Scene::lights, which the writer keeps; -1 for a
// light the document does not have (the command line's --sun over a source file).
int documentLightIndex(const Scene* scene, const Light& l);

// Page i of the mask clamped to [0, 1]: the first three channels, and the fourth as a page of its own (its
// texels' x; 1 when the mask has no fourth channel).
struct ShadowMaskPage {
  Lightmap rgb, alpha;
};
ShadowMaskPage shadowMaskPage(const ShadowMaskExport& mask, size_t i);

// EXR file name of a page's mask: <prefix>_<page>_shadowmask.exr.
std::string shadowMaskPageUri(const std::string& prefix, int page);

// Writes page i's mask as a 4-channel float EXR (the exr map encoding).
void writeShadowMaskExr(const ShadowMaskExport& mask, size_t i, const std::filesystem::path& file,
                        const std::filesystem::path& finalPath);

// Adds each page's PNG and {"index", "texCoord": 1, "exr"} on every material whose MOZ_lightmap is that
// page's, and the root extension {"lights": [{"light", "name", "channel"}, ...]}; lists it in extensionsUsed.
void addShadowMaskExtension(GltfDocument& doc, const ShadowMaskExport& mask, const std::string& exrPrefix);

// Records each punctual light's settled mode where a client finds it (docs/export.md "Mixed lights"): a KHR light
// that is not baked, or whose source extras named a mode, gets extras.irbake.mode; the command line's sun when
// not baked gets the root extras "irbakeSun" {"mode", "direction", "irradiance"}. `modes` is per scene light
// (empty: every light baked, nothing written).
void recordLightModes(GltfDocument& doc, const Scene& scene, const std::vector<LightMode>& modes);

}  // namespace irbake
