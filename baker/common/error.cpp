#include "common/error.h"

namespace irbake {

const char* toString(ErrorCode code) {
  switch (code) {
    case ErrorCode::Io: return "I/O error";
    case ErrorCode::Parse: return "parse error";
    case ErrorCode::InvalidData: return "invalid data";
    case ErrorCode::EmptyScene: return "empty scene";
    case ErrorCode::NoLight: return "no light";
    case ErrorCode::Gl: return "OpenGL error";
    case ErrorCode::NumericError: return "numeric error";
    case ErrorCode::Usage: return "usage error";
  }
  return "error";
}

int exitCodeFor(ErrorCode code) {
  switch (code) {
    case ErrorCode::Usage: return 2;
    case ErrorCode::Io: return 3;
    case ErrorCode::Parse: return 4;
    case ErrorCode::InvalidData: return 5;
    case ErrorCode::EmptyScene: return 6;
    case ErrorCode::NoLight: return 7;
    case ErrorCode::Gl: return 8;
    case ErrorCode::NumericError: return 9;
  }
  return 1;
}

std::string exitCodeHelp() {
  struct Row {
    ErrorCode code;
    const char* meaning;
  };
  const Row rows[] = {
      {ErrorCode::Usage, "bad command-line arguments, an atlas over --max-texels"},
      {ErrorCode::Io, "file missing, unreadable or unwritable; output folder busy (locked by another bake)"},
      {ErrorCode::Parse, "not glTF, malformed JSON, bad GLB container"},
      {ErrorCode::InvalidData, "bad buffers, accessors, indices, NaN, nesting, URIs or sizes"},
      {ErrorCode::EmptyScene, "no triangles"},
      {ErrorCode::NoLight, "no light and no emitter (give --sun)"},
      {ErrorCode::Gl, "no EGL display / OpenGL 4.5, shader or framebuffer failure"},
      {ErrorCode::NumericError, "NaN or Inf produced by a computation"},
  };
  std::string text = "exit codes:\n  0  success\n  1  unexpected internal error\n";
  for (const Row& r : rows)
    text += "  " + std::to_string(exitCodeFor(r.code)) + "  " + toString(r.code) + ": " + r.meaning + "\n";
  return text;
}

}  // namespace irbake
