#include "glcontext/gl_context.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "common/error.h"

namespace irbake {
namespace {

GLuint compile(GLenum type, const char* src) {
  GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  EXPECT_EQ(ok, GL_TRUE);
  return s;
}

TEST(GlContext, CreatesCore45HeadlessContext) {
  GlContext ctx;
  EXPECT_FALSE(ctx.renderer().empty());
  EXPECT_GE(epoxy_gl_version(), 45);
  GLint profile = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  EXPECT_NE(ctx.description().find(ctx.renderer()), std::string::npos);
  std::printf("renderer: %s\n", ctx.description().c_str());
}

// Draws a full-screen triangle three times with additive blending into an RGBA32F target and
// reads back exact float sums: the path the backend's accumulation depends on.
TEST(GlContext, RendersAndBlendsFloatTarget) {
  GlContext ctx;
  const int w = 8, h = 4;
  GLuint tex = 0, fbo = 0, vao = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &tex);
  glTextureStorage2D(tex, 1, GL_RGBA32F, w, h);
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, tex, 0);
  ASSERT_EQ(glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
  glCreateVertexArrays(1, &vao);
  GLuint vs = compile(GL_VERTEX_SHADER,
                      "#version 450 core\nvoid main(){vec2 p=vec2((gl_VertexID<<1)&2,gl_VertexID&2);"
                      "gl_Position=vec4(p*2.0-1.0,0,1);}");
  GLuint fs = compile(GL_FRAGMENT_SHADER,
                      "#version 450 core\nuniform float k; out vec4 c;"
                      "void main(){c=vec4(k*gl_FragCoord.x, 1e-7, 1e7, 0.25);}");
  GLuint prog = glCreateProgram();
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  GLint linked = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &linked);
  ASSERT_EQ(linked, GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, w, h);
  const float zero[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, zero);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glUseProgram(prog);
  glBindVertexArray(vao);
  for (int i = 0; i < 3; ++i) {
    glUniform1f(glGetUniformLocation(prog, "k"), float(i + 1));
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  std::vector<float> px(4 * w * h);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, px.data());
  checkGlError("readback");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = &px[4 * (y * w + x)];
      EXPECT_FLOAT_EQ(p[0], 6.0f * (x + 0.5f));  // (1+2+3) × pixel centre
      EXPECT_FLOAT_EQ(p[1], 3e-7f);              // no 8-bit or half-float quantisation
      EXPECT_FLOAT_EQ(p[2], 3e7f);
      EXPECT_FLOAT_EQ(p[3], 0.75f);
    }
  glDeleteProgram(prog);
  glDeleteShader(vs);
  glDeleteShader(fs);
  glDeleteFramebuffers(1, &fbo);
  glDeleteTextures(1, &tex);
  glDeleteVertexArrays(1, &vao);
}

TEST(GlContext, RoutesKhrDebugMessages) {
  GlContext ctx;
  const int before = ctx.debugMessageCount();
  glDebugMessageInsert(GL_DEBUG_SOURCE_APPLICATION, GL_DEBUG_TYPE_MARKER, 42, GL_DEBUG_SEVERITY_NOTIFICATION, -1,
                       "irbake test marker");
  EXPECT_EQ(ctx.debugMessageCount(), before + 1);
  // An invalid enum must come back as a GL error message and through checkGlError.
  const int errorsBefore = ctx.debugErrorCount();
  glEnable(GLenum(0xDEAD));
  EXPECT_THROW(checkGlError("glEnable(bad)"), Error);
  EXPECT_EQ(ctx.debugErrorCount(), errorsBefore + 1);
}

// The fallback path on its own: the EGL device platform (a GPU without a display; Mesa lists its
// software device too). Skipped where the EGL has no device enumeration.
TEST(GlContext, DevicePlatformAlone) {
  GlContextOptions opt;
  opt.platforms = {EglPlatform::Device};
  std::unique_ptr<GlContext> ctx;
  try {
    ctx = std::make_unique<GlContext>(opt);
  } catch (const Error& e) {
    GTEST_SKIP() << "no EGL device platform here: " << e.what();
  }
  EXPECT_EQ(ctx->platform(), EglPlatform::Device);
  EXPECT_GE(epoxy_gl_version(), 45);
  std::printf("device renderer: %s\n", ctx->description().c_str());
}

TEST(GlContext, FailsWithBackendHintWhenNoPlatform) {
  GlContextOptions opt;
  opt.platforms.clear();
  try {
    GlContext ctx(opt);
    FAIL() << "expected Error(Gl)";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Gl);
    EXPECT_NE(std::string(e.what()).find("--backend embree"), std::string::npos);
  }
}

TEST(GlContext, FailsWithBackendHintForImpossibleVersion) {
  GlContextOptions opt;
  opt.glMajor = 9;
  opt.glMinor = 9;
  try {
    GlContext ctx(opt);
    FAIL() << "expected Error(Gl)";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Gl);
    EXPECT_NE(std::string(e.what()).find("--backend embree"), std::string::npos);
  }
}

}  // namespace
}  // namespace irbake
