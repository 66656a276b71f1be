// Naming and comparing the files a command reads and writes.
#pragma once
#include <filesystem>
#include <string>

namespace irbake {

// The extension in lower case, with its dot (".glb" for "Scene.GLB"; "" without one).
std::string lowerExtension(const std::filesystem::path& p);
// True when p's extension is `ext` (lower case, with its dot) in any case.
bool hasExtension(const std::filesystem::path& p, const std::string& ext);
// The folder a file sits in: its parent, or "." for a bare name.
std::filesystem::path folderOf(const std::filesystem::path& file);
// True when a and b name the same file or folder: the same file where both exist, else the same absolute,
// normal path (links resolved as far as they exist).
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace irbake
