// Errors that reach the user: a code, the file it concerns and a one-line message.
#pragma once
#include <stdexcept>
#include <string>

namespace irbake {

enum class ErrorCode {
  Io,            // file missing, unreadable or unwritable
  Parse,         // not glTF, malformed JSON, bad binary container
  InvalidData,   // buffers, accessors, indices, NaN, recursion, unsafe URI, absurd sizes
  EmptyScene,    // no triangles
  NoLight,       // no light, no emitter and none given on the command line
  Gl,            // no EGL display / GL 4.5, shader or framebuffer failure
  NumericError,  // NaN or Inf produced by a computation
  Usage,         // bad command-line arguments
};

const char* toString(ErrorCode code);

// Thrown by every stage; the command prints "irbake: error: <file>: <message>" and exits non-zero.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, std::string file, const std::string& message)
      : std::runtime_error(file.empty() ? message : file + ": " + message), code_(code), file_(std::move(file)) {}
  ErrorCode code() const { return code_; }
  const std::string& file() const { return file_; }

 private:
  ErrorCode code_;
  std::string file_;
};

// Process exit code for an error code (distinct per class so scripts can tell them apart).
int exitCodeFor(ErrorCode code);

// The exit codes as a help footer: "exit codes:\n  0  success\n  2  usage error: ...".
std::string exitCodeHelp();

}  // namespace irbake
