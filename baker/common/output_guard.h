// The one gate every file a command writes goes through (bake, merge, unwrap, samples, irview's screenshots).
// It knows the command's inputs and outputs, refuses an output that is an input, another output, a folder, a
// special file or a path on a kernel pseudo-filesystem (/proc, /sys), writes each set through temp names and
// renames after every check, and removes a file only when the manifest of its folder proves irbake wrote it
// and it is unchanged since.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/atomic_file.h"

namespace irbake {

// What a command may do with an output name that already exists.
enum class ExistingOutput {
  Replace,       // the user named it (or its folder): replace it
  ReplaceOurs,   // the command chose the name itself: replace it only when the manifest proves it is ours
};

class OutputGuard {
 public:
  // A file the command reads: no output may land on it, however named (links, relative paths).
  void addInput(const std::filesystem::path& file);
  void addInputs(const std::vector<std::filesystem::path>& files);

  // Declares an output before anything is written. `what` names it in messages ("--report", "the glTF
  // output"). Throws Error(Usage, file) when it is an input, another declared output, a folder, a special
  // file (device, fifo, socket), on /proc or /sys, or (ReplaceOurs) an existing file the manifest does not
  // prove is ours.
  void addOutput(const std::filesystem::path& file, const std::string& what,
                 ExistingOutput existing = ExistingOutput::Replace);
  // Declares the names the command picks itself inside `folder` (a bake's pages): any input or other output
  // there whose name `matches` is refused, naming `what`.
  void addOutputNames(const std::filesystem::path& folder, std::function<bool(const std::string&)> matches,
                      const std::string& what);

  // Keeps the manifest of `folder`, a folder the command owns (a bake's OUTDIR, the samples' folder): what it
  // writes there is recorded, so a later run can prove it wrote a file before replacing or removing it.
  // Folders a user merely names a file in (--report, --dump-config, a screenshot) get no manifest.
  void keepManifest(const std::filesystem::path& folder);

  // Checks every file of the set (declared or not: a file declared nowhere is checked like a new output),
  // writes them all-or-nothing through temp names and renames (writeAllAtomically), then records those in
  // folders it keeps a manifest of. Throws before writing anything when a check fails.
  void write(const std::vector<PendingFile>& files) const;
  void write(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& writer) const;

  // Removes `file` when the manifest of its folder proves this program wrote it and it is unchanged since;
  // returns false (removing nothing) otherwise, and for anything that is not a regular file.
  bool removeIfOurs(const std::filesystem::path& file) const;

  // True when the manifest of file's folder lists it with the size and XXH3-64 of its present bytes.
  static bool provablyOurs(const std::filesystem::path& file);

  // The manifest's file name in each folder the guard wrote into.
  static constexpr const char* kManifestName = ".irbake-manifest";

 private:
  struct Output {
    std::filesystem::path file;
    std::string what;
  };
  struct NamedOutputs {
    std::filesystem::path folder;
    std::function<bool(const std::string&)> matches;
    std::string what;
  };
  void check(const std::filesystem::path& file, const std::string& what, const Output* self) const;

  std::vector<std::filesystem::path> inputs_;
  std::vector<Output> outputs_;
  std::vector<NamedOutputs> named_;
  std::vector<std::filesystem::path> manifestFolders_;
};

// Why `file` cannot be an output at all, or "" when it can: a folder, a special file, a pseudo-filesystem.
std::string unwritableReason(const std::filesystem::path& file);

}  // namespace irbake
