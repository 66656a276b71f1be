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

}  // namespace irbake
