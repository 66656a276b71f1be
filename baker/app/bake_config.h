// `irbake bake --config bake.toml`: the bake's options in a file a pipeline checks in beside the level.
// A TOML subset: `key = value` lines, the key a long option of `irbake bake` without its dashes ("scene"
// for SCENE), the value a "string" (escapes \" \\ \n \t \uXXXX), a number, true/false, or, for a repeatable
// option, an array of strings (`light-mode = ["sun=indirect", "*=baked"]`); `#` comments; an optional [bake]
// table; a UTF-8 byte-order mark is skipped. Relative paths (scene, output, report, env) are read from the
// file's folder. The command line wins.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace irbake::app {

// A config file is a page of options: anything larger is not one (and is refused before it is read).
constexpr std::uintmax_t kMaxConfigBytes = 1u << 20;

struct ConfigEntry {
  std::string key;                 // option name without dashes
  std::string value;               // as the command line would give it ("true" / "false" for flags); "" for an array
  int line = 0;                    // 1-based, for messages
  bool array = false;              // `key = ["a", "b"]`: a repeatable option, given once per item
  std::vector<std::string> items;  // the array's strings, in order
};

// Reads the file's entries. Throws Error(Io) when missing or unreadable, Error(Usage) when it is a folder or
// not a regular file (a device, a pipe), Error(Parse) when larger than kMaxConfigBytes, and Error(Parse)
// naming the file and line for a line that is not `key = value`, a repeated key, or a value that is neither a
// string, a number, a boolean nor an array of strings. Messages quote the file's text as a short excerpt.
std::vector<ConfigEntry> readConfigFile(const std::filesystem::path& file);

// A config file's text for these entries (strings quoted and escaped, numbers and booleans bare, arrays of
// strings; a key starting with "# " is written as a comment line), with a header line.
std::string configText(const std::vector<ConfigEntry>& entries, const std::string& header);

}  // namespace irbake::app
