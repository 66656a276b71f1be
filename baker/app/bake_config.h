// `irbake bake --config bake.toml`: the bake's options in a file a pipeline checks in beside the level.
// A TOML subset: `key = value` lines, the key a long option of `irbake bake` without its dashes ("scene"
// for SCENE), the value a "string", a number or true/false; `#` comments; an optional [bake] table.
// Relative paths (scene, output, report, env) are read from the file's folder. The command line wins.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace irbake::app {

struct ConfigEntry {
  std::string key;    // option name without dashes
  std::string value;  // as the command line would give it ("true" / "false" for flags)
  int line = 0;       // 1-based, for messages
};

// Reads the file's entries. Throws Error(Io) when unreadable, Error(Parse) naming the file and line for a
// line that is not `key = value`, a repeated key, or a value that is neither a string, a number nor a boolean.
std::vector<ConfigEntry> readConfigFile(const std::filesystem::path& file);

// A config file's text for these entries (strings quoted, numbers and booleans bare; a key starting with
// "# " is written as a comment line), with a header line.
std::string configText(const std::vector<ConfigEntry>& entries, const std::string& header);

}  // namespace irbake::app
