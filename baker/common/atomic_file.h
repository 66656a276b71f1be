// Write-then-rename: no half-written output ever carries the final name, and a failed write leaves the
// previous file at that name exactly as it was.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace irbake {

// Calls writer(tempPath) and renames tempPath to finalPath if it returns normally. If the writer
// throws, the temp file is removed and the exception propagates. Throws Error(Io) when the rename fails.
void writeAtomically(const std::filesystem::path& finalPath,
                     const std::function<void(const std::filesystem::path& tempPath)>& writer);

// Same for a set of files that belong together (a glTF with its PNG and EXRs): every writer runs
// on a temp name first; only when all succeeded are they all renamed. On failure none of the new files
// remains and every file the set would have replaced is back as it was.
struct PendingFile {
  std::filesystem::path finalPath;
  std::function<void(const std::filesystem::path& tempPath)> writer;
};
void writeAllAtomically(const std::vector<PendingFile>& files);

// A temp name beside finalPath (same folder, so rename is atomic on one filesystem). Its name is
// ".irbake-tmp.<pid>.<n>.<final name>": only names of that form are ever removed as stale temps.
std::filesystem::path tempPathFor(const std::filesystem::path& finalPath);
// True for a file name tempPathFor could have made (the stale-temp cleanup removes only those).
bool isIrbakeTempName(const std::string& fileName);
// Removes the temp files a killed irbake left in `folder` (call only while holding its lock).
void removeStaleTemps(const std::filesystem::path& folder);

// Why writing `path` failed, for a message: "no space left on the device" when its filesystem is full,
// else `fallback`.
std::string writeFailureReason(const std::filesystem::path& path, const std::string& fallback);

}  // namespace irbake
