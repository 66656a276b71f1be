#include "app/bake_config.h"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/excerpt.h"

namespace irbake::app {

namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// The whole text is one number strtod reads (a NUL inside is not the end of it).
bool isNumber(const std::string& s) {
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

void appendUtf8(std::string& out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// Reads the "string" whose opening quote is at text[at], escapes decoded; `at` ends past its closing quote.
// False, with `error` set, for an unknown escape or a missing closing quote.
bool readString(const std::string& text, size_t& at, std::string& out, std::string& error) {
  ++at;
  while (at < text.size()) {
    const char c = text[at++];
    if (c == '"') return true;
    if (c != '\\') {
      out += c;
      continue;
    }
    if (at >= text.size()) break;
    const char e = text[at++];
    switch (e) {
      case '"': out += '"'; break;
      case '\\': out += '\\'; break;
      case 'b': out += '\b'; break;
      case 'f': out += '\f'; break;
      case 'n': out += '\n'; break;
      case 'r': out += '\r'; break;
      case 't': out += '\t'; break;
      case 'u':
      case 'U': {
        const size_t digits = e == 'u' ? 4 : 8;
        uint32_t cp = 0;
        bool hex = at + digits <= text.size();
        for (size_t k = 0; hex && k < digits; ++k) {
          const char h = text[at + k];
          hex = std::isxdigit(static_cast<unsigned char>(h)) != 0;
          cp = cp * 16 + static_cast<uint32_t>(std::isdigit(static_cast<unsigned char>(h)) ? h - '0' : (std::tolower(h) - 'a' + 10));
        }
        if (!hex || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
          error = std::string("\\") + e + " needs " + std::to_string(digits) + " hex digits of a Unicode scalar value";
          return false;
        }
        appendUtf8(out, cp);
        at += digits;
        break;
      }
      default:
        error = "unknown escape " + quotedExcerpt(std::string("\\") + e) +
                " in a string (a backslash is written \\\\, a quote \\\")";
        return false;
    }
  }
  error = "a string without its closing quote";
  return false;
}

// The line up to a '#' that is outside a string.
std::string withoutComment(const std::string& raw) {
  bool quoted = false;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (quoted && raw[i] == '\\') {
      ++i;
      continue;
    }
    if (raw[i] == '"') quoted = !quoted;
    if (raw[i] == '#' && !quoted) return raw.substr(0, i);
  }
  return raw;
}

// The file's bytes, refused before reading when it is not a regular file of at most kMaxConfigBytes.
std::string configBytes(const fs::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (!fs::exists(status)) throw Error(ErrorCode::Io, name, "cannot read the config file (no such file)");
  if (fs::is_directory(status)) throw Error(ErrorCode::Usage, name, "--config names a folder: give the config file (bake.toml)");
  if (!fs::is_regular_file(status))
    throw Error(ErrorCode::Usage, name, "--config needs a regular file, not a device, a pipe or a socket");
  auto tooLarge = [&](const std::string& size) {
    return Error(ErrorCode::Parse, name, "the config file is " + size + " bytes, more than the " +
                                             std::to_string(kMaxConfigBytes) + " (1 MiB) a config file may have");
  };
  const std::uintmax_t size = fs::file_size(file, ec);
  if (!ec && size > kMaxConfigBytes) throw tooLarge(std::to_string(size));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorCode::Io, name, "cannot read the config file");
  std::string bytes(kMaxConfigBytes + 1, '\0');  // at most one byte past the cap, should the file have grown
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (in.bad()) throw Error(ErrorCode::Io, name, "cannot read the config file");
  bytes.resize(static_cast<size_t>(in.gcount()));
  if (bytes.size() > kMaxConfigBytes) throw tooLarge("over " + std::to_string(kMaxConfigBytes));
  if (bytes.rfind("\xEF\xBB\xBF", 0) == 0) bytes.erase(0, 3);  // a UTF-8 byte-order mark
  return bytes;
}

// `key = ["a", "b", ]`: the strings of the array value (opening bracket at value[0]).
bool readArray(const std::string& value, std::vector<std::string>& items, std::string& error) {
  size_t at = 1;
  auto skipSpace = [&] {
    while (at < value.size() && std::isspace(static_cast<unsigned char>(value[at]))) ++at;
  };
  for (;;) {
    skipSpace();
    if (at < value.size() && value[at] == ']') break;
    if (at >= value.size() || value[at] != '"') {
      error = "an array holds \"strings\" separated by commas, on one line";
      return false;
    }
    std::string item;
    if (!readString(value, at, item, error)) return false;
    items.push_back(item);
    skipSpace();
    if (at < value.size() && value[at] == ',') {
      ++at;
      continue;
    }
    if (at < value.size() && value[at] == ']') break;
    error = "an array holds \"strings\" separated by commas, on one line";
    return false;
  }
  if (at + 1 != value.size()) {
    error = "text after the array's ]: " + quotedExcerpt(value.substr(at + 1));
    return false;
  }
  return true;
}

// A string as the reader reads it back: quotes, backslashes and control bytes escaped.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7F) {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\u%04X", u);
      out += escape;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::vector<ConfigEntry> readConfigFile(const std::filesystem::path& file) {
  const std::string bytes = configBytes(file);
  std::vector<ConfigEntry> entries;
  std::set<std::string> seen;
  size_t start = 0;
  for (int line = 1; start < bytes.size(); ++line) {
    size_t end = bytes.find('\n', start);
    if (end == std::string::npos) end = bytes.size();
    const std::string raw = bytes.substr(start, end - start);
    start = end + 1;
    auto fail = [&](const std::string& what) {
      throw Error(ErrorCode::Parse, file.string(), "line " + std::to_string(line) + ": " + what);
    };
    const std::string text = trim(withoutComment(raw));
    if (text.empty()) continue;
    if (text.front() == '[') {
      if (text != "[bake]") fail("only a [bake] table is read here, not " + quotedExcerpt(text));
      continue;
    }
    const size_t eq = text.find('=');
    if (eq == std::string::npos) fail("expected key = value, got " + quotedExcerpt(text));
    ConfigEntry e;
    e.key = trim(text.substr(0, eq));
    e.line = line;
    const std::string value = trim(text.substr(eq + 1));
    if (e.key.empty() || e.key.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
      fail(quotedExcerpt(e.key) + " is not an option name (lower case, without the leading --)");
    const std::string key = "key " + quotedExcerpt(e.key);
    if (!seen.insert(e.key).second) fail(key + " is given twice (a repeatable option takes an array: [\"a\", \"b\"])");
    std::string error;
    if (!value.empty() && value.front() == '"') {
      size_t at = 0;
      if (!readString(value, at, e.value, error)) fail(key + ": " + error);
      if (at != value.size()) fail(key + ": text after the string: " + quotedExcerpt(value.substr(at)));
    } else if (!value.empty() && value.front() == '[') {
      e.array = true;
      if (!readArray(value, e.items, error)) fail(key + ": " + error);
    } else if (value == "true" || value == "false" || isNumber(value)) {
      e.value = value;
    } else {
      fail(key + ": the value must be a \"string\", a number, true/false or an array of strings, got " +
           quotedExcerpt(value));
    }
    entries.push_back(e);
  }
  return entries;
}

std::string configText(const std::vector<ConfigEntry>& entries, const std::string& header) {
  std::ostringstream out;
  out << "# " << header << "\n[bake]\n";
  for (const ConfigEntry& e : entries) {
    out << e.key << " = ";
    if (e.key.rfind("# ", 0) == 0) {  // a comment line: a knob at the value the bake uses, not set by the file
      out << e.value << "\n";
      continue;
    }
    if (e.array) {
      out << "[";
      for (size_t i = 0; i < e.items.size(); ++i) out << (i ? ", " : "") << quoted(e.items[i]);
      out << "]\n";
      continue;
    }
    const bool bare = e.value == "true" || e.value == "false" || isNumber(e.value);
    out << (bare ? e.value : quoted(e.value)) << "\n";
  }
  return out.str();
}

}  // namespace irbake::app
