#include "common/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <system_error>
#include <unistd.h>
#include <vector>

#include <sys/statvfs.h>

#include "common/error.h"
#include "common/signal_cleanup.h"

namespace irbake {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTempPrefix = ".irbake-tmp.";

bool allDigits(const std::string& s, size_t from, size_t to) {
  if (to <= from) return false;
  for (size_t i = from; i < to; ++i)
    if (s[i] < '0' || s[i] > '9') return false;
  return true;
}

// A registered temp: removed on a signal, forgotten when renamed or removed normally.
struct TempFile {
  fs::path path;
  int slot = -1;
};

TempFile claimTemp(const fs::path& finalPath) {
  TempFile t{tempPathFor(finalPath), -1};
  t.slot = removeOnSignal(fs::absolute(t.path));
  return t;
}

}  // namespace

fs::path tempPathFor(const fs::path& finalPath) {
  static std::atomic<unsigned> counter{0};
  const std::string name = kTempPrefix + std::to_string(::getpid()) + "." + std::to_string(counter++) + "." +
                           finalPath.filename().string();
  return finalPath.has_parent_path() ? finalPath.parent_path() / name : fs::path(name);
}

bool isIrbakeTempName(const std::string& name) {
  const std::string prefix = kTempPrefix;
  if (name.rfind(prefix, 0) != 0) return false;
  const size_t pidEnd = name.find('.', prefix.size());
  if (pidEnd == std::string::npos || !allDigits(name, prefix.size(), pidEnd)) return false;
  const size_t countEnd = name.find('.', pidEnd + 1);
  return countEnd != std::string::npos && allDigits(name, pidEnd + 1, countEnd) && countEnd + 1 < name.size();
}

void removeStaleTemps(const fs::path& folder) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (!isIrbakeTempName(entry.path().filename().string())) continue;
    std::error_code removeError;
    if (entry.is_regular_file(removeError)) fs::remove(entry.path(), removeError);
  }
}

std::string writeFailureReason(const fs::path& path, const std::string& fallback) {
  const int err = errno;
  if (err == ENOSPC || err == EDQUOT) return "no space left on the device";
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  struct statvfs fsInfo {};
  if (::statvfs(folder.c_str(), &fsInfo) == 0 && fsInfo.f_bavail * fsInfo.f_frsize < 64 * 1024)
    return "no space left on the device";
  return fallback;
}

void writeAllAtomically(const std::vector<PendingFile>& files) {
  std::vector<TempFile> temps;
  auto cleanup = [&]() {
    std::error_code ec;
    for (auto& t : temps) {
      fs::remove(t.path, ec);
      forgetPath(t.slot);
    }
  };
  // A folder where a file should go would fail at the rename, after the work: refuse it first.
  for (const auto& f : files) {
    std::error_code ec;
    if (fs::is_directory(f.finalPath, ec))
      throw Error(ErrorCode::Usage, f.finalPath.string(), "is a folder, not a file name for this output");
  }
  try {
    for (const auto& f : files) {
      if (f.finalPath.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(f.finalPath.parent_path(), ec);
      }
      temps.push_back(claimTemp(f.finalPath));
      try {
        errno = 0;
        f.writer(temps.back().path);
      } catch (const Error& e) {
        // A full disk is said as such, and the message names the output, never the temp.
        const std::string reason = writeFailureReason(f.finalPath, "");
        if (!reason.empty()) throw Error(ErrorCode::Io, f.finalPath.string(), "cannot write: " + reason);
        throw;
      }
      if (!fs::exists(temps.back().path))
        throw Error(ErrorCode::Io, f.finalPath.string(), "writer produced no file");
    }
  } catch (...) {
    cleanup();
    throw;
  }
  // Files the set replaces are kept under a second (hard-linked) name until every rename succeeded, so a
  // failure half-way puts them back: the previous outputs stay exactly as they were.
  struct Replaced {
    size_t index;
    fs::path backup;
    int slot;
  };
  std::vector<Replaced> replaced;
  auto dropBackups = [&](bool restore) {
    std::error_code ec;
    for (auto& r : replaced) {
      if (restore) fs::rename(r.backup, files[r.index].finalPath, ec);
      fs::remove(r.backup, ec);
      forgetPath(r.slot);
    }
  };
  for (size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    if (!fs::is_regular_file(files[i].finalPath, ec)) continue;
    const TempFile backup = claimTemp(files[i].finalPath);
    fs::create_hard_link(files[i].finalPath, backup.path, ec);
    if (ec) {
      ec.clear();
      fs::copy_file(files[i].finalPath, backup.path, ec);
    }
    if (ec) {
      forgetPath(backup.slot);
      dropBackups(false);
      cleanup();
      throw Error(ErrorCode::Io, files[i].finalPath.string(), "cannot keep the previous file while replacing it: " + ec.message());
    }
    replaced.push_back({i, backup.path, backup.slot});
  }
  for (size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    fs::rename(temps[i].path, files[i].finalPath, ec);
    if (ec) {
      // All or nothing: the files already renamed go, and what they replaced comes back.
      std::error_code ignored;
      std::vector<bool> hadPrevious(files.size(), false);
      for (const auto& r : replaced) hadPrevious[r.index] = true;
      for (size_t j = 0; j < i; ++j)
        if (!hadPrevious[j]) fs::remove(files[j].finalPath, ignored);
      dropBackups(true);
      cleanup();
      throw Error(ErrorCode::Io, files[i].finalPath.string(), "cannot rename temp file: " + ec.message());
    }
  }
  for (auto& t : temps) forgetPath(t.slot);
  dropBackups(false);
}

void writeAtomically(const fs::path& finalPath, const std::function<void(const fs::path&)>& writer) {
  writeAllAtomically({PendingFile{finalPath, writer}});
}

}  // namespace irbake
