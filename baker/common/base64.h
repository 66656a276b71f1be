// Base64 (RFC 4648, the alphabet with + and /), as glTF's data URIs carry their bytes.
#pragma once
#include <string>

namespace irbake {

std::string base64Encode(const std::string& bytes);
// Skips what is not a digit of the alphabet (padding, line breaks).
std::string base64Decode(const std::string& text);

}  // namespace irbake
