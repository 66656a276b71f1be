#include "shaders.h"

#include <cstring>
#include <stdexcept>

namespace irbake::detail {
struct EmbeddedShader { const char* name; const char* source; };
extern const EmbeddedShader kEmbeddedShaders[];
}  // namespace irbake::detail

namespace irbake {
std::string shaderSource(const std::string& fileName) {
  for (const auto* s = detail::kEmbeddedShaders; s->name; ++s)
    if (fileName == s->name) return s->source;
  throw std::runtime_error("shader not embedded: shaders/" + fileName);
}
}  // namespace irbake
