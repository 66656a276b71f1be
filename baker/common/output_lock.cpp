#include "common/output_lock.h"

#include <cerrno>
#include <cstring>
#include <string>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/error.h"
#include "common/signal_cleanup.h"

namespace irbake {
namespace fs = std::filesystem;

namespace {
// The pid the holder wrote into the lock file ("" when unreadable).
std::string holderPid(int fd) {
  char buf[32] = {};
  ssize_t n = ::pread(fd, buf, sizeof(buf) - 1, 0);
  std::string pid = n > 0 ? std::string(buf, size_t(n)) : std::string();
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid;
}
}  // namespace

OutputFolderLock::OutputFolderLock(const fs::path& folder) : folder_(folder), file_(folder / kFileName) {
  std::error_code ec;
  createdFolder_ = !fs::exists(folder_, ec);
  fs::create_directories(folder_, ec);
  if (!fs::is_directory(folder_, ec)) throw Error(ErrorCode::Io, folder_.string(), "cannot create the output folder");
  // A holder unlinks the file when it finishes: a lock taken on a file that is no longer the one
  // at the path protects nothing, so check the inode and try again.
  for (int attempt = 0; attempt < 8; ++attempt) {
    fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw Error(ErrorCode::Io, file_.string(), std::string("cannot open the output-folder lock: ") + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string pid = holderPid(fd_);
      ::close(fd_);
      fd_ = -1;
      if (err == EWOULDBLOCK)
        throw Error(ErrorCode::Io, folder_.string(),
                    "output folder is busy: another irbake bake" + (pid.empty() ? std::string() : " (process " + pid + ")") +
                        " is writing into it (lock " + kFileName + "); wait for it or choose another -o");
      throw Error(ErrorCode::Io, file_.string(), std::string("cannot lock the output folder: ") + std::strerror(err));
    }
    struct stat held {}, atPath {};
    if (::fstat(fd_, &held) == 0 && ::stat(file_.c_str(), &atPath) == 0 && held.st_ino == atPath.st_ino &&
        held.st_dev == atPath.st_dev) {
      // Ours now: removed if a signal kills us (registered before the pid is written, so a file with a pid
      // in it is always one a signal cleans up).
      installSignalCleanup();
      signalSlot_ = removeOnSignal(fs::absolute(file_));
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
        // The pid is only for the message of a second bake: a lock without it is still a lock.
      }
      return;
    }
    ::close(fd_);
    fd_ = -1;
  }
  throw Error(ErrorCode::Io, file_.string(), "cannot lock the output folder: the lock file keeps being replaced");
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ < 0) return;
  std::error_code ec;
  forgetPath(signalSlot_);
  fs::remove(file_, ec);  // unlinked while still held: a waiting bake re-checks the inode
  ::close(fd_);
  if (createdFolder_ && fs::is_empty(folder_, ec)) fs::remove(folder_, ec);
}

}  // namespace irbake
