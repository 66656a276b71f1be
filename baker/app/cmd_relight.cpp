// irbake relight BAKED.gltf|.glb --group NAME=W ... -o OUT.gltf|.glb: a bake with light groups
// (IRBAKE_lightmap_scenarios) written again with other weights on its layers, without tracing a ray
// (export/relight.h). W is one number (grey) or R,G,B, finite and ≥ 0; a layer not named keeps its weight in the
// base scenario (the document's default, or --scenario NAME).
#include <cstdio>
#include <set>
#include <string>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "common/file_paths.h"
#include "common/output_lock.h"
#include "common/progress.h"
#include "export/gltf_export.h"
#include "export/relight.h"

namespace irbake::app {

int runRelight(const Args& args) {
  std::vector<std::string> inputs, groups;
  std::string output, scenario;
  auto app = cli::makeApp("irbake relight",
                          "Writes a bake with light groups (--light-group) again with other weights on its layers,\n"
                          "without tracing a ray: the maps, the PNGs and the probes of the new default scenario.");
  app->add_option("BAKED", inputs, "a glTF/GLB that irbake bake wrote with --light-group");
  app->add_option("--group", groups, "a layer's new weight: NAME=W, W one number or R,G,B (repeatable; layers not\n"
                  "named keep their weight in the base scenario)")->type_name("NAME=W");
  app->add_option("--scenario", scenario, "the base weights: a scenario the file stores (default: its default scenario)")
      ->type_name("NAME");
  app->add_option("-o,--output", output, "the relit bake (its EXR pages, and for .gltf its .bin and PNGs, beside it)")
      ->type_name("OUT.gltf|OUT.glb");
  if (!cli::parse(*app, args)) return 0;
  if (inputs.size() != 1) throw Error(ErrorCode::Usage, "", "relight takes exactly one baked glTF/GLB");
  if (output.empty()) throw Error(ErrorCode::Usage, "", "relight needs -o OUT.gltf or OUT.glb");
  if (!namesGltfFile(output)) throw Error(ErrorCode::Usage, output, "relight writes one glTF: give -o a .gltf or .glb file name");
  RelightOptions options;
  options.input = inputs[0];
  options.output = output;
  options.scenario = scenario;
  std::set<std::string> named;
  for (const std::string& g : groups) {
    options.weights.push_back(parseLayerWeight(g));
    if (!named.insert(options.weights.back().first).second)
      throw Error(ErrorCode::Usage, "", "--group '" + options.weights.back().first + "' given twice");
  }

  Stopwatch time;
  Relight relight(options);
  // Every output checked before any work: never onto the bake's files, a folder, or each other.
  OutputGuard guard;
  guard.addInputs(relight.inputs());
  const std::filesystem::path folder = outputFolderOf(output);
  guard.keepManifest(folder);
  guard.addOutput(output, "the relit glTF (-o)");
  if (hasExtension(output, ".gltf"))
    guard.addOutput(folder / (std::filesystem::path(output).stem().string() + ".bin"), "the glTF's .bin output");
  for (const std::filesystem::path& page : relight.outputs())
    guard.addOutput(page, "an EXR page of the relit bake", ExistingOutput::ReplaceOurs);
  const OutputFolderLock lock(folder);
  removeStaleTemps(folder);
  const RelightSummary s = relight.write(guard);
  std::printf("relit %d page(s), %zu probe(s):", s.pages, s.probes);
  for (size_t l = 0; l < s.layers.size(); ++l)
    std::printf(" %s=%g,%g,%g", s.layers[l].c_str(), s.weights[l].x, s.weights[l].y, s.weights[l].z);
  std::printf("; wrote %s in %.2f s\n", output.c_str(), time.seconds());
  return 0;
}

}  // namespace irbake::app
