// A linked GLSL program built from embedded sources (shaders/), with errors that name the file.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <epoxy/gl.h>

namespace irbake {

struct ShaderStage {
  GLenum type;                       // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER
  std::vector<std::string> files;    // shaders/<file> sources concatenated after the #version line
};

class GlProgram {
 public:
  // defines: lines placed after the #version line ("#define MAX_BATCH 16"). version: the GLSL
  // version line's argument; the viewer's window asks for a 3.3 core context, hence "330 core".
  GlProgram(const std::vector<ShaderStage>& stages, const std::vector<std::string>& defines = {},
            const std::string& version = "450 core");
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  GLuint id() const { return program_; }
  void use() const { glUseProgram(program_); }
  GLint uniform(const char* name) const { return glGetUniformLocation(program_, name); }

 private:
  GLuint program_ = 0;
};

// Programs built once per context and reused, keyed by their stages, defines and version. Interleaved
// sampling calls the GL backend n² + 1 times per bake; rebuilding its programs each time is slow on llvmpipe,
// which also JIT-compiles a program's state variants again at its first draws.
// Owned by GlContext (GlContext::programs), destroyed with the context current.
class GlProgramCache {
 public:
  const GlProgram& get(const std::vector<ShaderStage>& stages, const std::vector<std::string>& defines = {},
                       const std::string& version = "450 core");
  size_t size() const { return programs_.size(); }
  size_t builds() const { return builds_; }  // programs compiled so far (a hit builds nothing)

 private:
  std::map<std::string, std::unique_ptr<GlProgram>> programs_;
  size_t builds_ = 0;
};

}  // namespace irbake
