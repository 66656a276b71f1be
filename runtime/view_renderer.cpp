#include "view_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include <epoxy/gl.h>

#include "common/error.h"
#include "common/log.h"
#include "export/light_probes_export.h"
#include "export/map_encoding.h"
#include "mixed_lights.h"
#include "probe_view.h"
#include "screenshot.h"
#include "glcontext/gl_program.h"

namespace irbake::view {
namespace {

void throwOnGlError(const char* what) {
  GLenum e = glGetError(), first = e;
  while (e != GL_NO_ERROR) e = glGetError();  // drain the queue
  if (first != GL_NO_ERROR) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%04x", first);
    throw Error(ErrorCode::Gl, "", std::string(what) + ": GL error " + buf);
  }
}

GLenum glWrap(WrapMode m) {
  switch (m) {
    case WrapMode::ClampToEdge: return GL_CLAMP_TO_EDGE;
    case WrapMode::MirroredRepeat: return GL_MIRRORED_REPEAT;
    default: return GL_REPEAT;
  }
}

// Colour textures: half float (linear values ≤ 1 keep 11 bits), mipmapped for minification.
GLuint uploadColorTexture(const Texture& t) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, t.width, t.height, 0, GL_RGBA, GL_FLOAT, t.texels.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, glWrap(t.wrapS));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, glWrap(t.wrapT));
  return tex;
}

// An environment map (Environment::texels, rows top to bottom) as RGB32F: the sky shader reads it with
// texelFetch, so screenshots hold the map's radiance exactly.
GLuint uploadEnvironment(const Environment& env) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, env.width(), env.height(), 0, GL_RGB, GL_FLOAT, env.texels().data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

struct Vertex {
  glm::vec3 position, normal;
  glm::vec2 uv0, uv1;
  float chart;
};

}  // namespace

// Light maps: half float (range to 65504, 11-bit mantissa: 0.05% relative, far below what a display
// shows) — llvmpipe filters RGBA16F markedly faster than RGB32F (docs/validation.md, "Viewer");
// bilinear, no mipmaps (a coarser level would mix in the padding between charts), clamped at the page edge.
unsigned uploadLightmap(int width, int height, unsigned format, const void* data) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  GLenum internal = GL_RGBA16F;
  glTexImage2D(GL_TEXTURE_2D, 0, internal, width, height, 0, format, GL_FLOAT, data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

const char* toString(ViewMode mode) {
  switch (mode) {
    case ViewMode::Lit: return "lit";
    case ViewMode::Lightmap: return "lightmap";
    case ViewMode::Albedo: return "albedo";
    case ViewMode::Charts: return "charts";
    case ViewMode::TexelDensity: return "density";
    case ViewMode::Wireframe: return "wireframe";
  }
  return "?";
}

const char* toString(LightmapMode mode) { return mode == LightmapMode::L0 ? "l0" : "sh"; }

LightmapMode parseLightmapMode(const std::string& name) {
  for (LightmapMode m : {LightmapMode::Sh, LightmapMode::L0})
    if (name == toString(m)) return m;
  throw Error(ErrorCode::Usage, "", "unknown light-map mode '" + name + "' (sh, l0)");
}

ViewMode parseViewMode(const std::string& name) {
  for (ViewMode m : {ViewMode::Lit, ViewMode::Lightmap, ViewMode::Albedo, ViewMode::Charts,
                     ViewMode::TexelDensity, ViewMode::Wireframe})
    if (name == toString(m)) return m;
  throw Error(ErrorCode::Usage, "",
              "unknown view '" + name + "' (lit, lightmap, albedo, charts, density, wireframe)");
}

// One shader variant: the view mode, the output encoding and what the primitive's material uses,
// reduced to what that mode shows (the lightmap view needs no emissive texture, the charts view no
// base colour unless it cuts alpha-mask holes). Packed into an int as the program cache key.
struct Variant {
  int mode = 0;         // ViewMode, 5 = the wireframe's line pass
  int output = 0;       // 0 linear radiance, 1 exposure + sRGB encode (display)
  int baseTex = 0;      // 0 none, 1 TEXCOORD_0, 2 TEXCOORD_1
  int emissiveTex = 0;  // 0 none, 1 TEXCOORD_0, 2 TEXCOORD_1
  int lightmap = 0;     // 1: the primitive has a light map
  int alphaMask = 0;    // 1: alphaMode MASK
  int directional = 0;  // L1 SH with the normal map: 0 off, 1 normal map on TEXCOORD_0, 2 on TEXCOORD_1
  int mixed = 0;        // 1: shades the export's runtime lights (mixed_lights.h)
  int probeLit = 0;     // 1: lit by the probes instead of a map (a probe-lit object)

  int key() const {
    return mode | output << 3 | baseTex << 4 | emissiveTex << 6 | lightmap << 8 | alphaMask << 9 | directional << 10 |
           mixed << 12 | probeLit << 13;
  }
  static Variant fromKey(int k) {
    return {k & 7,         (k >> 3) & 1,  (k >> 4) & 3,  (k >> 6) & 3, (k >> 8) & 1,
            (k >> 9) & 1,  (k >> 10) & 3, (k >> 12) & 1, (k >> 13) & 1};
  }
  // `all`: every feature of the primitive; keeps those `mode` reads (and the SH only when `sh`).
  static Variant forMode(int mode, int output, const Variant& all, bool sh = true) {
    Variant v;
    v.mode = mode;
    v.output = output;
    if (mode == 5) return v;  // line colour only
    v.alphaMask = all.alphaMask;
    const bool baseShown = mode == 0 || mode == 2;
    v.baseTex = baseShown || all.alphaMask ? all.baseTex : 0;  // other views read base alpha for holes only
    v.emissiveTex = mode == 0 ? all.emissiveTex : 0;
    v.lightmap = mode == 0 || mode == 1 ? all.lightmap : 0;
    v.directional = v.lightmap && sh ? all.directional : 0;
    v.mixed = mode == 0 ? all.mixed : 0;
    v.probeLit = mode == 0 || mode == 1 ? all.probeLit : 0;
    return v;
  }
  int needUv0() const { return baseTex == 1 || emissiveTex == 1 || directional == 1; }
  int needUv1() const { return baseTex == 2 || emissiveTex == 2 || lightmap || mode == 4 || directional == 2 || mixed; }
  int needNormal() const { return mode == 3 || directional != 0 || mixed || probeLit; }
  int needTangent() const { return directional != 0; }
  int needChart() const { return mode == 3 || mode == 4; }
};

struct ViewRenderer::Impl {
  struct GpuPrimitive {
    GLuint vao = 0, vbo = 0, ebo = 0;
    GLuint tangentVbo = 0;        // only for a directional primitive (its normal map needs the frame)
    GLuint l1[3] = {0, 0, 0};     // L1x, L1y, L1z (values, decoded), for a directional primitive
    GLsizei indexCount = 0;
    int material = 0;
    GLuint lightmap = 0;          // 0: none (albedo only)
    float lightmapScale = 1.0f;   // MOZ_lightmap intensity
    glm::vec2 lightmapSize{1.0f};
    GLenum indexType = GL_UNSIGNED_INT;  // GL_UNSIGNED_SHORT when every index fits
    Variant features;                    // everything the material uses (mode and output unset)
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // world-space bounds, for the draw order
    bool cullBackFaces = false;          // closed outward solid, opaque: back faces only show from inside
    GLuint shadowMask = 0;               // with Variant::mixed: the material's mask page (or white)
    ProbeSphere probe;                   // with Variant::probeLit: the probes over the primitive
  };
  const Scene& scene;
  GLuint program = 0;                      // the bound variant
  std::map<int, std::unique_ptr<GlProgram>> programs;  // (view mode, sRGB) variant → program
  std::map<GLuint, std::map<std::string, GLint>> uniformsByProgram;
  std::map<int, GLuint> colorTextures;     // Scene::textures index → GL texture
  std::map<int, GLuint> textureLightmaps;  // Scene::textures index → float light map texture
  std::vector<GLuint> pageTextures;        // ViewerScene::pages index → GL texture
  std::array<std::vector<GLuint>, 3> directionalPageTextures;  // ViewerScene::directionalPages → GL texture
  std::map<std::pair<int, float>, GLuint> directionalPngs;    // (Scene::textures index, scale) → decoded L1
  std::vector<GpuPrimitive> prims;
  std::unique_ptr<RenderTarget> offscreen;  // float target of render(), resized on demand
  GLuint environmentTexture = 0;           // the scene's environment map (0: none, or a uniform sky)
  float environmentRotation = 0.0f;
  std::unique_ptr<GlProgram> skyPrograms[2];  // view_sky per OUTPUT (0 linear, 1 exposure + sRGB)
  GLuint skyVao = 0;                        // empty: the sky triangle comes from gl_VertexID
  std::unique_ptr<MixedLights> mixed;       // the export's runtime lights and mask pages
  std::optional<LightProbeGrid> probeGrid;  // the file's probes, read for the first probe-lit primitive
  bool probeGridRead = false;
  ProbeSphereSun probeSun;                  // the grid's sun level (none: zero)
  int probeEmitterTriangles = 0;            // the grid's exact emitters (probe_emitters.glsl's EMITTER_TRIANGLES)

  // A probe-lit primitive (an export's extras.lightProbes, Primitive::mode): the probes over its bounding sphere
  // (world box centre, farthest vertex), as three.js's irbake_light_probes.js lightObject takes them. Without
  // probes in the file it keeps the plain shading (albedo), with a warning.
  void lightFromProbes(const Primitive& p, GpuPrimitive& g) {
    if (!probeGridRead) {
      probeGridRead = true;
      try {
        probeGrid = readLightProbes(scene.sourcePath);
        probeSun = probeSphereSun(*probeGrid);
        if (!probeGrid->emitters.empty()) {
          ProbeSphere any;
          any.emitters = std::make_shared<const std::vector<ProbeEmitter>>(probeGrid->emitters);
          probeEmitterTriangles = emitterTriangles({any});
        }
      } catch (const Error& e) {
        log::warn(std::string(e.what()) + ": probe-lit objects are drawn without light");
      }
    }
    if (!probeGrid) return;
    const glm::vec3 centre = 0.5f * (g.boundsMin + g.boundsMax);
    float radius = 0.0f;
    for (const glm::vec3& q : p.positions) radius = std::max(radius, glm::length(q - centre));
    try {
      g.probe = probeObject(*probeGrid, centre, radius, scene.sourcePath);
      g.features.probeLit = 1;
    } catch (const Error& e) {
      log::warn(std::string(e.what()) + " (probe-lit object \"" + p.name + "\")");
    }
  }

  void setProbeUniforms(const GpuPrimitive& g, int key) {
    setEmitterUniforms(*programs.at(key), g.probe, probeEmitterTriangles);
    glUniform3fv(u("uCentre"), 1, &g.probe.centre[0]);
    glUniform3fv(u("uSh"), kShCoefficients, &g.probe.coefficients[0][0]);
    glUniform3fv(u("uShGradient"), 3 * kShCoefficients, &g.probe.gradient[0][0][0]);
    glUniform1f(u("uSunVisibility"), g.probe.sunVisibility);
    glUniform3fv(u("uSunGradient"), 1, &g.probe.sunGradient[0]);
    glUniform3fv(u("uSunDirection"), 1, &probeSun.direction[0]);
    glUniform3fv(u("uSunIrradiance"), 1, &probeSun.irradiance[0]);
    glUniform3fv(u("uSunSh"), kShCoefficients, &probeSun.sh[0][0]);
  }

  // Draws the environment map over the whole viewport, without depth, before the scene.
  void drawSky(const glm::mat4& viewProjection, int width, int height, bool encode, float exposure) {
    std::unique_ptr<GlProgram>& sky = skyPrograms[encode ? 1 : 0];
    if (!sky)
      sky = std::make_unique<GlProgram>(std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"view_sky.vert"}},
                                                                 {GL_FRAGMENT_SHADER, {"view_encode.glsl", "view_sky.frag"}}},
                                        std::vector<std::string>{encode ? "#define OUTPUT 1" : "#define OUTPUT 0"},
                                        "330 core");
    if (!skyVao) glGenVertexArrays(1, &skyVao);
    sky->use();
    const glm::mat4 inverse = glm::inverse(viewProjection);
    glUniformMatrix4fv(sky->uniform("uInverseViewProjection"), 1, GL_FALSE, &inverse[0][0]);
    glUniform2f(sky->uniform("uViewportSize"), static_cast<float>(width), static_cast<float>(height));
    glUniform1i(sky->uniform("uEnvironment"), 0);
    glUniform1f(sky->uniform("uRotation"), environmentRotation);
    glUniform1f(sky->uniform("uExposureScale"), std::exp2(exposure));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, environmentTexture);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(skyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
    glUseProgram(0);
    program = 0;
  }

  explicit Impl(const Scene& s) : scene(s) {}

  GLint u(const char* name) {
    auto& uniforms = uniformsByProgram[program];
    auto it = uniforms.find(name);
    if (it != uniforms.end()) return it->second;
    return uniforms[name] = glGetUniformLocation(program, name);
  }

  // Binds the shader variant for a key (Variant::key), compiling it on first use. Returns true
  // when the program changed, so the caller sets its per-frame uniforms again.
  bool useProgram(int key) {
    auto it = programs.find(key);
    if (it == programs.end()) {
      const Variant f = Variant::fromKey(key);
      auto define = [](const char* name, int value) {
        return "#define " + std::string(name) + " " + std::to_string(value);
      };
      const std::vector<std::string> defines = {
          define("VIEW_MODE", f.mode),          define("OUTPUT", f.output),
          define("BASE_TEX", f.baseTex),        define("EMISSIVE_TEX", f.emissiveTex),
          define("HAS_LIGHTMAP", f.lightmap),   define("ALPHA_MASK", f.alphaMask),
          define("NEED_UV0", f.needUv0()),      define("NEED_UV1", f.needUv1()),
          define("NEED_NORMAL", f.needNormal()), define("NEED_CHART", f.needChart()),
          define("DIRECTIONAL", f.directional), define("NEED_TANGENT", f.needTangent()),
          define("MIXED_LIGHTS", f.mixed),      define("NEED_POSITION", f.mixed || f.probeLit),
          define("PROBE_LIT", f.probeLit),
          define("EMITTER_TRIANGLES", f.probeLit ? probeEmitterTriangles : 0)};
      it = programs
               .emplace(key, std::make_unique<GlProgram>(
                                 std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"view_mesh.vert"}},
                                                          {GL_FRAGMENT_SHADER, {"view_encode.glsl", "light_range.glsl", "view_mixed_lights.glsl", "probe_sh.glsl", "probe_emitters.glsl", "view_mesh.frag"}}},
                                 defines, "330 core"))
               .first;
    }
    if (program == it->second->id()) return false;
    program = it->second->id();
    glUseProgram(program);
    return true;
  }

  // The primitive's vertex array: vertices, indices (16-bit where every index fits) and attributes 0-4.
  static void uploadGeometry(GpuPrimitive& g, const std::vector<Vertex>& verts, const std::vector<uint32_t>& indices) {
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    glGenBuffers(1, &g.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
    glBufferData(GL_ARRAY_BUFFER, verts.size() * sizeof(Vertex), verts.data(), GL_STATIC_DRAW);
    glGenBuffers(1, &g.ebo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
    if (*std::max_element(indices.begin(), indices.end()) <= 0xffff) {
      // Half the index bytes for llvmpipe's vertex fetch to read.
      const std::vector<uint16_t> shortIndices(indices.begin(), indices.end());
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, shortIndices.size() * sizeof(uint16_t), shortIndices.data(),
                   GL_STATIC_DRAW);
      g.indexType = GL_UNSIGNED_SHORT;
    } else {
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, indices.size() * sizeof(uint32_t), indices.data(),
                   GL_STATIC_DRAW);
    }
    const GLsizei stride = sizeof(Vertex);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(Vertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(Vertex, normal)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(Vertex, uv0)));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(Vertex, uv1)));
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(Vertex, chart)));
    glBindVertexArray(0);
  }

  GLuint colorTexture(int index) {
    if (index < 0 || index >= static_cast<int>(scene.textures.size())) return 0;
    const Texture& t = scene.textures[index];
    if (t.width <= 0 || t.height <= 0 || t.texels.size() != static_cast<size_t>(t.width) * t.height) return 0;
    auto it = colorTextures.find(index);
    if (it != colorTextures.end()) return it->second;
    return colorTextures[index] = uploadColorTexture(t);
  }

  // An IRBAKE_lightmap_directional PNG as values, (2·texel − 1)·scale (docs/export.md: png8, signed), decoded
  // once per (texture, scale): the shader then reads float pages and PNGs alike, and bilinear filtering
  // commutes with the affine decode.
  GLuint directionalPng(int index, float scale) {
    auto it = directionalPngs.find({index, scale});
    if (it != directionalPngs.end()) return it->second;
    const Texture& t = scene.textures.at(index);
    MapMetadata md;
    md.intensity = scale;
    md.signedValues = true;
    const DecodedMap d = mapEncoding(MapEncodingKind::Png8).fromStored(t, md);
    return directionalPngs[{index, scale}] = uploadLightmap(t.width, t.height, GL_RGB, d.map.texels.data());
  }

  void ensureFramebuffer(int w, int h) {
    if (offscreen && w == offscreen->width() && h == offscreen->height()) return;
    offscreen.reset();
    offscreen = std::make_unique<RenderTarget>(w, h, GL_RGBA32F);
  }
};

RenderTarget::RenderTarget(int width, int height, unsigned colorFormat) : width_(width), height_(height) {
  glGenFramebuffers(1, &fbo_);
  glGenRenderbuffers(1, &color_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_);
  glRenderbufferStorage(GL_RENDERBUFFER, colorFormat, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    release();
    throw Error(ErrorCode::Gl, "", "offscreen framebuffer " + std::to_string(width) + "x" + std::to_string(height) +
                                       " is incomplete");
  }
}

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::release() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (color_) glDeleteRenderbuffers(1, &color_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
  fbo_ = color_ = depth_ = 0;
}

ViewRenderer::ViewRenderer(const ViewerScene& v) : impl_(std::make_unique<Impl>(v.scene)) {
  Impl& I = *impl_;
  I.mixed = std::make_unique<MixedLights>(v);
  for (const Lightmap& page : v.pages)
    I.pageTextures.push_back(page.size() > 0 && page.texels.size() == page.size()
                                 ? uploadLightmap(page.width, page.height, GL_RGB, page.texels.data())
                                 : 0);
  for (int k = 0; k < 3; ++k)
    for (const Lightmap& page : v.directionalPages[k])
      I.directionalPageTextures[k].push_back(page.size() > 0 && page.texels.size() == page.size()
                                                 ? uploadLightmap(page.width, page.height, GL_RGB, page.texels.data())
                                                 : 0);

  if (v.scene.environment.present() && !v.scene.environment.isUniform()) {
    I.environmentTexture = uploadEnvironment(v.scene.environment);
    I.environmentRotation = v.scene.environment.rotation();
  }

  uint32_t chartBase = 0, nextChartBase = 0;
  for (const Primitive& source : v.scene.primitives) {
    if (source.indices.empty()) continue;
    // Tangents generated the MikkTSpace way need the vertices that a UV mirror's two halves share split
    // before the vertex buffer is built.
    const Material& sm = v.scene.materials.at(source.material);
    std::optional<Primitive> split;
    if (source.tangents.size() != source.positions.size() && sm.normalTexture >= 0 &&
        directionalSourceOf(v, source) != DirectionalSource::None)
      split = splitMirroredUvVertices(source, sm.normalTexCoord == 1 ? 1 : 0);
    const Primitive& p = split ? *split : source;
    Impl::GpuPrimitive g;
    g.material = p.material;
    const Material& m = v.scene.materials.at(p.material);
    switch (lightmapSourceOf(v, p)) {
      case LightmapSource::Page: {
        g.lightmap = I.pageTextures[p.lightmap.page];
        const Lightmap& page = v.pages[p.lightmap.page];
        g.lightmapSize = glm::vec2(page.width, page.height);
        break;
      }
      case LightmapSource::MaterialTexture: {
        // MOZ_lightmap's png8 decode split in two: the loader applied the transfer curve, the shader multiplies
        // by the intensity, so the half-float texture holds [0, 1] whatever the intensity.
        const Texture& t = v.scene.textures[m.lightmapTexture];
        auto it = I.textureLightmaps.find(m.lightmapTexture);
        if (it == I.textureLightmaps.end())
          it = I.textureLightmaps.emplace(m.lightmapTexture,
                                          uploadLightmap(t.width, t.height, GL_RGBA, t.texels.data())).first;
        g.lightmap = it->second;
        g.lightmapScale = m.lightmapIntensity;
        g.lightmapSize = glm::vec2(t.width, t.height);
        break;
      }
      case LightmapSource::None:
        if (p.lightmap.width > 0) g.lightmapSize = glm::vec2(p.lightmap.width, p.lightmap.height);
        break;
    }
    // Chart ids run on across primitives so chart 0 of every primitive does not share one colour.
    const std::vector<uint32_t> charts = chartIds(p);
    std::vector<Vertex> verts(p.positions.size());
    for (size_t i = 0; i < verts.size(); ++i) {
      verts[i].position = p.positions[i];
      verts[i].normal = i < p.normals.size() ? p.normals[i] : glm::vec3(0, 1, 0);
      verts[i].uv0 = i < p.uv0.size() ? p.uv0[i] : glm::vec2(0.0f);
      verts[i].uv1 = i < p.uv1.size() ? p.uv1[i] : glm::vec2(0.0f);
      verts[i].chart = static_cast<float>(chartBase + charts[i]);
    }
    for (uint32_t c : charts) nextChartBase = std::max(nextChartBase, chartBase + c + 1);
    chartBase = nextChartBase;
    Impl::uploadGeometry(g, verts, p.indices);
    g.indexCount = static_cast<GLsizei>(p.indices.size());
    g.boundsMin = g.boundsMax = p.positions.front();
    for (const glm::vec3& q : p.positions) {
      g.boundsMin = glm::min(g.boundsMin, q);
      g.boundsMax = glm::max(g.boundsMax, q);
    }
    triangles_ += p.indices.size() / 3;
    // Upload the material's colour textures now so the first frame does no uploads.
    g.features.baseTex = I.colorTexture(m.baseColorTexture) ? (m.baseColorTexCoord == 1 ? 2 : 1) : 0;
    g.features.emissiveTex = I.colorTexture(m.emissiveTexture) ? (m.emissiveTexCoord == 1 ? 2 : 1) : 0;
    g.features.lightmap = g.lightmap ? 1 : 0;
    g.features.alphaMask = m.alphaMode == AlphaMode::Mask ? 1 : 0;
    g.features.mixed = I.mixed->shades(g.lightmap != 0) ? 1 : 0;
    if (g.features.mixed) g.shadowMask = I.mixed->maskTexture(p.material);
    if (p.mode == ObjectMode::Probes && !g.lightmap) I.lightFromProbes(p, g);
    // Directional maps only change what a normal map bends: at n = n_g the reconstruction is L0 itself
    // (the L1 pages hold t ⟂ n_g), so a primitive without a normal map keeps the plain shading and skips the
    // three fetches.
    const DirectionalSource l1Source = directionalSourceOf(v, p);
    const std::vector<glm::vec2>& normalUv = m.normalTexCoord == 1 ? p.uv1 : p.uv0;
    if (g.lightmap && l1Source != DirectionalSource::None && I.colorTexture(m.normalTexture) &&
        normalUv.size() == p.positions.size() && p.normals.size() == p.positions.size()) {
      for (int k = 0; k < 3; ++k)
        g.l1[k] = l1Source == DirectionalSource::Pages
                      ? I.directionalPageTextures[k][p.lightmap.page]
                      : I.directionalPng(m.directionalTextures[k], m.directionalScales[k]);
      const std::vector<glm::vec4> tangents =
          p.tangents.size() == p.positions.size() ? p.tangents : generateTangents(p, normalUv);
      glGenBuffers(1, &g.tangentVbo);
      glBindBuffer(GL_ARRAY_BUFFER, g.tangentVbo);
      glBufferData(GL_ARRAY_BUFFER, tangents.size() * sizeof(glm::vec4), tangents.data(), GL_STATIC_DRAW);
      glBindVertexArray(g.vao);
      glEnableVertexAttribArray(5);
      glVertexAttribPointer(5, 4, GL_FLOAT, GL_FALSE, sizeof(glm::vec4), nullptr);
      glBindVertexArray(0);
      g.features.directional = m.normalTexCoord == 1 ? 2 : 1;
      ++directionalPrimitives_;
    }
    g.cullBackFaces = !g.features.alphaMask && isClosedOutward(p);  // a masked hole would show the back
    // Compile the lit variant now: shader errors surface here, and the first frame compiles nothing.
    I.useProgram(Variant::forMode(0, 0, g.features).key());
    I.prims.push_back(g);
  }
  throwOnGlError("uploading the scene");
}

ViewRenderer::~ViewRenderer() {
  Impl& I = *impl_;
  for (auto& g : I.prims) {
    glDeleteVertexArrays(1, &g.vao);
    glDeleteBuffers(1, &g.vbo);
    glDeleteBuffers(1, &g.ebo);
    if (g.tangentVbo) glDeleteBuffers(1, &g.tangentVbo);
  }
  for (auto& [i, t] : I.colorTextures) glDeleteTextures(1, &t);
  for (auto& [i, t] : I.textureLightmaps) glDeleteTextures(1, &t);
  for (GLuint t : I.pageTextures)
    if (t) glDeleteTextures(1, &t);
  for (const auto& axis : I.directionalPageTextures)
    for (GLuint t : axis)
      if (t) glDeleteTextures(1, &t);
  for (auto& [key, t] : I.directionalPngs) glDeleteTextures(1, &t);
  if (I.environmentTexture) glDeleteTextures(1, &I.environmentTexture);
  I.mixed.reset();
  if (I.skyVao) glDeleteVertexArrays(1, &I.skyVao);
  for (auto& sky : I.skyPrograms) sky.reset();
  I.offscreen.reset();
  I.programs.clear();
}

void ViewRenderer::draw(const ViewCamera& camera, int width, int height, const DrawSettings& settings) {
  Impl& I = *impl_;
  glViewport(0, 0, width, height);
  // The background as the scene's pixels are: linear radiance offscreen, exposed and sRGB-encoded on screen.
  glm::vec3 background = settings.background;
  if (settings.encodeSrgb)
    for (int c = 0; c < 3; ++c) background[c] = encodeSrgb(std::min(1.0f, background[c] * std::exp2(settings.exposure)));
  glClearColor(background.r, background.g, background.b, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const float aspect = static_cast<float>(width) / std::max(height, 1);
  const glm::mat4 vp = camera.projection(aspect) * camera.view();
  // An environment map is drawn itself (the clear colour, its mean, stays underneath for nothing).
  if (I.environmentTexture && settings.drawEnvironment)
    I.drawSky(vp, width, height, settings.encodeSrgb, settings.exposure);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  // Culling only for closed outward solids (isClosedOutward): a wall seen from behind is still drawn,
  // but the hidden far side of a closed object costs no rasterisation.
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glDisable(GL_BLEND);

  const int output = settings.encodeSrgb ? 1 : 0;
  const bool sh = settings.lightmapMode == LightmapMode::Sh;
  // Front to back, by the distance to each primitive's farthest bounding-box corner (a room's walls,
  // whose far corner is the farthest thing in view, go last): llvmpipe tests depth before shading,
  // so what is drawn behind something already drawn costs no shading. Program switches cost less than
  // that saves, so the order ignores the shader variant.
  const glm::vec3 eye = camera.position();
  std::vector<std::pair<float, size_t>> order(I.prims.size());  // (squared distance, primitive index)
  for (size_t i = 0; i < I.prims.size(); ++i) {
    const glm::vec3 far = glm::max(glm::abs(eye - I.prims[i].boundsMin), glm::abs(eye - I.prims[i].boundsMax));
    order[i] = {glm::dot(far, far), i};
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  auto drawAll = [&](int mode) {
    I.program = 0;
    for (const auto& [distance, index] : order) {
      const auto& g = I.prims[index];
      const Variant variant = Variant::forMode(mode, output, g.features, sh);
      if (I.useProgram(variant.key())) {
        glUniformMatrix4fv(I.u("uViewProjection"), 1, GL_FALSE, &vp[0][0]);
        glUniform1f(I.u("uExposureScale"), std::exp2(settings.exposure));
        glUniform1i(I.u("uBaseColorTex"), 0);
        glUniform1i(I.u("uEmissiveTex"), 1);
        glUniform1i(I.u("uLightmap"), 2);
        glUniform1i(I.u("uNormalTex"), 3);
        glUniform1i(I.u("uL1x"), 4);
        glUniform1i(I.u("uL1y"), 5);
        glUniform1i(I.u("uL1z"), 6);
        glUniform3f(I.u("uLineColor"), 0.9f, 0.9f, 0.9f);
        if (variant.mixed) I.mixed->setUniforms(I.program, 7);
      }
      const Material& m = I.scene.materials.at(g.material);
      glUniform4fv(I.u("uBaseColorFactor"), 1, &m.baseColorFactor[0]);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, I.colorTexture(m.baseColorTexture));
      const glm::vec3 emission = m.emission();
      glUniform3fv(I.u("uEmissive"), 1, &emission[0]);
      // KHR_texture_transform (the identity without it): set on every draw, the default of a mat3 is zero.
      const glm::mat3 baseUv = m.baseColorUvTransform.matrix(), emissiveUv = m.emissiveUvTransform.matrix();
      glUniformMatrix3fv(I.u("uBaseColorUvTransform"), 1, GL_FALSE, &baseUv[0][0]);
      glUniformMatrix3fv(I.u("uEmissiveUvTransform"), 1, GL_FALSE, &emissiveUv[0][0]);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, I.colorTexture(m.emissiveTexture));
      glUniform1f(I.u("uLightmapScale"), g.lightmapScale);
      glUniform2fv(I.u("uLightmapSize"), 1, &g.lightmapSize[0]);
      glActiveTexture(GL_TEXTURE2);
      glBindTexture(GL_TEXTURE_2D, g.lightmap);
      glUniform1f(I.u("uAlphaCutoff"), m.alphaCutoff);
      if (variant.directional) {
        glUniform1f(I.u("uNormalScale"), m.normalScale);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, I.colorTexture(m.normalTexture));
        for (int k = 0; k < 3; ++k) {
          glActiveTexture(GL_TEXTURE4 + k);
          glBindTexture(GL_TEXTURE_2D, g.l1[k]);
        }
      }
      if (variant.probeLit) I.setProbeUniforms(g, variant.key());
      if (variant.mixed) {
        glActiveTexture(GL_TEXTURE7);
        glBindTexture(GL_TEXTURE_2D, g.shadowMask);
      }
      if (g.cullBackFaces)
        glEnable(GL_CULL_FACE);
      else
        glDisable(GL_CULL_FACE);
      glBindVertexArray(g.vao);
      glDrawElements(GL_TRIANGLES, g.indexCount, g.indexType, nullptr);
    }
  };

  if (settings.mode == ViewMode::Wireframe) {
    // Filled and pushed back slightly, then the edges on top.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    drawAll(static_cast<int>(ViewMode::Lit));
    glDisable(GL_POLYGON_OFFSET_FILL);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    drawAll(5);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  } else {
    drawAll(static_cast<int>(settings.mode));
  }
  for (const Overlay& overlay : overlays_) overlay(camera, vp, settings);
  glBindVertexArray(0);
  glActiveTexture(GL_TEXTURE0);
  glDisable(GL_CULL_FACE);
  throwOnGlError("drawing the scene");
}

RgbaImage ViewRenderer::render(const ViewCamera& camera, int width, int height, DrawSettings settings) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    throw Error(ErrorCode::Usage, "", "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                          " is out of range (1..16384)");
  Impl& I = *impl_;
  GLint previous = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous);
  I.ensureFramebuffer(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, I.offscreen->framebuffer());
  settings.encodeSrgb = false;
  draw(camera, width, height, settings);
  RgbaImage img;
  img.width = width;
  img.height = height;
  std::vector<glm::vec4> rows(static_cast<size_t>(width) * height);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rows.data());
  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(previous));
  throwOnGlError("reading the offscreen image");
  // GL's row 0 is the bottom; images here have row 0 at the top.
  img.pixels.resize(rows.size());
  for (int y = 0; y < height; ++y)
    std::copy_n(rows.begin() + static_cast<size_t>(height - 1 - y) * width, width,
                img.pixels.begin() + static_cast<size_t>(y) * width);
  return img;
}

}  // namespace irbake::view
