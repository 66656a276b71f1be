#include "app/bake_config.h"

#include <cctype>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "common/error.h"

namespace irbake::app {

namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

bool isNumber(const std::string& s) {
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return *end == 0;
}

}  // namespace

std::vector<ConfigEntry> readConfigFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(ErrorCode::Io, file.string(), "cannot read the config file");
  std::vector<ConfigEntry> entries;
  std::set<std::string> seen;
  std::string raw;
  for (int line = 1; std::getline(in, raw); ++line) {
    auto fail = [&](const std::string& what) {
      throw Error(ErrorCode::Parse, file.string(), "line " + std::to_string(line) + ": " + what);
    };
    // A '#' outside a string starts a comment.
    std::string text;
    bool quoted = false;
    for (char c : raw) {
      if (c == '"') quoted = !quoted;
      if (c == '#' && !quoted) break;
      text += c;
    }
    text = trim(text);
    if (text.empty()) continue;
    if (text.front() == '[') {
      if (text != "[bake]") fail("only a [bake] table is read here, not " + text);
      continue;
    }
    const size_t eq = text.find('=');
    if (eq == std::string::npos) fail("expected key = value, got '" + text + "'");
    ConfigEntry e;
    e.key = trim(text.substr(0, eq));
    e.line = line;
    std::string value = trim(text.substr(eq + 1));
    if (e.key.empty() || e.key.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
      fail("'" + e.key + "' is not an option name (lower case, without the leading --)");
    if (!seen.insert(e.key).second) fail("key '" + e.key + "' is given twice");
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
      e.value = value.substr(1, value.size() - 2);
      if (e.value.find('"') != std::string::npos || e.value.find('\\') != std::string::npos)
        fail("key '" + e.key + "': quotes and backslashes inside a string are not supported");
    } else if (value == "true" || value == "false" || isNumber(value)) {
      e.value = value;
    } else {
      fail("key '" + e.key + "': the value must be a \"string\", a number or true/false, got '" + value + "'");
    }
    entries.push_back(e);
  }
  return entries;
}

std::string configText(const std::vector<ConfigEntry>& entries, const std::string& header) {
  std::ostringstream out;
  out << "# " << header << "\n[bake]\n";
  for (const ConfigEntry& e : entries) {
    // A key starting with "# " is a comment line: a knob at the value the bake uses, not set by the file.
    const bool bare = e.key.rfind("# ", 0) == 0 || e.value == "true" || e.value == "false" || isNumber(e.value);
    out << e.key << " = " << (bare ? e.value : "\"" + e.value + "\"") << "\n";
  }
  return out.str();
}

}  // namespace irbake::app
