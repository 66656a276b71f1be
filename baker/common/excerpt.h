// Text from a user's file or option quoted in a one-line message: short, and every byte that does not print
// shown as an escape, so a binary file, a huge line or an invisible mark cannot garble or flood the terminal.
#pragma once
#include <cstddef>
#include <string>

namespace irbake {

// `text` in single quotes, its bytes that do not print (control bytes, invalid UTF-8) escaped as \xNN and its
// invisible code points (U+FEFF, zero-width and direction marks, C1 controls) as \u{XXXX}, a backslash as \\;
// cut after about maxBytes with "…' (N bytes)" added. Printable UTF-8 is kept as it is.
std::string quotedExcerpt(const std::string& text, size_t maxBytes = 60);

// The same without the quotes and with backslashes as they are, "… (N bytes)" after a cut: for a whole
// message that may hold such text.
std::string printableExcerpt(const std::string& text, size_t maxBytes);

}  // namespace irbake
