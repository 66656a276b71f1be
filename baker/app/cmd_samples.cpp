// irbake samples OUTDIR: writes the built-in sample scenes (samples/sample_scenes.h) as glTF.
#include <cstdio>

#include "app/commands.h"
#include "common/command_line.h"
#include "common/error.h"
#include "samples/sample_scenes.h"

namespace irbake::app {

int runSamples(const Args& args) {
  std::vector<std::string> folders;
  bool quiet = false;
  auto app = cli::makeApp("irbake samples",
                          "Writes cornell_box, furnace, point_over_plane, quad_over_plane, corner, thin_wall,\n"
                          "textured_plane and contacts as OUTDIR/<name>.gltf (+ .bin).");
  app->add_option("OUTDIR", folders, "output folder");
  app->add_flag("--quiet", quiet, "do not list the files written");
  if (!cli::parse(*app, args)) return 0;
  if (folders.size() != 1) throw Error(ErrorCode::Usage, "", "samples takes exactly one OUTDIR argument");
  for (const auto& path : samples::writeSamples(folders[0]))
    if (!quiet) std::printf("wrote %s\n", path.string().c_str());
  return 0;
}

}  // namespace irbake::app
