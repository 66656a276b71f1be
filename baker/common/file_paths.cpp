#include "common/file_paths.h"

#include <cctype>
#include <system_error>

namespace irbake {

namespace fs = std::filesystem;

std::string lowerExtension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool hasExtension(const fs::path& p, const std::string& ext) { return lowerExtension(p) == ext; }

fs::path folderOf(const fs::path& file) { return file.has_parent_path() ? file.parent_path() : fs::path("."); }

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  auto canonical = [](const fs::path& p) {
    std::error_code error;
    const fs::path c = fs::weakly_canonical(fs::absolute(p), error);
    return error ? fs::absolute(p).lexically_normal() : c;
  };
  return canonical(a) == canonical(b);
}

}  // namespace irbake
