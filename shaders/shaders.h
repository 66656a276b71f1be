// GLSL sources embedded at build time from shaders/*.{vert,frag,comp,glsl}.
#pragma once
#include <string>

namespace irbake {
// The source of shaders/<fileName>; throws Error(Gl) naming the file when it is not embedded.
std::string shaderSource(const std::string& fileName);
}  // namespace irbake
