#include "common/output_guard.h"

#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include <sys/vfs.h>

#include "common/checksum.h"
#include "common/error.h"
#include "common/file_paths.h"

namespace irbake {

namespace fs = std::filesystem;

namespace {

constexpr const char* kManifestHeader = "# irbake manifest 1: XXH3-64, size and name of each file irbake wrote here";

struct ManifestEntry {
  std::string hash;
  uintmax_t size = 0;
};
using Manifest = std::map<std::string, ManifestEntry>;  // file name -> what was written

// XXH3-64 of a file's bytes (hex), or "" when it cannot be read.
std::string fileHash(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  Checksum64 sum;
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    sum.add(buffer.data(), static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) return "";
  return sum.hex();
}

Manifest readManifest(const fs::path& folder) {
  Manifest manifest;
  std::error_code ec;
  const fs::path file = folder / OutputGuard::kManifestName;
  if (!fs::is_regular_file(file, ec) || fs::file_size(file, ec) > (64u << 20)) return manifest;
  std::ifstream in(file, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line != kManifestHeader) return manifest;  // not ours: proves nothing
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    ManifestEntry e;
    std::string name;
    if (!(fields >> e.hash >> e.size) || e.hash.size() != 16) continue;
    std::getline(fields, name);
    if (name.size() < 2 || name[0] != ' ') continue;
    manifest[name.substr(1)] = e;
  }
  return manifest;
}

void writeManifest(const fs::path& folder, const Manifest& manifest) {
  std::string text = std::string(kManifestHeader) + "\n";
  for (const auto& [name, e] : manifest) text += e.hash + " " + std::to_string(e.size) + " " + name + "\n";
  writeAtomically(folder / OutputGuard::kManifestName, [&](const fs::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw Error(ErrorCode::Io, (folder / OutputGuard::kManifestName).string(), "cannot write the manifest");
  });
}

// Records `files` (all in `folder`, as written now) and forgets entries whose file is gone.
void updateManifest(const fs::path& folder, const std::vector<fs::path>& files) {
  Manifest manifest = readManifest(folder);
  std::error_code ec;
  for (auto it = manifest.begin(); it != manifest.end();)
    it = fs::is_regular_file(folder / it->first, ec) ? std::next(it) : manifest.erase(it);
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    if (name.find('\n') != std::string::npos || name.find('\r') != std::string::npos) continue;
    ManifestEntry e{fileHash(file), fs::file_size(file, ec)};
    if (ec || e.hash.empty()) {
      manifest.erase(name);
      continue;
    }
    manifest[name] = e;
  }
  writeManifest(folder, manifest);
}

// The nearest part of `p` that exists (itself, or a parent folder), for statfs.
fs::path nearestExisting(const fs::path& p) {
  std::error_code ec;
  fs::path at = fs::absolute(p, ec);
  while (!at.empty() && !fs::exists(at, ec)) {
    if (at == at.parent_path()) break;
    at = at.parent_path();
  }
  return at.empty() ? fs::path("/") : at;
}

bool onPseudoFilesystem(const fs::path& p) {
  struct statfs info {};
  if (::statfs(nearestExisting(p).c_str(), &info) != 0) return false;
  switch (static_cast<unsigned long>(info.f_type)) {
    case 0x9fa0:      // proc
    case 0x62656572:  // sysfs
    case 0x1cd1:      // devpts
    case 0x27e0eb:    // cgroup
    case 0x63677270:  // cgroup2
    case 0x64626720:  // debugfs
    case 0x74726163:  // tracefs
    case 0x73636673:  // securityfs
    case 0x62656570:  // configfs
    case 0xcafe4a11:  // bpf
      return true;
    default:
      return false;
  }
}

}  // namespace

std::string unwritableReason(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (fs::is_directory(status)) return "is a folder, not a file name for this output";
  if (fs::exists(status) && !fs::is_regular_file(status))
    return "is not a regular file (a device, fifo or socket): refusing to replace it";
  if (onPseudoFilesystem(file)) return "is on a kernel pseudo-filesystem (/proc, /sys), not a place for an output";
  if (file.filename() == OutputGuard::kManifestName || file.filename().empty() || file.filename() == "." ||
      file.filename() == "..")
    return "is not a file name this command may write";
  if (isIrbakeTempName(file.filename().string())) return "is the name of an irbake temporary file: choose another name";
  return "";
}

void OutputGuard::addInput(const fs::path& file) {
  for (const Output& o : outputs_)
    if (sameFile(o.file, file))
      throw Error(ErrorCode::Usage, file.string(),
                  "is an input of this command and would be overwritten by " + o.what + ": choose another name");
  for (const NamedOutputs& n : named_)
    if (sameFile(folderOf(file), n.folder) && n.matches(file.filename().string()))
      throw Error(ErrorCode::Usage, file.string(),
                  "is an input of this command and would be overwritten by " + n.what + ": choose another output folder");
  inputs_.push_back(file);
}

void OutputGuard::addInputs(const std::vector<fs::path>& files) {
  for (const fs::path& f : files) addInput(f);
}

void OutputGuard::check(const fs::path& file, const std::string& what, const Output* self) const {
  const std::string reason = unwritableReason(file);
  if (!reason.empty()) throw Error(ErrorCode::Usage, file.string(), reason + " (" + what + ")");
  for (const fs::path& input : inputs_)
    if (sameFile(input, file))
      throw Error(ErrorCode::Usage, file.string(),
                  "is an input of this command and would be overwritten by " + what + ": choose another name");
  for (const Output& o : outputs_)
    if (&o != self && sameFile(o.file, file))
      throw Error(ErrorCode::Usage, file.string(), what + " would overwrite " + o.what + ": choose another name");
  if (self)
    for (const NamedOutputs& n : named_)
      if (sameFile(folderOf(file), n.folder) && n.matches(file.filename().string()))
        throw Error(ErrorCode::Usage, file.string(), what + " would overwrite " + n.what + ": choose another name");
}

void OutputGuard::addOutput(const fs::path& file, const std::string& what, ExistingOutput existing) {
  outputs_.push_back({file, what});
  try {
    check(file, what, &outputs_.back());
    std::error_code ec;
    if (existing == ExistingOutput::ReplaceOurs && fs::exists(file, ec) && !provablyOurs(file))
      throw Error(ErrorCode::Usage, file.string(),
                  "exists and was not written by irbake (or was changed since): refusing to replace it; remove it "
                  "or choose another folder");
  } catch (...) {
    outputs_.pop_back();
    throw;
  }
}

void OutputGuard::addOutputNames(const fs::path& folder, std::function<bool(const std::string&)> matches,
                                 const std::string& what) {
  for (const fs::path& input : inputs_)
    if (sameFile(folderOf(input), folder) && matches(input.filename().string()))
      throw Error(ErrorCode::Usage, input.string(),
                  "is an input of this command and would be overwritten by " + what + ": choose another output folder");
  for (const Output& o : outputs_)
    if (sameFile(folderOf(o.file), folder) && matches(o.file.filename().string()))
      throw Error(ErrorCode::Usage, o.file.string(), o.what + " would overwrite " + what + ": choose another name");
  named_.push_back({folder, std::move(matches), what});
}

void OutputGuard::write(const std::vector<PendingFile>& files) const {
  for (size_t i = 0; i < files.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (sameFile(files[i].finalPath, files[j].finalPath))
        throw Error(ErrorCode::Usage, files[i].finalPath.string(), "is written twice by this command: choose another name");
    const Output* declared = nullptr;
    for (const Output& o : outputs_)
      if (sameFile(o.file, files[i].finalPath)) declared = &o;
    check(files[i].finalPath, declared ? declared->what : "an output", declared);
  }
  writeAllAtomically(files);
  std::map<fs::path, std::vector<fs::path>> byFolder;
  for (const PendingFile& f : files)
    for (const fs::path& kept : manifestFolders_)
      if (sameFile(folderOf(f.finalPath), kept)) {
        byFolder[kept].push_back(f.finalPath);
        break;
      }
  // The outputs are in place; a manifest that cannot be written only means they are never removed later.
  for (const auto& [folder, written] : byFolder) try {
      updateManifest(folder, written);
    } catch (const Error&) {
    }
}

void OutputGuard::keepManifest(const fs::path& folder) { manifestFolders_.push_back(folder); }

void OutputGuard::write(const fs::path& file, const std::function<void(const fs::path&)>& writer) const {
  write(std::vector<PendingFile>{PendingFile{file, writer}});
}

bool OutputGuard::provablyOurs(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(file, ec))) return false;
  const Manifest manifest = readManifest(folderOf(file));
  const auto it = manifest.find(file.filename().string());
  if (it == manifest.end()) return false;
  const uintmax_t size = fs::file_size(file, ec);
  return !ec && size == it->second.size && fileHash(file) == it->second.hash;
}

bool OutputGuard::removeIfOurs(const fs::path& file) const {
  if (!provablyOurs(file)) return false;
  for (const fs::path& input : inputs_)
    if (sameFile(input, file)) return false;
  std::error_code ec;
  if (!fs::remove(file, ec) || ec) return false;
  try {
    updateManifest(folderOf(file), {});
  } catch (const Error&) {
  }
  return true;
}

}  // namespace irbake
