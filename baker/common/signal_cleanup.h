// Files to remove when the process is killed by a signal (SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGABRT):
// the output-folder lock and the temp files being written, so a killed bake leaves nothing behind.
#pragma once
#include <filesystem>

namespace irbake {

// Installs the handlers (once; later calls do nothing). The handler unlinks every registered path and
// then dies of the same signal, so the exit status still says how the process ended.
void installSignalCleanup();

// Registers a path for removal on a signal; returns a slot for forgetPath (-1 when every slot is taken:
// the file is then only left behind as before).
int removeOnSignal(const std::filesystem::path& path);
// Forgets a registered path (it was renamed or removed normally).
void forgetPath(int slot);

}  // namespace irbake
