// One bake per output folder at a time: an exclusive flock on OUTDIR/.irbake.lock, held from before
// the scene is loaded until the outputs are written. A second bake into the same folder fails at once.
// A bake killed by a signal removes the lock file on its way out (common/signal_cleanup.h).
#pragma once
#include <filesystem>

namespace irbake {

class OutputFolderLock {
 public:
  // Creates the folder when missing and takes the lock; throws Error(Io, folder) naming the process
  // that holds it when another bake does.
  explicit OutputFolderLock(const std::filesystem::path& folder);
  // Removes the lock file, and the folder when this lock created it and it is still empty (a failed
  // bake leaves nothing behind).
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

  static constexpr const char* kFileName = ".irbake.lock";

 private:
  std::filesystem::path folder_, file_;
  bool createdFolder_ = false;
  int fd_ = -1;
  int signalSlot_ = -1;  // the lock file is removed when a signal kills the bake
};

}  // namespace irbake
