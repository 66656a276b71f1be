#include "common/excerpt.h"

#include <cstdint>
#include <cstdio>

namespace irbake {

namespace {

// The valid UTF-8 sequence at s[i]: its length and code point; 0 for a byte that starts none (overlong,
// surrogate, truncated or stray continuation bytes included).
size_t utf8At(const std::string& s, size_t i, uint32_t& cp) {
  const unsigned char c = static_cast<unsigned char>(s[i]);
  size_t n = 0;
  if (c < 0x80) {
    cp = c;
    return 1;
  }
  if ((c & 0xE0) == 0xC0) n = 2, cp = c & 0x1Fu;
  else if ((c & 0xF0) == 0xE0) n = 3, cp = c & 0x0Fu;
  else if ((c & 0xF8) == 0xF0) n = 4, cp = c & 0x07u;
  else return 0;
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    const unsigned char d = static_cast<unsigned char>(s[i + k]);
    if ((d & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (d & 0x3Fu);
  }
  static const uint32_t kSmallest[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < kSmallest[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// Code points a terminal shows as nothing (or moves the cursor for): controls, soft hyphen, zero-width and
// direction marks, the byte-order mark.
bool invisible(uint32_t cp) {
  return cp < 0x20 || (cp >= 0x7F && cp < 0xA0) || cp == 0xAD || (cp >= 0x200B && cp <= 0x200F) ||
         (cp >= 0x2028 && cp <= 0x202E) || (cp >= 0x2060 && cp <= 0x2064) || cp == 0xFEFF;
}

// The printable part of text from `at` up to about maxBytes shown; `at` ends where it stopped. A quoted excerpt
// escapes its backslashes too (so \x41 in the text cannot pass for an escape); a whole message keeps them.
std::string printable(const std::string& text, size_t maxBytes, size_t& at, bool escapeBackslash) {
  std::string out;
  size_t shown = 0;
  while (at < text.size() && shown < maxBytes) {
    uint32_t cp = 0;
    const size_t n = utf8At(text, at, cp);
    char escape[16];
    if (n == 0 || (n == 1 && invisible(cp))) {
      std::snprintf(escape, sizeof escape, "\\x%02X", static_cast<unsigned char>(text[at]));
      out += escape;
      ++at;
      shown += 4;
      continue;
    }
    if (invisible(cp)) {
      std::snprintf(escape, sizeof escape, "\\u{%04X}", cp);
      out += escape;
    } else if (cp == '\\' && escapeBackslash) {
      out += "\\\\";
    } else {
      out.append(text, at, n);
    }
    at += n;
    shown += n;
  }
  return out;
}

}  // namespace

std::string quotedExcerpt(const std::string& text, size_t maxBytes) {
  size_t at = 0;
  const std::string shown = printable(text, maxBytes, at, true);
  if (at < text.size()) return "'" + shown + "…' (" + std::to_string(text.size()) + " bytes)";
  return "'" + shown + "'";
}

std::string printableExcerpt(const std::string& text, size_t maxBytes) {
  size_t at = 0;
  const std::string shown = printable(text, maxBytes, at, false);
  if (at < text.size()) return shown + "… (" + std::to_string(text.size()) + " bytes)";
  return shown;
}

}  // namespace irbake
