#include "glcontext/gl_program.h"

#include "common/error.h"
#include "shaders.h"

namespace irbake {

namespace {

std::string joinNames(const std::vector<std::string>& files) {
  std::string s;
  for (const auto& f : files) s += (s.empty() ? "shaders/" : "+shaders/") + f;
  return s;
}

}  // namespace

GlProgram::GlProgram(const std::vector<ShaderStage>& stages, const std::vector<std::string>& defines,
                     const std::string& version) {
  std::vector<GLuint> shaders;
  auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  program_ = glCreateProgram();
  for (const ShaderStage& stage : stages) {
    std::string source = "#version " + version + "\n";
    for (const auto& d : defines) source += d + "\n";
    std::string names = joinNames(stage.files);
    try {
      for (const auto& f : stage.files) source += "#line 1\n" + shaderSource(f) + "\n";
    } catch (const std::exception& e) {
      cleanup();
      glDeleteProgram(program_);
      throw Error(ErrorCode::Gl, names, e.what());
    }
    GLuint s = glCreateShader(stage.type);
    shaders.push_back(s);
    const char* src = source.c_str();
    glShaderSource(s, 1, &src, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      GLint len = 0;
      glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
      std::string log(std::max(len, 1), '\0');
      glGetShaderInfoLog(s, len, nullptr, log.data());
      cleanup();
      glDeleteProgram(program_);
      throw Error(ErrorCode::Gl, names, "shader compilation failed: " + log);
    }
    glAttachShader(program_, s);
  }
  glLinkProgram(program_);
  cleanup();
  GLint ok = 0;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(program_, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::max(len, 1), '\0');
    glGetProgramInfoLog(program_, len, nullptr, log.data());
    glDeleteProgram(program_);
    std::string names;
    for (const auto& st : stages) names += (names.empty() ? "" : ", ") + joinNames(st.files);
    throw Error(ErrorCode::Gl, names, "program link failed: " + log);
  }
}

GlProgram::~GlProgram() {
  if (program_) glDeleteProgram(program_);
}

const GlProgram& GlProgramCache::get(const std::vector<ShaderStage>& stages, const std::vector<std::string>& defines,
                                     const std::string& version) {
  std::string key = version;
  for (const ShaderStage& st : stages) key += "\n@" + std::to_string(st.type) + ":" + joinNames(st.files);
  for (const std::string& d : defines) key += "\n" + d;
  std::unique_ptr<GlProgram>& p = programs_[key];
  if (!p) {
    try {
      p = std::make_unique<GlProgram>(stages, defines, version);
    } catch (...) {
      programs_.erase(key);
      throw;
    }
    ++builds_;
  }
  return *p;
}

}  // namespace irbake
