#include "common/atomic_file.h"

#include <atomic>
#include <system_error>
#include <unistd.h>
#include <vector>

#include "common/error.h"

namespace irbake {

std::filesystem::path tempPathFor(const std::filesystem::path& finalPath) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path p = finalPath;
  p += ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  return p;
}

void writeAllAtomically(const std::vector<PendingFile>& files) {
  std::vector<std::filesystem::path> temps;
  auto cleanup = [&]() {
    std::error_code ec;
    for (auto& t : temps) std::filesystem::remove(t, ec);
  };
  try {
    for (const auto& f : files) {
      if (f.finalPath.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(f.finalPath.parent_path(), ec);
      }
      temps.push_back(tempPathFor(f.finalPath));
      f.writer(temps.back());
      if (!std::filesystem::exists(temps.back()))
        throw Error(ErrorCode::Io, f.finalPath.string(), "writer produced no file");
    }
  } catch (...) {
    cleanup();
    throw;
  }
  for (size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    std::filesystem::rename(temps[i], files[i].finalPath, ec);
    if (ec) {
      // The set is all or nothing: the files already renamed go too, with the remaining temps.
      std::error_code ignored;
      for (size_t j = 0; j < i; ++j) std::filesystem::remove(files[j].finalPath, ignored);
      cleanup();
      throw Error(ErrorCode::Io, files[i].finalPath.string(), "cannot rename temp file: " + ec.message());
    }
  }
}

void writeAtomically(const std::filesystem::path& finalPath,
                     const std::function<void(const std::filesystem::path&)>& writer) {
  writeAllAtomically({PendingFile{finalPath, writer}});
}

}  // namespace irbake
