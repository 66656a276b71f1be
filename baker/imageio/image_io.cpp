#include "imageio/image_io.h"

#include <climits>
#include <mutex>

#include <dlfcn.h>
#include <unistd.h>

#include "common/error.h"

namespace irbake::imageio {
namespace {

constexpr const char* kPluginFile = "libirbake_imageio_oiio.so";

// Where the plugin may be, in order: $IRBAKE_IMAGEIO_PLUGIN, beside the running program, where the
// build wrote it.
std::vector<std::string> candidates() {
  std::vector<std::string> paths;
  if (const char* env = std::getenv("IRBAKE_IMAGEIO_PLUGIN"); env && *env) paths.emplace_back(env);
  char exe[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) paths.push_back((std::filesystem::path(std::string(exe, size_t(n))).parent_path() / kPluginFile).string());
#ifdef IRBAKE_IMAGEIO_PLUGIN
  paths.emplace_back(IRBAKE_IMAGEIO_PLUGIN);
#endif
  return paths;
}

const Api* load() {
  std::string errors;
  for (const std::string& path : candidates()) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    // RTLD_LOCAL: OpenImageIO's libraries stay out of the global symbol scope.
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      errors += std::string(" ") + ::dlerror();
      continue;
    }
    using Entry = const Api* (*)();
    if (auto entry = reinterpret_cast<Entry>(::dlsym(handle, "irbake_imageio_api"))) return entry();
    errors += " " + path + " has no irbake_imageio_api";
  }
  throw Error(ErrorCode::Io, kPluginFile,
              "cannot load the image plugin (needed to read and write images)" + (errors.empty() ? std::string(": not found") : ":" + errors));
}

}  // namespace

const Api& api() {
  static std::once_flag once;
  static const Api* loaded = nullptr;
  std::call_once(once, [] { loaded = load(); });
  return *loaded;
}

}  // namespace irbake::imageio
