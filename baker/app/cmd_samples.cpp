// irbake samples OUTDIR: writes the built-in sample scenes (samples/sample_scenes.h) as glTF.
#include <cstdio>

#include "app/commands.h"
#include "common/args.h"
#include "common/error.h"
#include "samples/sample_scenes.h"

namespace irbake::app {

int runSamples(const Args& args) {
  ArgParser parser(args, {}, {"--help", "--quiet"});
  if (parser.flag("--help")) {
    std::puts("usage: irbake samples OUTDIR [--quiet]\n"
              "  writes cornell_box, furnace, point_over_plane, quad_over_plane, corner, thin_wall,\n"
              "  textured_plane and contacts as OUTDIR/<name>.gltf (+ .bin)");
    return 0;
  }
  if (parser.positionals().size() != 1) throw Error(ErrorCode::Usage, "", "samples takes exactly one OUTDIR argument");
  for (const auto& path : samples::writeSamples(parser.positionals()[0]))
    if (!parser.flag("--quiet")) std::printf("wrote %s\n", path.string().c_str());
  return 0;
}

}  // namespace irbake::app
