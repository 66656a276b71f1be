// Write-then-rename: no half-written output ever carries the final name.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

namespace irbake {

// Calls writer(tempPath) and renames tempPath to finalPath if it returns normally. If the writer
// throws, the temp file is removed and the exception propagates. Throws Error(Io) when the rename fails.
void writeAtomically(const std::filesystem::path& finalPath,
                     const std::function<void(const std::filesystem::path& tempPath)>& writer);

// Same for a set of files that belong together (a glTF with its PNG and EXRs): every writer runs
// on a temp name first; only when all succeeded are they all renamed. On failure none remains.
struct PendingFile {
  std::filesystem::path finalPath;
  std::function<void(const std::filesystem::path& tempPath)> writer;
};
void writeAllAtomically(const std::vector<PendingFile>& files);

// A temp name beside finalPath (same folder, so rename is atomic on one filesystem).
std::filesystem::path tempPathFor(const std::filesystem::path& finalPath);

}  // namespace irbake
