// Runs the irbake executable as a user would (fork + exec, output into a log file) for the command-line
// tests: exit code or 128 + signal, and everything it printed.
#pragma once
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace irbake::testing {

inline std::string fileText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Starts irbake with these arguments (stdout and stderr into log); returns its pid.
inline pid_t startIrbake(const std::vector<std::string>& args, const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* out = std::freopen(log.c_str(), "w", stdout);
    if (!out || dup2(fileno(stdout), 2) < 0) _exit(127);
    std::vector<char*> argv{const_cast<char*>(IRBAKE_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(IRBAKE_EXE, argv.data());
    _exit(127);
  }
  return pid;
}

// Exit code, or 128 + signal.
inline int waitForIrbake(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

struct IrbakeRun {
  int code;
  std::string output;
};
inline IrbakeRun runIrbakeLogged(const std::vector<std::string>& args, const std::filesystem::path& log) {
  const int code = waitForIrbake(startIrbake(args, log));
  return {code, fileText(log)};
}
// Runs irbake with its output in a numbered log of dir (a test's scratch folder).
inline IrbakeRun runIrbakeIn(const std::filesystem::path& dir, const std::vector<std::string>& args) {
  static int n = 0;
  return runIrbakeLogged(args, dir / ("log_" + std::to_string(n++) + ".txt"));
}

// An empty folder test_scratch/<group>/<name> in the working directory (the build folder).
inline std::filesystem::path scratchFolder(const std::string& group, const std::string& name) {
  const std::filesystem::path d = std::filesystem::current_path() / "test_scratch" / group / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// The sample scenes (`irbake samples`) in test_scratch/<group>/samples. Tests of one group may start at once in
// parallel processes: each writes its own copy beside it and renames it into place, so the folder appears whole
// and nothing writes into it afterwards (a copy made while another `samples` run replaced files in it failed).
inline std::filesystem::path sampleScenes(const std::string& group) {
  namespace fs = std::filesystem;
  const fs::path d = fs::current_path() / "test_scratch" / group / "samples";
  if (!fs::exists(d / "cornell_box.gltf")) {
    const std::string pid = std::to_string(getpid());
    const fs::path mine = d.parent_path() / ("samples.writing." + pid);
    fs::remove_all(mine);
    fs::create_directories(mine);
    runIrbakeLogged({"samples", mine.string(), "--quiet"}, d.parent_path() / ("samples_log." + pid + ".txt"));
    std::error_code ec;
    fs::rename(mine, d, ec);  // fails when another process's copy is there already: then that one is used
    if (ec) fs::remove_all(mine, ec);
  }
  return d;
}

}  // namespace irbake::testing
