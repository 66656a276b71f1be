// libFuzzer entry for the glTF/GLB loader: every input either loads or is refused with
// irbake::Error. Anything else is a finding: a sanitizer report (ASan/UBSan), a crash, a hang, or a
// non-irbake exception escaping loadScene (the command would print no file name for it).
//
// The input is handed to loadSceneFromBytes, the same code loadScene runs after reading the file.
// Its name sits in an empty folder of its own (in the working directory: run_fuzz.sh runs in the
// build folder), so relative buffer/image URIs resolve to nothing and
// every byte the loader sees comes from the fuzzer. Images are not decoded (decodeImages = false):
// decoding is OpenImageIO's code behind a plugin, not ours; the loader's handling of the image
// records (indices, buffer views, URIs) still runs.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/log.h"
#include "scene/gltf_loader.h"

namespace {

std::filesystem::path inputName() {
  static const std::filesystem::path name = [] {
    std::filesystem::path folder = std::filesystem::current_path() / "empty_scene_folder";
    std::filesystem::create_directories(folder);
    return folder / "input.glb";
  }();
  return name;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbake::log::setLevel(irbake::log::Level::Quiet);  // thousands of warnings per second otherwise
  inputName();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  irbake::LoadOptions options;
  options.decodeImages = false;
  try {
    irbake::Scene scene = irbake::loadSceneFromBytes(std::vector<uint8_t>(data, data + size), inputName(), options);
  } catch (const irbake::Error&) {
    // Refused with a message naming the file: the expected outcome for most inputs.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gltf_loader_fuzz: non-irbake exception escaped loadScene: %s\n", e.what());
    std::abort();
  }
  return 0;
}
